// engine/src/mesh_text_coordinates.cpp -- vertex coordinates of OBJ, OFF, ASCII PLY and ASCII
// STL files in double, with the byte range of each, so that they can be measured and rewritten.
// Only the vertex coordinates are read: faces, normals, colours and every other element stay
// assimp's to parse. Invariant: points.size() * 3 == spans.size(), spans ascending and disjoint.
#include "mesh_text_coordinates.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <optional>
#include <string_view>
#include <utility>

namespace engine {

namespace {

using collision::Real;
using collision::Vec3;

struct Token {
    std::string_view text;
    std::size_t begin = 0;  ///< byte offset in the file
};

bool isBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

// The file split into lines, each into blank-separated tokens with their offsets.
class Lines {
public:
    explicit Lines(const std::string& text) : text_(text) {}
    /// The next line's tokens (possibly none); nullopt at the end of the file.
    std::optional<std::vector<Token>> next() {
        if (pos_ >= text_.size()) return std::nullopt;
        std::vector<Token> tokens;
        while (pos_ < text_.size() && text_[pos_] != '\n') {
            if (isBlank(text_[pos_])) {
                ++pos_;
                continue;
            }
            const std::size_t from = pos_;
            while (pos_ < text_.size() && text_[pos_] != '\n' && !isBlank(text_[pos_])) ++pos_;
            tokens.push_back({std::string_view(text_).substr(from, pos_ - from), from});
        }
        ++pos_;  // the newline
        return tokens;
    }
    /// The next line holding a token that does not start a '#' comment.
    std::optional<std::vector<Token>> nextContent() {
        for (std::optional<std::vector<Token>> l = next(); l; l = next()) {
            if (!l->empty() && l->front().text.front() != '#') return l;
        }
        return std::nullopt;
    }

private:
    const std::string& text_;
    std::size_t pos_ = 0;
};

std::optional<Real> number(std::string_view t) {
    if (!t.empty() && t.front() == '+') t.remove_prefix(1);
    double v = 0;
    const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (ec != std::errc() || end != t.data() + t.size() || !std::isfinite(v)) return std::nullopt;
    return Real(v);
}

// Appends the point whose coordinates are tokens[i], tokens[j], tokens[k]; false if one is not
// a finite number.
bool addPoint(TextCoordinates& tc, const std::vector<Token>& tokens, std::size_t i, std::size_t j,
              std::size_t k) {
    const std::size_t idx[3] = {i, j, k};
    Vec3 p;
    for (int a = 0; a < 3; ++a) {
        if (idx[a] >= tokens.size()) return false;
        const std::optional<Real> v = number(tokens[idx[a]].text);
        if (!v) return false;
        p[a] = *v;
    }
    for (const std::size_t n : idx) {
        tc.spans.emplace_back(tokens[n].begin, tokens[n].begin + tokens[n].text.size());
    }
    tc.points.push_back(p);
    return true;
}

// Wavefront OBJ: "v x y z [w | r g b]".
bool readObj(TextCoordinates& tc) {
    Lines lines(tc.text);
    for (std::optional<std::vector<Token>> l = lines.next(); l; l = lines.next()) {
        if (l->empty() || l->front().text != "v") continue;
        if (!addPoint(tc, *l, 1, 2, 3)) return false;
    }
    return true;
}

// OFF (and COFF, NOFF, CNOFF, STOFF...; not 4OFF or nOFF, whose points are not x y z): the
// magic, the vertex and face counts (on its line or the next), then one vertex per line.
bool readOff(TextCoordinates& tc) {
    Lines lines(tc.text);
    std::optional<std::vector<Token>> l = lines.nextContent();
    if (!l) return false;
    const std::string_view magic = l->front().text;
    if (magic.size() < 3 || magic.substr(magic.size() - 3) != "OFF" ||
        magic.find_first_of("4n") != std::string_view::npos) {
        return false;
    }
    std::vector<Token> counts(l->begin() + 1, l->end());
    if (counts.empty()) {
        l = lines.nextContent();
        if (!l) return false;
        counts = *l;
    }
    std::size_t nv = 0;
    const std::string_view c = counts.front().text;
    if (std::from_chars(c.data(), c.data() + c.size(), nv).ptr != c.data() + c.size()) return false;
    for (std::size_t i = 0; i < nv; ++i) {
        l = lines.nextContent();
        if (!l || !addPoint(tc, *l, 0, 1, 2)) return false;
    }
    return true;
}

// ASCII PLY: the header's elements in order, each instance one line; x, y, z of `vertex` must
// come before any list property of it (so that their token positions are fixed).
bool readPly(TextCoordinates& tc) {
    Lines lines(tc.text);
    std::optional<std::vector<Token>> l = lines.next();
    if (!l || l->empty() || l->front().text != "ply") return false;
    struct Element {
        std::string_view name;
        std::size_t count = 0;
        std::vector<std::string_view> scalars;  ///< properties before the first list
        bool list = false;
    };
    std::vector<Element> elements;
    bool ascii = false;
    for (l = lines.next();; l = lines.next()) {
        if (!l) return false;
        if (l->empty()) continue;
        const std::string_view key = l->front().text;
        if (key == "end_header") break;
        if (key == "format") {
            ascii = l->size() > 1 && (*l)[1].text == "ascii";
        } else if (key == "element" && l->size() == 3) {
            Element e;
            e.name = (*l)[1].text;
            const std::string_view n = (*l)[2].text;
            if (std::from_chars(n.data(), n.data() + n.size(), e.count).ptr != n.data() + n.size())
                return false;
            elements.push_back(e);
        } else if (key == "property" && !elements.empty() && l->size() >= 3) {
            Element& e = elements.back();
            if ((*l)[1].text == "list") e.list = true;
            if (!e.list) e.scalars.push_back(l->back().text);
        }
    }
    if (!ascii) return false;
    for (const Element& e : elements) {
        if (e.name != "vertex") {
            for (std::size_t i = 0; i < e.count; ++i) {
                if (!lines.nextContent()) return false;
            }
            continue;
        }
        const auto at = [&e](std::string_view name) {
            return static_cast<std::size_t>(
                std::find(e.scalars.begin(), e.scalars.end(), name) - e.scalars.begin());
        };
        const std::size_t ix = at("x"), iy = at("y"), iz = at("z");
        if (std::max({ix, iy, iz}) >= e.scalars.size()) return false;
        for (std::size_t i = 0; i < e.count; ++i) {
            l = lines.nextContent();
            if (!l || !addPoint(tc, *l, ix, iy, iz)) return false;
        }
        return true;
    }
    return false;
}

// ASCII STL: "solid", facets, "vertex x y z" lines. A binary STL may begin with "solid" too; it
// holds NUL bytes (its triangle count) and no parsable vertex lines.
bool readStl(TextCoordinates& tc) {
    if (tc.text.find('\0') != std::string::npos) return false;
    Lines lines(tc.text);
    std::optional<std::vector<Token>> l = lines.nextContent();
    if (!l || l->front().text != "solid") return false;
    for (l = lines.next(); l; l = lines.next()) {
        if (l->empty() || l->front().text != "vertex") continue;
        if (!addPoint(tc, *l, 1, 2, 3)) return false;
    }
    return !tc.points.empty() && tc.points.size() % 3 == 0;
}

}  // namespace

TextCoordinates readTextCoordinates(const std::filesystem::path& file) {
    TextCoordinates tc;
    std::string ext = file.extension().string();
    if (!ext.empty()) ext.erase(0, 1);
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    bool (*read)(TextCoordinates&) = ext == "obj"   ? readObj
                                      : ext == "off" ? readOff
                                      : ext == "ply" ? readPly
                                      : ext == "stl" ? readStl
                                                     : nullptr;
    if (read == nullptr) return tc;
    std::ifstream in(file, std::ios::binary);
    tc.text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    tc.hint = ext;
    tc.ok = in.good() || in.eof();
    tc.ok = tc.ok && read(tc);
    if (!tc.ok) {
        tc.points.clear();
        tc.spans.clear();
    }
    return tc;
}

std::string shiftedText(const TextCoordinates& tc, const collision::Vec3& offset) {
    std::string out;
    out.reserve(tc.text.size() + tc.text.size() / 4);
    std::size_t from = 0;
    for (std::size_t s = 0; s < tc.spans.size(); ++s) {
        const auto [begin, end] = tc.spans[s];
        out.append(tc.text, from, begin - from);
        const Real v = tc.points[s / 3][static_cast<int>(s % 3)] - offset[static_cast<int>(s % 3)];
        char buf[32];
        const int n = std::snprintf(buf, sizeof buf, "%.17g", double(v));
        out.append(buf, static_cast<std::size_t>(n));
        from = end;
    }
    out.append(tc.text, from, std::string::npos);
    return out;
}

}  // namespace engine
