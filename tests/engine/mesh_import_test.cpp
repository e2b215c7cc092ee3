// tests/engine/mesh_import_test.cpp -- OBJ files written to a temporary folder, read via assimp.
#include "engine/mesh_import.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace engine {
namespace {

namespace fs = std::filesystem;
using collision::Vec3;

class MeshImport : public ::testing::Test {
protected:
    void SetUp() override {
        const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() / ("cdlab_mesh_import_" + std::string(info->name()));
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }

    fs::path write(const std::string& name, const std::string& text) {
        const fs::path p = dir_ / name;
        std::ofstream(p, std::ios::binary) << text;
        return p;
    }

    fs::path dir_;
};

// A unit cube written as 6 quads, with per-face normals so that assimp first splits the corners
// (3 normals each); the importer must still weld them to 8 vertices.
const char* const kCubeObj = R"(# unit cube
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
vn 0 0 -1
vn 0 0 1
vn 0 -1 0
vn 0 1 0
vn -1 0 0
vn 1 0 0
f 1//1 4//1 3//1 2//1
f 5//2 6//2 7//2 8//2
f 1//3 2//3 6//3 5//3
f 4//4 8//4 7//4 3//4
f 1//5 5//5 8//5 4//5
f 2//6 3//6 7//6 6//6
)";

// Every directed edge has its reverse: closed and consistently oriented.
bool closedAndOriented(const collision::TriangleMesh& m) {
    std::map<std::pair<int, int>, int> edges;
    for (const auto& t : m.triangles) {
        for (int e = 0; e < 3; ++e) ++edges[{t[e], t[(e + 1) % 3]}];
    }
    for (const auto& [e, n] : edges) {
        if (n != 1 || edges.count({e.second, e.first}) != 1) return false;
    }
    return true;
}

TEST_F(MeshImport, CubeHasTwelveTrianglesAndEightVertices) {
    const MeshImportOutput out = importMesh(write("cube.obj", kCubeObj), 1);
    ASSERT_TRUE(out.ok) << out.error;
    EXPECT_EQ(out.mesh.triangles.size(), 12u);
    EXPECT_EQ(out.mesh.vertices.size(), 8u);
    EXPECT_TRUE(closedAndOriented(out.mesh));
    // Outward: signed volume via the divergence theorem is +1.
    double volume = 0;
    for (const auto& t : out.mesh.triangles) {
        volume +=
            out.mesh.vertices[t[0]].dot(out.mesh.vertices[t[1]].cross(out.mesh.vertices[t[2]])) / 6;
    }
    EXPECT_NEAR(volume, 1.0, 1e-12);
}

TEST_F(MeshImport, ScaleMultipliesCoordinates) {
    const MeshImportOutput out = importMesh(write("cube.obj", kCubeObj), 2.5);
    ASSERT_TRUE(out.ok) << out.error;
    Vec3 hi = Vec3::Constant(-1);
    for (const Vec3& v : out.mesh.vertices) hi = hi.cwiseMax(v);
    EXPECT_EQ(hi, Vec3::Constant(2.5));
}

TEST_F(MeshImport, TwoObjectsAreMergedAndWelded) {
    // Two tetrahedra sharing vertex (0,0,0), written as separate objects with their own
    // vertex lists: 7 distinct positions, 8 triangles.
    const std::string text = R"(o a
v 0 0 0
v 1 0 0
v 0 1 0
v 0 0 1
f 1 3 2
f 1 2 4
f 1 4 3
f 2 3 4
o b
v 0 0 0
v -1 0 0
v 0 -1 0
v 0 0 -1
f 5 6 7
f 5 8 6
f 5 7 8
f 6 8 7
)";
    const MeshImportOutput out = importMesh(write("two.obj", text), 1);
    ASSERT_TRUE(out.ok) << out.error;
    EXPECT_EQ(out.mesh.triangles.size(), 8u);
    EXPECT_EQ(out.mesh.vertices.size(), 7u);
}

// Small meshes keep every vertex: nothing but exactly equal positions is welded (a join within a
// fixed distance, such as assimp's 1e-5, merges the corners of a mesh a few micrometres across).
TEST_F(MeshImport, AMicrometreTetrahedronKeepsItsFourVertices) {
    const std::string text =
        "v 0 0 0\nv 3e-6 0 0\nv 0 3e-6 0\nv 0 0 3e-6\n"
        "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    const MeshImportOutput out = importMesh(write("tiny.obj", text), 1);
    ASSERT_TRUE(out.ok) << out.error;
    EXPECT_EQ(out.mesh.vertices.size(), 4u);
    EXPECT_EQ(out.mesh.triangles.size(), 4u);
    EXPECT_TRUE(closedAndOriented(out.mesh));
    EXPECT_FALSE(out.report.changed()) << describeImportChanges(out.report);
}

// A cube of side 2^-26 (exact in float and in the text): eight vertices, twelve triangles, and a
// report that says nothing changed.
TEST_F(MeshImport, ACubeOfSideTwoToTheMinus26KeepsItsEightVertices) {
    const double side = std::ldexp(1.0, -26);
    char value[64];
    std::snprintf(value, sizeof value, "%.17g", side);
    std::string text = kCubeObj;
    std::string scaled;
    // kCubeObj's coordinates are 0 and 1 on the vertex lines: 1 becomes the side.
    for (std::size_t at = 0, end; at < text.size(); at = end + 1) {
        end = text.find('\n', at);
        if (end == std::string::npos) end = text.size();
        std::string line = text.substr(at, end - at);
        if (line.rfind("v ", 0) == 0) {
            std::string out = "v";
            for (std::size_t k = 2; k < line.size(); k += 2) {
                out += line[k] == '1' ? std::string(" ") + value : std::string(" 0");
            }
            line = out;
        }
        scaled += line + "\n";
    }
    const MeshImportOutput out = importMesh(write("small_cube.obj", scaled), 1);
    ASSERT_TRUE(out.ok) << out.error;
    EXPECT_EQ(out.mesh.vertices.size(), 8u);
    EXPECT_EQ(out.mesh.triangles.size(), 12u);
    EXPECT_TRUE(closedAndOriented(out.mesh));
    for (const Vec3& v : out.mesh.vertices) {
        for (int a = 0; a < 3; ++a) EXPECT_TRUE(v[a] == 0 || v[a] == side) << v.transpose();
    }
    EXPECT_FALSE(out.report.changed()) << describeImportChanges(out.report);
}

TEST_F(MeshImport, DegenerateTrianglesAreDropped) {
    const std::string text = R"(v 0 0 0
v 1 0 0
v 0 1 0
v 2 0 0
f 1 2 3
f 1 2 4
)";
    const MeshImportOutput out = importMesh(write("degenerate.obj", text), 1);
    ASSERT_TRUE(out.ok) << out.error;
    EXPECT_EQ(out.mesh.triangles.size(), 1u);
    EXPECT_EQ(out.mesh.vertices.size(), 3u);  // the unused vertex is dropped too
    EXPECT_EQ(out.report.triangles_read, 2);
    EXPECT_EQ(out.report.degenerate_dropped, 1);
}

TEST_F(MeshImport, MissingFileIsAClearError) {
    const MeshImportOutput out = importMesh(dir_ / "nope.obj", 1);
    EXPECT_FALSE(out.ok);
    EXPECT_NE(out.error.find("no such file"), std::string::npos) << out.error;
    EXPECT_NE(out.error.find("nope.obj"), std::string::npos) << out.error;
}

TEST_F(MeshImport, DirectoryIsAClearError) {
    const MeshImportOutput out = importMesh(dir_, 1);
    EXPECT_FALSE(out.ok);
    EXPECT_NE(out.error.find("not a regular file"), std::string::npos) << out.error;
}

TEST_F(MeshImport, GarbageFileIsAnError) {
    std::string bytes;
    for (int i = 0; i < 4096; ++i) bytes.push_back(static_cast<char>((i * 7919 + 13) % 256));
    for (const char* name : {"garbage.obj", "garbage.stl", "garbage.xyz"}) {
        const MeshImportOutput out = importMesh(write(name, bytes), 1);
        EXPECT_FALSE(out.ok) << name;
        EXPECT_FALSE(out.error.empty()) << name;
    }
    const MeshImportOutput empty = importMesh(write("empty.obj", ""), 1);
    EXPECT_FALSE(empty.ok);
    EXPECT_FALSE(empty.error.empty());
}

TEST_F(MeshImport, FileWithoutTrianglesIsAnError) {
    const std::string text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\n";
    const MeshImportOutput out = importMesh(write("lines.obj", text), 1);
    EXPECT_FALSE(out.ok);
    EXPECT_FALSE(out.error.empty());
    const MeshImportOutput flat = importMesh(write("points.obj", "v 0 0 0\nv 1 1 1\n"), 1);
    EXPECT_FALSE(flat.ok);
    EXPECT_FALSE(flat.error.empty());
}

TEST_F(MeshImport, BadScaleIsAnError) {
    const fs::path p = write("cube.obj", kCubeObj);
    EXPECT_FALSE(importMesh(p, 0).ok);
    EXPECT_FALSE(importMesh(p, -1).ok);
    EXPECT_FALSE(importMesh(p, std::nan("")).ok);
}

// Regression: a 100-byte OFF header claiming 2e8 vertices took assimp 5.5 GB and 16 s to refuse,
// and the same lie in an ASCII PLY did not finish in a minute. Counts the file's bytes cannot hold
// are refused before assimp reads the file; honest headers of the same formats still load.
TEST_F(MeshImport, HeaderCountsTheFileCannotHoldAreRefusedUpFront) {
    const std::string cube_vertices = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n";
    const std::string cube_faces =
        "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 3 7 6 2\n4 0 4 7 3\n4 1 2 6 5\n";
    const MeshImportOutput off =
        importMesh(write("cube.off", "OFF\n8 6 0\n" + cube_vertices + cube_faces), 1);
    ASSERT_TRUE(off.ok) << off.error;
    EXPECT_EQ(off.mesh.triangles.size(), 12u);
    const std::string ply_header =
        "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\n"
        "property float y\nproperty float z\nelement face 6\n"
        "property list uchar int vertex_indices\nend_header\n";
    const MeshImportOutput ply =
        importMesh(write("cube.ply", ply_header + cube_vertices + cube_faces), 1);
    ASSERT_TRUE(ply.ok) << ply.error;
    EXPECT_EQ(ply.mesh.triangles.size(), 12u);

    struct Lie {
        const char* name;
        std::string text;
    };
    std::string binary_ply =
        "ply\nformat binary_little_endian 1.0\nelement vertex 200000000\nproperty float x\n"
        "property float y\nproperty float z\nelement face 1\n"
        "property list uchar int vertex_indices\nend_header\n";
    binary_ply += std::string(9 * 4 + 1 + 3 * 4, '\0');
    const Lie lies[] = {
        {"lie.off", "OFF\n200000000 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"},
        {"lie_same_line.off", "OFF 200000000 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"},
        {"lie_faces.off", "# comment\nOFF\n3 900000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"},
        {"lie.ply",
         "ply\nformat ascii 1.0\nelement vertex 200000000\nproperty float x\n"
         "property float y\nproperty float z\nelement face 1\n"
         "property list uchar int vertex_indices\nend_header\n"
         "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"},
        {"lie_binary.ply", binary_ply},
    };
    for (const Lie& lie : lies) {
        SCOPED_TRACE(lie.name);
        const MeshImportOutput out = importMesh(write(lie.name, lie.text), 1);
        EXPECT_FALSE(out.ok);
        EXPECT_NE(out.error.find("bytes can hold (a truncated or corrupt file)"), std::string::npos)
            << out.error;
        EXPECT_NE(out.error.find("declares "), std::string::npos) << out.error;
    }
}

// A PLY header that never ends (no end_header line) kept assimp's reader at 100% CPU forever:
// refused by name before assimp reads it, whether the header is short or runs past the part read.
TEST_F(MeshImport, APlyHeaderWithoutEndHeaderIsRefused) {
    const std::string header =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\n";
    const std::string body = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    std::string long_comments;
    while (long_comments.size() < 100 * 1024) long_comments += "comment padding the header\n";
    const std::pair<const char*, std::string> files[] = {
        {"open.ply", header + body},
        {"open_long.ply", header + long_comments + body},
    };
    for (const auto& [name, text] : files) {
        SCOPED_TRACE(name);
        const MeshImportOutput out = importMesh(write(name, text), 1);
        EXPECT_FALSE(out.ok);
        EXPECT_NE(out.error.find(name), std::string::npos) << out.error;
        EXPECT_NE(out.error.find("end_header"), std::string::npos) << out.error;
    }
    // The same file with its end_header loads.
    const MeshImportOutput closed =
        importMesh(write("closed.ply", header + "end_header\n" + body), 1);
    ASSERT_TRUE(closed.ok) << closed.error;
    EXPECT_EQ(closed.mesh.triangles.size(), 1u);
}

// Files a model refers to (an OBJ's mtllib here) obey the model file's rules: a FIFO blocked the
// import forever, /dev/zero and a sparse file past the size limit were read whole. Each is refused
// unopened, naming the model and the file; a readable material file changes nothing.
TEST_F(MeshImport, FilesAModelRefersToAreCheckedLikeTheModel) {
    const fs::path fifo = write("fifo.mtl", "");
    fs::remove(fifo);
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    const fs::path zero = dir_ / "zero.mtl";
    fs::create_symlink("/dev/zero", zero);
    const fs::path big = write("big.mtl", "newmtl m\n");
    fs::resize_file(big, (std::uintmax_t(256) << 20) + 1);  // sparse
    for (const fs::path& ref : {fifo, zero, big}) {
        SCOPED_TRACE(ref.filename().string());
        const fs::path obj = write("with_" + ref.stem().string() + ".obj",
                                   "mtllib " + ref.filename().string() + "\n" +
                                       std::string(kCubeObj));
        const MeshImportOutput out = importMesh(obj, 1);
        EXPECT_FALSE(out.ok);
        EXPECT_NE(out.error.find(obj.string()), std::string::npos) << out.error;
        EXPECT_NE(out.error.find(ref.string()), std::string::npos) << out.error;
    }
    write("plain.mtl", "newmtl m\nKd 1 0 0\n");
    const MeshImportOutput plain =
        importMesh(write("with_plain.obj", "mtllib plain.mtl\n" + std::string(kCubeObj)), 1);
    ASSERT_TRUE(plain.ok) << plain.error;
    EXPECT_EQ(plain.mesh.triangles.size(), 12u);
}

TEST_F(MeshImport, FilesPastTheSizeLimitAreRefusedUnread) {
    const fs::path p = write("big.obj", kCubeObj);
    fs::resize_file(p, (std::uintmax_t(256) << 20) + 1);  // sparse: nothing is written
    const MeshImportOutput out = importMesh(p, 1);
    EXPECT_FALSE(out.ok);
    EXPECT_NE(out.error.find("more than the limit of 268435456 (256 MiB)"), std::string::npos)
        << out.error;
}

// x rounded to float and back; volatile, since GCC 12's vectorizer at -O2 dropped the round trip
// in degenerateInFloat's loop (it counted 0 collapsed triangles instead of 1250).
double roundedToFloat(double x) {
    const volatile float f = static_cast<float>(x);
    return double(f);
}

// A fine grid near (1e6, 1e6): n x n cells of `h` (1 cm), z a small ripple; two triangles a cell.
// Float keeps 1/16 at 1e6, so most of its vertices collapse onto each other in float.
struct FarGrid {
    static constexpr int kN = 30;
    static constexpr double kH = 0.01;
    static constexpr double kOrigin = 1e6;
    std::vector<std::array<double, 3>> vertices;
    std::vector<std::array<int, 3>> triangles;
    FarGrid() {
        for (int i = 0; i <= kN; ++i) {
            for (int j = 0; j <= kN; ++j) {
                vertices.push_back({kOrigin + i * kH, kOrigin + j * kH, 0.001 * ((i + j) % 3)});
            }
        }
        const auto at = [](int i, int j) { return i * (kN + 1) + j; };
        for (int i = 0; i < kN; ++i) {
            for (int j = 0; j < kN; ++j) {
                triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
                triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
            }
        }
    }
    std::string obj() const {
        std::string text;
        char line[128];
        for (const auto& v : vertices) {
            std::snprintf(line, sizeof line, "v %.10f %.10f %.10f\n", v[0], v[1], v[2]);
            text += line;
        }
        for (const auto& t : triangles) {
            text += "f " + std::to_string(t[0] + 1) + " " + std::to_string(t[1] + 1) + " " +
                    std::to_string(t[2] + 1) + "\n";
        }
        return text;
    }
    // Binary STL: float in the file itself.
    std::string binaryStl() const {
        std::string bytes(80, '\0');
        const auto put = [&bytes](const void* p, std::size_t n) {
            bytes.append(static_cast<const char*>(p), n);
        };
        const std::uint32_t count = static_cast<std::uint32_t>(triangles.size());
        put(&count, 4);
        for (const auto& t : triangles) {
            const float normal[3] = {0, 0, 1};
            put(normal, sizeof normal);
            for (const int k : t) {
                const float v[3] = {float(vertices[k][0]), float(vertices[k][1]),
                                    float(vertices[k][2])};
                put(v, sizeof v);
            }
            const std::uint16_t attribute = 0;
            put(&attribute, 2);
        }
        return bytes;
    }
    // Triangles that have a repeated corner or no area once their corners are floats: computed
    // here from the grid itself, independently of the importer. The rounded corners lie on a
    // lattice of exactly representable steps, so the cross product is exact and zero means zero.
    int degenerateInFloat() const {
        int n = 0;
        for (const auto& t : triangles) {
            std::array<Vec3, 3> c;
            for (int k = 0; k < 3; ++k) {
                const auto& v = vertices[t[k]];
                c[k] = Vec3(roundedToFloat(v[0]), roundedToFloat(v[1]), roundedToFloat(v[2]));
            }
            if (c[0] == c[1] || c[1] == c[2] || c[0] == c[2] ||
                (c[1] - c[0]).cross(c[2] - c[0]).squaredNorm() == 0) {
                ++n;
            }
        }
        return n;
    }
};

// A fine grid near 1e6 lost 2,686 of 3,732 triangles in
// assimp's float coordinates, silently. An OBJ is read in double as well, so the importer hands
// assimp its text recentred on the mesh: every triangle is kept, the coordinates come back to
// float's precision relative to the mesh's size, and there is nothing to warn about.
TEST_F(MeshImport, FarFromOriginTextMeshKeepsEveryTriangle) {
    const FarGrid grid;
    ASSERT_GT(grid.degenerateInFloat(), 1000);  // what a float import of it would lose
    const MeshImportOutput out = importMesh(write("far.obj", grid.obj()), 1);
    ASSERT_TRUE(out.ok) << out.error;
    EXPECT_EQ(out.mesh.triangles.size(), grid.triangles.size());
    EXPECT_EQ(out.mesh.vertices.size(), grid.vertices.size());
    const MeshImportReport& r = out.report;
    EXPECT_TRUE(r.coordinates_checked);
    EXPECT_TRUE(r.recentred);
    EXPECT_EQ(r.triangles_read, static_cast<std::int64_t>(grid.triangles.size()));
    EXPECT_EQ(r.degenerate_dropped, 0);
    EXPECT_EQ(r.vertices_merged, 0);
    // Float relative to the grid's half-size (0.15): 2^-24 * 0.15 ~ 1e-8.
    EXPECT_LE(r.max_rounding, 2e-8);
    EXPECT_FALSE(r.changed());
    EXPECT_EQ(describeImportChanges(r), "");
    // Each vertex within float's rounding (relative to the mesh) of the grid vertex it is.
    for (const Vec3& v : out.mesh.vertices) {
        const long i = std::lround((v.x() - FarGrid::kOrigin) / FarGrid::kH);
        const long j = std::lround((v.y() - FarGrid::kOrigin) / FarGrid::kH);
        ASSERT_TRUE(i >= 0 && i <= FarGrid::kN && j >= 0 && j <= FarGrid::kN) << v.transpose();
        const auto& g = grid.vertices[static_cast<std::size_t>(i * (FarGrid::kN + 1) + j)];
        EXPECT_LE((v - Vec3(g[0], g[1], g[2])).cwiseAbs().maxCoeff(), 2e-8) << v.transpose();
    }
}

// The same grid in a binary STL is float in the file itself: the importer cannot recover it, but
// it counts every triangle it drops and says how to get them back.
TEST_F(MeshImport, FarFromOriginFloatMeshIsReportedWithTheWayOut) {
    const FarGrid grid;
    const int expected = grid.degenerateInFloat();
    ASSERT_GT(expected, 1000);
    const MeshImportOutput out = importMesh(write("far.stl", grid.binaryStl()), 1);
    ASSERT_TRUE(out.ok) << out.error;
    const MeshImportReport& r = out.report;
    EXPECT_FALSE(r.coordinates_checked);
    EXPECT_EQ(r.triangles_read, static_cast<std::int64_t>(grid.triangles.size()));
    EXPECT_EQ(r.degenerate_dropped, expected);
    EXPECT_EQ(out.mesh.triangles.size(), grid.triangles.size() - expected);
    EXPECT_NEAR(r.max_coordinate, 1e6 + 0.3, 0.1);
    EXPECT_TRUE(r.changed());
    const std::string w = describeImportChanges(r);
    EXPECT_NE(w.find("dropped " + std::to_string(expected) + " of 1800 triangles as degenerate"),
              std::string::npos)
        << w;
    EXPECT_NE(w.find("move the mesh's coordinates near its own origin"), std::string::npos) << w;
    EXPECT_NE(w.find("place it with the body's position"), std::string::npos) << w;
}

// Two vertices 1e-9 apart near the origin of a unit mesh are one vertex in float: the report
// counts the merge, the triangle it collapses, and blames rounding (not the file).
TEST_F(MeshImport, VerticesMergedByRoundingAreCounted) {
    const std::string text =
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1.000000001 0 0\n"
        "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\nf 2 5 4\n";
    const MeshImportOutput out = importMesh(write("near.obj", text), 1);
    ASSERT_TRUE(out.ok) << out.error;
    const MeshImportReport& r = out.report;
    EXPECT_TRUE(r.coordinates_checked);
    EXPECT_FALSE(r.recentred);
    EXPECT_EQ(r.triangles_read, 5);
    EXPECT_EQ(r.degenerate_dropped, 1);
    EXPECT_EQ(r.vertices_merged, 1);
    EXPECT_NEAR(r.max_rounding, 1e-9, 1e-10);
    const std::string w = describeImportChanges(r);
    EXPECT_NE(w.find("dropped 1 of 5 triangles as degenerate"), std::string::npos) << w;
    EXPECT_NE(w.find("merged 1 vertices"), std::string::npos) << w;
    EXPECT_NE(w.find("near its own origin"), std::string::npos) << w;
}

// A triangle degenerate in the file itself is counted too, and not blamed on rounding.
TEST_F(MeshImport, DegenerateInTheFileIsNotBlamedOnRounding) {
    const MeshImportOutput out =
        importMesh(write("d.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\n"), 1);
    ASSERT_TRUE(out.ok) << out.error;
    EXPECT_EQ(out.report.degenerate_dropped, 1);
    EXPECT_EQ(out.report.degenerate_in_file, 1);
    EXPECT_EQ(out.report.degenerate_by_rounding, 0);
    EXPECT_EQ(out.report.vertices_merged, 0);
    const std::string w = describeImportChanges(out.report);
    EXPECT_NE(w.find("degenerate in the file itself"), std::string::npos) << w;
}

// A regular 20,000-gon (one face, which assimp triangulates as a fan) under a cone: around the
// fan's first corner, three neighbouring corners are 3e-4 apart and bulge by 5e-8, less than
// float's rounding at radius 1, so some fan triangles lose all area in float, though every one
// has area in the file. The report says so, and does not call them degenerate in the file.
TEST_F(MeshImport, SliversCollapsedByRoundingAreNotBlamedOnTheFile) {
    constexpr int kN = 20000;
    std::string text;
    char line[96];
    for (int k = 0; k < kN; ++k) {
        const double a = 2 * M_PI * k / kN;
        std::snprintf(line, sizeof line, "v %.17g %.17g 0\n", std::cos(a), std::sin(a));
        text += line;
    }
    text += "v 0 0 1\n";
    for (int k = 0; k < kN; ++k) {
        std::snprintf(line, sizeof line, "f %d %d %d\n", k + 1, (k + 1) % kN + 1, kN + 1);
        text += line;
    }
    text += "f";
    for (int k = kN; k >= 1; --k) {
        std::snprintf(line, sizeof line, " %d", k);
        text += line;
    }
    text += "\n";
    const MeshImportOutput out = importMesh(write("cone.obj", text), 1);
    ASSERT_TRUE(out.ok) << out.error;
    const MeshImportReport& r = out.report;
    ASSERT_TRUE(r.coordinates_checked);
    EXPECT_EQ(r.vertices_merged, 0);
    ASSERT_GT(r.degenerate_dropped, 0);
    EXPECT_EQ(r.degenerate_by_rounding, r.degenerate_dropped);
    EXPECT_EQ(r.degenerate_in_file, 0);
    const std::string w = describeImportChanges(r);
    EXPECT_EQ(w.find("degenerate in the file itself"), std::string::npos) << w;
    EXPECT_NE(w.find(std::to_string(r.degenerate_by_rounding) +
                     " of them have area in the file's coordinates"),
              std::string::npos)
        << w;
}

// The text readers agree with assimp on OFF, ASCII PLY and ASCII STL far from the origin: each is
// recentred and loses nothing.
TEST_F(MeshImport, FarFromOriginOffPlyAndAsciiStlAreRecentred) {
    const FarGrid grid;
    std::string verts;
    char line[128];
    for (const auto& v : grid.vertices) {
        std::snprintf(line, sizeof line, "%.10f %.10f %.10f\n", v[0], v[1], v[2]);
        verts += line;
    }
    std::string faces;
    for (const auto& t : grid.triangles) {
        faces += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " +
                 std::to_string(t[2]) + "\n";
    }
    const std::string nv = std::to_string(grid.vertices.size());
    const std::string nf = std::to_string(grid.triangles.size());
    std::string stl = "solid grid\n";
    for (const auto& t : grid.triangles) {
        stl += "facet normal 0 0 1\nouter loop\n";
        for (const int k : t) {
            const auto& v = grid.vertices[k];
            std::snprintf(line, sizeof line, "vertex %.10f %.10f %.10f\n", v[0], v[1], v[2]);
            stl += line;
        }
        stl += "endloop\nendfacet\n";
    }
    stl += "endsolid grid\n";
    const std::pair<const char*, std::string> files[] = {
        {"far.off", "OFF\n" + nv + " " + nf + " 0\n" + verts + faces},
        {"far.ply", "ply\nformat ascii 1.0\nelement vertex " + nv +
                        "\nproperty double x\nproperty double y\nproperty double z\n"
                        "element face " + nf +
                        "\nproperty list uchar int vertex_indices\nend_header\n" + verts + faces},
        {"far_ascii.stl", stl},
    };
    for (const auto& [name, text] : files) {
        SCOPED_TRACE(name);
        const MeshImportOutput out = importMesh(write(name, text), 1);
        ASSERT_TRUE(out.ok) << out.error;
        EXPECT_TRUE(out.report.coordinates_checked);
        EXPECT_TRUE(out.report.recentred);
        EXPECT_EQ(out.mesh.triangles.size(), grid.triangles.size());
        EXPECT_EQ(out.report.degenerate_dropped, 0);
        EXPECT_FALSE(out.report.changed()) << describeImportChanges(out.report);
    }
}

TEST_F(MeshImport, ProjectAssetsAreClosedMeshes) {
    for (const char* name : {"torus.obj", "crystal.obj", "spaceship.obj"}) {
        const fs::path p = fs::path(CDLAB_SOURCE_DIR) / "assets" / name;
        const MeshImportOutput out = importMesh(p, 1);
        ASSERT_TRUE(out.ok) << name << ": " << out.error;
        EXPECT_TRUE(closedAndOriented(out.mesh)) << name;
        EXPECT_GE(out.mesh.triangles.size(), 20u) << name;
        // Read in double too, near their origin (not recentred), and nothing lost.
        EXPECT_TRUE(out.report.coordinates_checked) << name;
        EXPECT_FALSE(out.report.recentred) << name;
        EXPECT_FALSE(out.report.changed()) << name << ": " << describeImportChanges(out.report);
    }
}

}  // namespace
}  // namespace engine
