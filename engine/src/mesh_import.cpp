// engine/src/mesh_import.cpp -- assimp -> collision::TriangleMesh. The only file that sees assimp.
// Output invariant: vertices are unique by position (welded exactly, after scaling), every vertex
// is used, every triangle has three distinct vertices and non-zero area, and the order of both
// follows the file (meshes in scene order, faces in mesh order), so imports are deterministic.
// Every triangle dropped is counted in the report; for text formats the report also measures what
// float coordinates cost against the file's coordinates read in double (mesh_text_coordinates.h).
#include "engine/mesh_import.h"

#include <assimp/DefaultIOSystem.h>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <array>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <exception>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "mesh_text_coordinates.h"

namespace engine {

namespace {

using collision::Real;
using collision::Vec3;

// A triangle is degenerate when |(b-a) x (c-a)| is at rounding level of its longest edge squared.
constexpr Real kDegenerateArea = Real(4) * collision::kEpsilon;

// Text formats whose largest coordinate exceeds this multiple of the mesh's largest extent go to
// assimp recentred: float keeps 24 bits relative to the coordinate, so at 16 sizes from the origin
// the mesh already has 4 bits less than around its own centre.
constexpr Real kRecentreRatio = 16;

// Rounding below this fraction of the mesh's size is what float gives any mesh near its own origin
// (2^-24 of coordinates up to 16 sizes): not worth a warning.
constexpr Real kRoundingWarnFraction = Real(0x1.0p-20);

// Model files past this size are refused before assimp reads them (a binary STL of 256 MiB holds
// 5.4 million triangles); assimp's memory grows with the file.
constexpr std::uintmax_t kMaxMeshFileBytes = std::uintmax_t(256) << 20;

// Reads whitespace-separated tokens of a text header, skipping '#' comments.
class HeaderTokens {
public:
    explicit HeaderTokens(std::string text) : text_(std::move(text)) {}
    std::optional<std::string> next() {
        for (;;) {
            while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) {
                ++pos_;
            }
            if (pos_ >= text_.size()) return std::nullopt;
            if (text_[pos_] != '#') break;
            while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
        }
        const std::size_t from = pos_;
        while (pos_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[pos_]))) {
            ++pos_;
        }
        return text_.substr(from, pos_ - from);
    }
    /// The next token as a count (decimal digits only), or nullopt.
    std::optional<long double> count() {
        const std::optional<std::string> t = next();
        if (!t || t->empty() || t->size() > 30 ||
            !std::all_of(t->begin(), t->end(), [](char c) { return c >= '0' && c <= '9'; })) {
            return std::nullopt;
        }
        return std::stold(*t);
    }

private:
    std::string text_;
    std::size_t pos_ = 0;
};

// Formats whose header states how many elements follow (OFF, PLY) are checked against the file's
// size before assimp allocates for them: each element takes at least a few bytes, so a count the
// bytes cannot hold is a lie (a 100-byte OFF claiming 2e8 vertices took assimp 5.5 GB and 16 s
// to refuse; the same PLY in ASCII did not finish). A PLY header must also end (end_header)
// within the 64 KiB read. Empty when the header is consistent or is not one of these formats
// (assimp then judges the file alone).
std::string declaredCountsError(const std::filesystem::path& file, std::uintmax_t bytes) {
    std::ifstream in(file, std::ios::binary);
    std::string head(64 * 1024, '\0');
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<std::size_t>(in.gcount()));
    const auto tooMany = [&](long double least_bytes, const std::string& what) -> std::string {
        if (least_bytes <= static_cast<long double>(bytes)) return "";
        std::string why = "'";
        why += file.string();
        why += "' declares " + what + ", more than its " + std::to_string(bytes) +
               " bytes can hold (a truncated or corrupt file)";
        return why;
    };
    HeaderTokens tokens(head);
    const std::optional<std::string> magic = tokens.next();
    if (!magic) return "";
    // OFF (and COFF, NOFF, STOFF...): "OFF", then vertex, face and edge counts. A vertex takes at
    // least 6 bytes of text ("0 0 0\n"), a face at least 2 ("0\n").
    if (magic->size() >= 3 && magic->compare(magic->size() - 3, 3, "OFF") == 0 &&
        magic->size() <= 8) {
        const std::optional<long double> nv = tokens.count();
        const std::optional<long double> nf = tokens.count();
        if (!nv || !nf) return "";
        return tooMany(*nv * 6 + *nf * 2,
                       std::to_string(static_cast<unsigned long long>(std::min(*nv, 1e19L))) +
                           " vertices and " +
                           std::to_string(static_cast<unsigned long long>(std::min(*nf, 1e19L))) +
                           " faces");
    }
    // PLY: "element NAME N" lines, each followed by its properties; the smallest element is the
    // sum of its properties' sizes in binary (a list at least its count), two bytes each in ASCII.
    if (*magic == "ply") {
        bool binary = false;
        bool ended = false;
        long double least = 0;
        long double elements = 0;
        long double element_count = 0;
        long double element_bytes = 0;
        const auto sizeOf = [](const std::string& type) -> int {
            if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
            if (type == "short" || type == "ushort" || type == "int16" || type == "uint16")
                return 2;
            if (type == "double" || type == "float64") return 8;
            return 4;  // int, uint, float and their sized names
        };
        for (std::optional<std::string> t = tokens.next(); t; t = tokens.next()) {
            if (*t == "format") {
                const std::optional<std::string> f = tokens.next();
                binary = f && f->rfind("binary", 0) == 0;
            } else if (*t == "element" || *t == "end_header") {
                least += element_count * element_bytes;
                element_count = 0;
                element_bytes = 0;
                if (*t == "end_header") {
                    ended = true;
                    break;
                }
                tokens.next();  // name
                const std::optional<long double> n = tokens.count();
                if (!n) return "";
                element_count = *n;
                elements += *n;
            } else if (*t == "property") {
                std::optional<std::string> type = tokens.next();
                if (type && *type == "list") {
                    const std::optional<std::string> count_type = tokens.next();
                    tokens.next();  // item type
                    element_bytes += binary ? (count_type ? sizeOf(*count_type) : 1) : 2;
                } else {
                    element_bytes += binary ? (type ? sizeOf(*type) : 1) : 2;
                }
                tokens.next();  // property name
            }
        }
        // Without its end_header line assimp's reader never stops looking for it.
        if (!ended) {
            return "'" + file.string() + "' is a PLY file whose header has no end_header line" +
                   (head.size() == 64 * 1024 ? " in its first 64 KiB" : "") +
                   " (a truncated or corrupt file)";
        }
        return tooMany(least,
                       std::to_string(static_cast<unsigned long long>(std::min(elements, 1e19L))) +
                           " elements (vertices, faces...)");
    }
    return "";
}

// Why `file` cannot be opened as part of a model (missing, not a regular file: a FIFO or a device
// would block or never end, over the size limit), or "". Sets `bytes` when it can be.
std::string openError(const std::filesystem::path& file, std::uintmax_t& bytes) {
    std::error_code ec;
    if (!std::filesystem::exists(file, ec)) {
        return "cannot open '" + file.string() + "': no such file";
    }
    if (!std::filesystem::is_regular_file(file, ec)) {
        return "cannot open '" + file.string() + "': not a regular file";
    }
    bytes = std::filesystem::file_size(file, ec);
    if (ec) return "cannot open '" + file.string() + "': " + ec.message();
    if (bytes > kMaxMeshFileBytes) {
        std::string why = "'";
        why += file.string();
        why += "' has " + std::to_string(bytes) + " bytes, more than the limit of " +
               std::to_string(kMaxMeshFileBytes) + " (256 MiB) for a model file";
        return why;
    }
    return "";
}

// Why `file` cannot be a model file (openError, or declaring more elements than it can hold),
// or "".
std::string fileError(const std::filesystem::path& file) {
    std::uintmax_t bytes = 0;
    std::string why = openError(file, bytes);
    return why.empty() ? declaredCountsError(file, bytes) : why;
}

// assimp's file system with the model file's rules applied to every file an importer opens (an
// OBJ's mtllib, a glTF's buffers, an X file's textures): a FIFO, a device or a file past the size
// limit is not opened, and the first such refusal is kept to be reported.
class CheckedIoSystem final : public Assimp::DefaultIOSystem {
public:
    // Asked without opening the file (the default opens it, which blocks on a FIFO).
    bool Exists(const char* file) const override {
        std::error_code ec;
        return std::filesystem::exists(file, ec);
    }
    Assimp::IOStream* Open(const char* file, const char* mode = "rb") override {
        std::uintmax_t bytes = 0;
        const std::string why = openError(file, bytes);
        if (why.empty()) return Assimp::DefaultIOSystem::Open(file, mode);
        std::error_code ec;
        if (refused_.empty() && std::filesystem::exists(file, ec)) refused_ = why;
        return nullptr;
    }
    /// The first file refused that exists (a missing one is assimp's to report), or "".
    const std::string& refused() const { return refused_; }

private:
    std::string refused_;
};

// A triangle with a repeated corner or no area: its cross product below kDegenerateArea times
// its longest edge squared (relative, so the same at every scale).
bool degenerate(const std::array<Vec3, 3>& t) {
    const Vec3& a = t[0];
    const Vec3& b = t[1];
    const Vec3& c = t[2];
    if (a == b || b == c || a == c) return true;
    const Real longest2 =
        std::max({(b - a).squaredNorm(), (c - a).squaredNorm(), (c - b).squaredNorm()});
    return !((b - a).cross(c - a).norm() > kDegenerateArea * longest2);
}

// Every triangle of every mesh of `scene` into `mesh`, scaled, welding equal positions across
// meshes too (exact comparison: the file's shared vertices are bit-identical after the same
// transform and scale) and dropping degenerate triangles, whose corners go to `dropped`.
// Returns an error, or "".
// `offset` is added (in double) to assimp's coordinates before scaling: the file's text was handed
// to assimp recentred by it. Counts the triangles read and dropped in `report`.
std::string mergeMeshes(const aiScene& scene, Real scale, const Vec3& offset,
                        const std::filesystem::path& file, collision::TriangleMesh& mesh,
                        MeshImportReport& report, std::vector<std::array<Vec3, 3>>& dropped) {
    std::map<std::array<Real, 3>, std::int32_t> index_of;
    for (unsigned mi = 0; mi < scene.mNumMeshes; ++mi) {
        const aiMesh* am = scene.mMeshes[mi];
        if (am == nullptr || am->mVertices == nullptr) continue;
        std::vector<std::int32_t> local(am->mNumVertices, -1);
        for (unsigned fi = 0; fi < am->mNumFaces; ++fi) {
            const aiFace& face = am->mFaces[fi];
            if (face.mNumIndices != 3) continue;
            std::array<std::int32_t, 3> tri{};
            bool valid = true;
            for (int k = 0; k < 3; ++k) {
                const unsigned vi = face.mIndices[k];
                if (vi >= am->mNumVertices) {
                    valid = false;
                    break;
                }
                if (local[vi] < 0) {
                    const aiVector3D& v = am->mVertices[vi];
                    const Vec3 p = (Vec3(Real(v.x), Real(v.y), Real(v.z)) + offset) * scale;
                    if (!p.allFinite()) {
                        return "non-finite vertex in '" + file.string() + "'";
                    }
                    const std::array<Real, 3> key = {p.x(), p.y(), p.z()};
                    const auto [it, inserted] =
                        index_of.emplace(key, static_cast<std::int32_t>(mesh.vertices.size()));
                    if (inserted) mesh.vertices.push_back(p);
                    local[vi] = it->second;
                }
                tri[k] = local[vi];
            }
            if (!valid) continue;
            ++report.triangles_read;
            const std::array<Vec3, 3> corners = {mesh.vertices[tri[0]], mesh.vertices[tri[1]],
                                                 mesh.vertices[tri[2]]};
            if (degenerate(corners)) {
                ++report.degenerate_dropped;
                dropped.push_back(corners);
                continue;
            }
            mesh.triangles.push_back(tri);
        }
    }
    return "";
}

// The file's coordinates against what float makes of them (relative to `offset`, as assimp reads
// the recentred text): the largest rounding of one coordinate and the distinct positions that
// coincide after it. Assumes correctly rounded parsing, which assimp's fast_atof approaches to an
// ulp or two.
// x rounded to float and back. Through a volatile: GCC 12's vectorizer at -O2 was seen to drop
// such a round trip in a loop over triangle corners (1250 collapsed triangles counted as 0).
Real roundedToFloat(Real x) {
    const volatile float f = static_cast<float>(x);
    return Real(f);
}

void measureRounding(const std::vector<Vec3>& points, const Vec3& offset,
                     MeshImportReport& report) {
    std::vector<std::array<Real, 3>> read;
    std::vector<std::array<Real, 3>> rounded;
    read.reserve(points.size());
    rounded.reserve(points.size());
    for (const Vec3& p : points) {
        std::array<Real, 3> r{};
        for (int a = 0; a < 3; ++a) {
            r[a] = roundedToFloat(p[a] - offset[a]) + offset[a];
            report.max_rounding = std::max(report.max_rounding, std::abs(r[a] - p[a]));
        }
        read.push_back({p.x(), p.y(), p.z()});
        rounded.push_back(r);
    }
    const auto distinct = [](std::vector<std::array<Real, 3>>& v) {
        std::sort(v.begin(), v.end());
        return std::unique(v.begin(), v.end()) - v.begin();
    };
    report.vertices_merged = distinct(read) - distinct(rounded);
}

// The triangles mergeMeshes dropped, told apart by the file's own coordinates: each corner is
// matched to the text point that imports as exactly that position (rounded to float relative to
// `offset`, then scaled, as mergeMeshes computes it; the model measureRounding uses), and the
// triangle of those points in double is degenerate or not. A corner two text points import as,
// or none (assimp's parse was not correctly rounded), leaves its triangle unmatched.
void classifyDropped(const std::vector<Vec3>& points, Real scale, const Vec3& offset,
                     const std::vector<std::array<Vec3, 3>>& dropped, MeshImportReport& report) {
    constexpr std::size_t kAmbiguous = std::numeric_limits<std::size_t>::max();
    std::map<std::array<Real, 3>, std::size_t> point_of;
    for (std::size_t i = 0; i < points.size(); ++i) {
        Vec3 r;
        for (int a = 0; a < 3; ++a) r[a] = roundedToFloat(points[i][a] - offset[a]);
        const Vec3 imported = (r + offset) * scale;
        const auto [it, inserted] =
            point_of.emplace(std::array<Real, 3>{imported.x(), imported.y(), imported.z()}, i);
        if (!inserted && points[it->second] != points[i]) it->second = kAmbiguous;
    }
    for (const std::array<Vec3, 3>& t : dropped) {
        std::array<Vec3, 3> in_file;
        bool matched = true;
        for (int k = 0; k < 3 && matched; ++k) {
            const auto it = point_of.find({t[k].x(), t[k].y(), t[k].z()});
            matched = it != point_of.end() && it->second != kAmbiguous;
            if (matched) in_file[k] = points[it->second] * scale;
        }
        if (!matched) continue;
        if (degenerate(in_file)) {
            ++report.degenerate_in_file;
        } else {
            ++report.degenerate_by_rounding;
        }
    }
}

// Largest |coordinate| and bounding-box diagonal of `points`.
void measureExtent(const std::vector<Vec3>& points, Real scale, MeshImportReport& report) {
    if (points.empty()) return;
    Vec3 lo = points.front() / scale;
    Vec3 hi = lo;
    for (const Vec3& p : points) {
        lo = lo.cwiseMin(p / scale);
        hi = hi.cwiseMax(p / scale);
    }
    report.max_coordinate = std::max(lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff());
    report.size = (hi - lo).norm();
}

// 3 significant digits, for the numbers of a warning.
std::string brief(Real v) {
    std::ostringstream s;
    s << std::setprecision(3) << v;
    return s.str();
}

}  // namespace

bool MeshImportReport::changed() const {
    return degenerate_dropped > 0 || vertices_merged > 0 ||
           max_rounding > kRoundingWarnFraction * size;
}

std::string describeImportChanges(const MeshImportReport& r) {
    if (!r.changed()) return "";
    const bool rounding = r.max_rounding > kRoundingWarnFraction * r.size;
    std::string what = "import changed the geometry:";
    std::string sep = " ";
    if (r.degenerate_dropped > 0) {
        what += sep + "dropped " + std::to_string(r.degenerate_dropped) + " of " +
                std::to_string(r.triangles_read) +
                " triangles as degenerate (a repeated vertex or no area)";
        sep = ", ";
    }
    if (r.vertices_merged > 0) {
        what += sep + "merged " + std::to_string(r.vertices_merged) + " vertices";
        sep = ", ";
    }
    if (rounding) {
        what += sep + "rounded coordinates by up to " + brief(r.max_rounding) + " (" +
                brief(100 * r.max_rounding / r.size) + "% of the mesh's size " + brief(r.size) +
                ")";
    }
    const std::string way_out =
        "float coordinates (assimp's, and some formats' own, as binary STL's) keep about 7 "
        "significant digits of the largest coordinate (here " +
        brief(r.max_coordinate) + ", for a mesh of size " + brief(r.size) +
        "); move the mesh's coordinates near its own origin (subtract its centre when exporting) "
        "and place it with the body's position";
    if (!r.coordinates_checked) {
        return what + "; this format's coordinates are not checked against float rounding, " +
               "which collapses the triangles of a mesh far from its own origin; if that is the " +
               "cause: " + way_out;
    }
    if (r.vertices_merged == 0 && !rounding) {
        if (r.degenerate_by_rounding > 0) {
            return what + "; " + std::to_string(r.degenerate_by_rounding) +
                   " of them have area in the file's coordinates and none in float's (slivers "
                   "thinner than float resolves at this size, not a matter of where the mesh "
                   "lies)";
        }
        if (r.degenerate_in_file == r.degenerate_dropped) {
            return what + "; they are degenerate in the file itself (nothing was lost to rounding)";
        }
        return what + "; " + std::to_string(r.degenerate_dropped - r.degenerate_in_file) +
               " of them could not be matched to the file's coordinates (assimp read them "
               "differently from a correctly rounded parse), so rounding may be the cause";
    }
    return what + ": " + way_out;
}

MeshImportOutput importMesh(const std::filesystem::path& file, collision::Real scale) {
    MeshImportOutput out;
    if (!(scale > 0) || !std::isfinite(scale)) {
        out.error = "scale must be finite and > 0";
        return out;
    }
    out.error = fileError(file);
    if (!out.error.empty()) return out;

    Assimp::Importer importer;
    auto* io = new CheckedIoSystem;
    importer.SetIOHandler(io);  // the importer owns it
    // Only positions matter: drop normals, UVs and colours, and point and line primitives.
    // No JoinIdenticalVertices: it joins positions within an absolute 1e-5 of each other, which
    // merges the corners of a mesh a few micrometres across; mergeMeshes welds exactly equal
    // positions itself, which is all a vertex split at a normal seam needs.
    importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS,
                                aiComponent_NORMALS | aiComponent_TANGENTS_AND_BITANGENTS |
                                    aiComponent_COLORS | aiComponent_TEXCOORDS |
                                    aiComponent_BONEWEIGHTS | aiComponent_ANIMATIONS |
                                    aiComponent_TEXTURES | aiComponent_LIGHTS |
                                    aiComponent_CAMERAS | aiComponent_MATERIALS);
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                                aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    const unsigned flags = aiProcess_RemoveComponent | aiProcess_Triangulate |
                           aiProcess_PreTransformVertices | aiProcess_SortByPType |
                           aiProcess_ValidateDataStructure;
    // Text formats: the coordinates in double, to measure the rounding and, far from the origin,
    // to hand assimp the text recentred on the bounding box (every other byte unchanged).
    MeshImportReport& report = out.report;
    const TextCoordinates text = readTextCoordinates(file);
    std::string recentred_text;
    if (text.ok && !text.points.empty()) {
        report.coordinates_checked = true;
        measureExtent(text.points, 1, report);
        Vec3 lo = text.points.front();
        Vec3 hi = lo;
        for (const Vec3& p : text.points) {
            lo = lo.cwiseMin(p);
            hi = hi.cwiseMax(p);
        }
        if (report.max_coordinate > kRecentreRatio * (hi - lo).maxCoeff()) {
            report.recentred = true;
            report.offset = (lo + hi) / 2;
            recentred_text = shiftedText(text, report.offset);
        }
        measureRounding(text.points, report.offset, report);
    }
    const aiScene* scene = nullptr;
    try {
        scene = report.recentred
                    ? importer.ReadFileFromMemory(recentred_text.data(), recentred_text.size(),
                                                  flags, text.hint.c_str())
                    : importer.ReadFile(file.string(), flags);
    } catch (const std::exception& e) {
        out.error = std::string("assimp failed: ") + e.what();
        return out;
    } catch (...) {
        out.error = "assimp failed";
        return out;
    }
    if (!io->refused().empty()) {
        out.error = file.string() + " refers to a file that cannot be read: " + io->refused();
        return out;
    }
    if (scene == nullptr) {
        std::string why = importer.GetErrorString();
        if (why.empty()) why = "unknown error";
        out.error = "cannot read '" + file.string() + "': " + why;
        return out;
    }

    collision::TriangleMesh& mesh = out.mesh;
    std::vector<std::array<Vec3, 3>> dropped;
    out.error = mergeMeshes(*scene, scale, report.offset, file, mesh, report, dropped);
    if (!out.error.empty()) {
        mesh = {};
        return out;
    }
    if (report.coordinates_checked && !dropped.empty()) {
        classifyDropped(text.points, scale, report.offset, dropped, report);
    }
    if (!report.coordinates_checked) measureExtent(mesh.vertices, scale, report);
    if (mesh.triangles.empty()) {
        mesh = {};
        out.error = "no triangles in '" + file.string() + "'";
        if (report.triangles_read > 0) out.error += ": " + describeImportChanges(report);
        return out;
    }
    // Drop vertices only referenced by dropped triangles, keeping first-use order.
    std::vector<std::int32_t> remap(mesh.vertices.size(), -1);
    std::vector<Vec3> used;
    for (auto& t : mesh.triangles) {
        for (std::int32_t& v : t) {
            if (remap[v] < 0) {
                remap[v] = static_cast<std::int32_t>(used.size());
                used.push_back(mesh.vertices[v]);
            }
            v = remap[v];
        }
    }
    mesh.vertices = std::move(used);
    out.ok = true;
    return out;
}

}  // namespace engine
