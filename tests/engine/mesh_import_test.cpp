// tests/engine/mesh_import_test.cpp -- OBJ files written to a temporary folder, read via assimp.
#include "engine/mesh_import.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <utility>

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

TEST_F(MeshImport, FilesPastTheSizeLimitAreRefusedUnread) {
    const fs::path p = write("big.obj", kCubeObj);
    fs::resize_file(p, (std::uintmax_t(256) << 20) + 1);  // sparse: nothing is written
    const MeshImportOutput out = importMesh(p, 1);
    EXPECT_FALSE(out.ok);
    EXPECT_NE(out.error.find("more than the limit of 268435456 (256 MiB)"), std::string::npos)
        << out.error;
}

TEST_F(MeshImport, ProjectAssetsAreClosedMeshes) {
    for (const char* name : {"torus.obj", "crystal.obj", "spaceship.obj"}) {
        const fs::path p = fs::path(CDLAB_SOURCE_DIR) / "assets" / name;
        const MeshImportOutput out = importMesh(p, 1);
        ASSERT_TRUE(out.ok) << name << ": " << out.error;
        EXPECT_TRUE(closedAndOriented(out.mesh)) << name;
        EXPECT_GE(out.mesh.triangles.size(), 20u) << name;
    }
}

}  // namespace
}  // namespace engine
