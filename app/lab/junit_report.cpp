// app/lab/junit_report.cpp -- the JUnit XML of `cdlab check` (junit_report.h). Strings come from
// scene files and paths, so every one goes through xmlEscape: the document is well-formed XML 1.0
// (W3C XML 1.0 §2.2 Char, §2.4 character data, §3.3.3 attribute-value normalisation) whatever
// bytes a body name holds.
#include "junit_report.h"

#include <cstdint>
#include <cstdio>
#include <sstream>

#include "markup_entity.h"

namespace app {

namespace {

// Length of the well-formed UTF-8 sequence at s[i] (RFC 3629 table 3.9 of Unicode: no overlong
// forms, no surrogates, nothing above U+10FFFF), 0 when the bytes there are not one.
std::size_t utf8Length(std::string_view s, std::size_t i) {
    const auto at = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
    const unsigned char b = at(i);
    const auto cont = [&](std::size_t k, unsigned lo = 0x80, unsigned hi = 0xBF) {
        return k < s.size() && at(k) >= lo && at(k) <= hi;
    };
    if (b < 0x80) return 1;
    if (b >= 0xC2 && b <= 0xDF) return cont(i + 1) ? 2 : 0;
    if (b == 0xE0) return cont(i + 1, 0xA0) && cont(i + 2) ? 3 : 0;
    if (b == 0xED) return cont(i + 1, 0x80, 0x9F) && cont(i + 2) ? 3 : 0;
    if (b >= 0xE1 && b <= 0xEF) return cont(i + 1) && cont(i + 2) ? 3 : 0;
    if (b == 0xF0) return cont(i + 1, 0x90) && cont(i + 2) && cont(i + 3) ? 4 : 0;
    if (b >= 0xF1 && b <= 0xF3) return cont(i + 1) && cont(i + 2) && cont(i + 3) ? 4 : 0;
    if (b == 0xF4) return cont(i + 1, 0x80, 0x8F) && cont(i + 2) && cont(i + 3) ? 4 : 0;
    return 0;
}

void appendHexByte(std::string& out, unsigned char b) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "\\x%02X", b);
    out += buf;
}

std::string seconds(double s) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3f", s < 0 ? 0.0 : s);
    return buf;
}

std::string attr(const char* name, std::string_view value) {
    std::string s = " ";
    s += name;
    s += "=\"";
    s += xmlEscape(value, true);
    s += '"';
    return s;
}

struct Counts {
    std::size_t tests = 0, failures = 0, errors = 0;
};

Counts count(const SceneReport& s) {
    Counts c;
    c.tests = s.rows.size();
    if (s.outcome != SceneOutcome::Graded) {
        c.errors = c.tests;
        return c;
    }
    for (const CheckRow& r : s.rows) c.failures += r.pass ? 0 : 1;
    return c;
}

void writeSuite(std::ostringstream& x, const SceneReport& s) {
    const Counts c = count(s);
    x << "  <testsuite" << attr("name", s.label) << attr("tests", std::to_string(c.tests))
      << attr("failures", std::to_string(c.failures)) << attr("errors", std::to_string(c.errors))
      << attr("time", seconds(s.seconds)) << ">\n";
    for (const CheckRow& r : s.rows) {
        x << "    <testcase" << attr("classname", s.label) << attr("name", r.expectation);
        if (r.pass) {
            x << "/>\n";
            continue;
        }
        const char* kind = s.outcome == SceneOutcome::Graded ? "failure" : "error";
        x << ">\n      <" << kind << attr("message", r.reason) << ">" << xmlEscape(r.reason, false)
          << "</" << kind << ">\n    </testcase>\n";
    }
    std::string err;
    for (const std::string& note : s.notes) err += note + "\n";
    err += s.log;
    if (!err.empty()) x << "    <system-err>" << xmlEscape(err, false) << "</system-err>\n";
    x << "  </testsuite>\n";
}

}  // namespace

std::string xmlEscape(std::string_view text, bool attribute) {
    std::string out;
    out.reserve(text.size());
    for (std::size_t i = 0; i < text.size();) {
        const unsigned char b = static_cast<unsigned char>(text[i]);
        const std::size_t n = utf8Length(text, i);
        if (n == 0) {
            appendHexByte(out, b);
            ++i;
            continue;
        }
        if (n == 3 && b == 0xEF && static_cast<unsigned char>(text[i + 1]) == 0xBF &&
            static_cast<unsigned char>(text[i + 2]) >= 0xBE) {  // U+FFFE, U+FFFF: not Chars
            for (std::size_t k = 0; k < 3; ++k)
                appendHexByte(out, static_cast<unsigned char>(text[i + k]));
            i += 3;
            continue;
        }
        if (n > 1) {
            out.append(text.substr(i, n));
            i += n;
            continue;
        }
        if (const std::string_view entity = markupEntity(static_cast<char>(b), "&apos;");
            !entity.empty()) {
            out += entity;
            ++i;
            continue;
        }
        switch (b) {
            case '\t':
                out += attribute ? "&#9;" : "\t";
                break;
            case '\n':
                out += attribute ? "&#10;" : "\n";
                break;
            case '\r':
                out += "&#13;";
                break;
            default:
                if (b < 0x20) {
                    appendHexByte(out, b);
                } else {
                    out += static_cast<char>(b);
                }
        }
        ++i;
    }
    return out;
}

std::string junitXml(const std::vector<SceneReport>& reports, double total_seconds) {
    Counts total;
    for (const SceneReport& s : reports) {
        const Counts c = count(s);
        total.tests += c.tests;
        total.failures += c.failures;
        total.errors += c.errors;
    }
    std::ostringstream x;
    x << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<testsuites" << attr("name", "cdlab check") << attr("tests", std::to_string(total.tests))
      << attr("failures", std::to_string(total.failures))
      << attr("errors", std::to_string(total.errors)) << attr("time", seconds(total_seconds))
      << ">\n";
    for (const SceneReport& s : reports) writeSuite(x, s);
    x << "</testsuites>\n";
    return x.str();
}

}  // namespace app
