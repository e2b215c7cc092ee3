// tests/app/junit_report_test.cpp -- the JUnit XML of `cdlab check --junit`: every string a scene
// file can put into it is escaped so the document stays well-formed XML 1.0, the counts agree
// with the rows, and the document validates against tests/data/junit_cdlab.xsd (xmllint, Debian
// libxml2-utils).
#include "junit_report.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cli_run.h"

namespace app {
namespace {

namespace fs = std::filesystem;

TEST(JunitReport, EscapesTheFiveSpecialCharacters) {
    EXPECT_EQ(xmlEscape("a&b<c>d\"e'f", false), "a&amp;b&lt;c&gt;d&quot;e&apos;f");
    EXPECT_EQ(xmlEscape("a&b<c>d\"e'f", true), "a&amp;b&lt;c&gt;d&quot;e&apos;f");
    // "]]>" would end a CDATA section; escaped '>' keeps text safe anywhere.
    EXPECT_EQ(xmlEscape("]]>", false), "]]&gt;");
}

// Attribute-value normalisation (XML 1.0 §3.3.3) turns a literal tab or newline in an attribute
// into a space; a reason that spans lines must come back as it was.
TEST(JunitReport, KeepsWhitespaceInAttributes) {
    EXPECT_EQ(xmlEscape("a\tb\nc\rd", true), "a&#9;b&#10;c&#13;d");
    EXPECT_EQ(xmlEscape("a\tb\nc\rd", false), "a\tb\nc&#13;d");
}

// XML 1.0 cannot carry control characters other than tab, newline and carriage return, not
// even as &#1;, nor bytes that are not UTF-8: a body name "ab\x01" from a double-quoted YAML
// string would make the report unreadable. They become visible \xNN text.
TEST(JunitReport, ReplacesWhatXmlCannotCarry) {
    EXPECT_EQ(xmlEscape(std::string("a\x01z\x1f\x7f", 5), false), "a\\x01z\\x1F\x7f");
    EXPECT_EQ(xmlEscape(std::string("n\0m", 3), true), "n\\x00m");
    // Stray continuation byte, a lead byte cut short, an overlong '/', a surrogate, U+FFFE.
    EXPECT_EQ(xmlEscape("\x80", false), "\\x80");
    EXPECT_EQ(xmlEscape("x\xC3", false), "x\\xC3");
    EXPECT_EQ(xmlEscape("\xC0\xAF", false), "\\xC0\\xAF");
    EXPECT_EQ(xmlEscape("\xED\xA0\x80", false), "\\xED\\xA0\\x80");
    EXPECT_EQ(xmlEscape("\xEF\xBF\xBE", false), "\\xEF\\xBF\\xBE");
    EXPECT_EQ(xmlEscape("\xF4\x90\x80\x80", false), "\\xF4\\x90\\x80\\x80");  // > U+10FFFF
    // Well-formed UTF-8 passes unchanged: é, €, U+1F600.
    const std::string utf8 = "\xC3\xA9 \xE2\x82\xAC \xF0\x9F\x98\x80";
    EXPECT_EQ(xmlEscape(utf8, true), utf8);
}

SceneReport report(std::string label, SceneOutcome outcome, std::vector<CheckRow> rows) {
    SceneReport r;
    r.label = std::move(label);
    r.outcome = outcome;
    r.rows = std::move(rows);
    r.seconds = 0.25;
    return r;
}

bool haveXmllint() { return std::system("xmllint --version > /dev/null 2>&1") == 0; }

// `xmllint ARGS` with its stdout; the exit code in `code`.
std::string xmllint(const std::string& args, const fs::path& work, int* code = nullptr) {
    const fs::path out = work / "xmllint.txt";
    const int status = std::system(("xmllint " + args + " > " + out.string() + " 2>&1").c_str());
    if (code) *code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return cdlab_test::slurp(out);
}

TEST(JunitReport, ValidatesAndCountsAgreeWithTheRows) {
    if (!haveXmllint()) GTEST_SKIP() << "xmllint (Debian libxml2-utils) not installed";
    const fs::path work = cdlab_test::tempDir("cdlab_junit_test_", "counts");
    SceneReport noisy =
        report("s<&>'\".yaml", SceneOutcome::Graded,
               {{"pair a&b / <c> colliding", true, ""},
                {std::string("at rest \x01\"q'\t"), false, "moved 0.3 m <by> & \n so"},
                {"pause dump at frame 2", false, "x]]>y"}});
    noisy.notes = {"note: <deprecated> & gone"};
    noisy.log = std::string("child said \x02 <hi>\n");
    const std::vector<SceneReport> reports = {
        noisy,
        report("bad.yaml", SceneOutcome::NotLoaded,
               {{"load", false, "bad.yaml:3:7: bodies[0].name: no body is named 'zz'"}}),
        report("hang.yaml", SceneOutcome::NotRun, {{"run", false, "could not run: timed out"}}),
        report("ok.yaml", SceneOutcome::Graded, {{"at least 2 bodies", true, ""}}),
    };
    const fs::path file = work / "report.xml";
    std::ofstream(file, std::ios::binary) << junitXml(reports, 1.5);

    int code = -1;
    const std::string schema = std::string(CDLAB_SOURCE_DIR) + "/tests/data/junit_cdlab.xsd";
    const std::string said =
        xmllint("--noout --schema " + schema + " " + file.string(), work, &code);
    EXPECT_EQ(code, 0) << said << cdlab_test::slurp(file);
    // xmllint prints the value and a newline.
    auto xpath = [&](const std::string& expr) {
        std::string v = xmllint("--xpath '" + expr + "' " + file.string(), work);
        if (!v.empty() && v.back() == '\n') v.pop_back();
        return v;
    };
    EXPECT_EQ(xpath("count(//testsuite)"), "4");
    EXPECT_EQ(xpath("count(//testcase)"), "6");
    EXPECT_EQ(xpath("count(//testcase/failure)"), "2");
    EXPECT_EQ(xpath("count(//testcase/error)"), "2");
    EXPECT_EQ(xpath("string(/testsuites/@tests)"), "6");
    EXPECT_EQ(xpath("string(/testsuites/@failures)"), "2");
    EXPECT_EQ(xpath("string(/testsuites/@errors)"), "2");
    EXPECT_EQ(xpath("string(/testsuites/@time)"), "1.500");
    // Each suite's counts are its own testcases'.
    EXPECT_EQ(xpath("count(//testsuite[@tests != count(testcase)])"), "0");
    EXPECT_EQ(xpath("count(//testsuite[@failures != count(testcase/failure)])"), "0");
    EXPECT_EQ(xpath("count(//testsuite[@errors != count(testcase/error)])"), "0");
    EXPECT_EQ(xpath("string(//testsuite[1]/@time)"), "0.250");
    // The strings come back as they went in (the control character as \x01 text).
    EXPECT_EQ(xpath("string(//testsuite[1]/@name)"), "s<&>'\".yaml");
    EXPECT_EQ(xpath("string(//testsuite[1]/testcase[1]/@classname)"), "s<&>'\".yaml");
    EXPECT_EQ(xpath("string(//testsuite[1]/testcase[2]/@name)"), "at rest \\x01\"q'\t");
    EXPECT_EQ(xpath("string(//testsuite[1]/testcase[2]/failure/@message)"),
              "moved 0.3 m <by> & \n so");
    EXPECT_EQ(xpath("string(//testsuite[1]/testcase[3]/failure)"), "x]]>y");
    EXPECT_EQ(xpath("string(//testsuite[1]/system-err)"),
              "note: <deprecated> & gone\nchild said \\x02 <hi>\n");
    EXPECT_EQ(xpath("string(//testsuite[2]/testcase/error/@message)"),
              "bad.yaml:3:7: bodies[0].name: no body is named 'zz'");
    fs::remove_all(work);
}

}  // namespace
}  // namespace app
