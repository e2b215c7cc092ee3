// tests/engine/scene_meshes_test.cpp -- mesh and hull bodies in scene files: paths relative to
// the scene, one import shared, open and flat meshes, mass and inertia overrides, import notes.
#include "engine/scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "collision/bvh/bvh.h"
#include "engine/mass_properties.h"
#include "scene_error.h"
#include "scene_text.h"

namespace engine {
namespace {

using namespace scene_text;
namespace fs = std::filesystem;

class SceneMeshes : public ::testing::Test {
protected:
    void SetUp() override {
        const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() / ("cdlab_scene_" + std::string(info->name()));
        fs::remove_all(dir_);
        fs::create_directories(dir_ / "meshes");
    }
    void TearDown() override { fs::remove_all(dir_); }
    void write(const fs::path& rel, const std::string& text) {
        std::ofstream(dir_ / rel, std::ios::binary) << text;
    }
    fs::path dir_;
};

// A unit cube centred at (5, 0, 0): its file origin is not its centre of mass.
const char* const kOffsetCubeObj =
    "v 4.5 -0.5 -0.5\nv 5.5 -0.5 -0.5\nv 5.5 0.5 -0.5\nv 4.5 0.5 -0.5\n"
    "v 4.5 -0.5 0.5\nv 5.5 -0.5 0.5\nv 5.5 0.5 0.5\nv 4.5 0.5 0.5\n"
    "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n";

TEST_F(SceneMeshes, MeshPathIsRelativeToTheSceneFile) {
    write("meshes/cube.obj", kOffsetCubeObj);
    write("scene.yaml", kHeader +
                            "  - shape: mesh\n    file: meshes/cube.obj\n"
                            "    position: [1, 2, 3]\n    density: 10\n");
    const Scene s = loadScene(dir_ / "scene.yaml");
    EXPECT_EQ(s.name, "scene");
    ASSERT_EQ(s.bodies.size(), 1u);
    const Body& b = s.bodies[0];
    EXPECT_NEAR(b.mass, 10.0, 1e-12);
    // Re-centred: the local origin is the centre of mass, and `position` is where it goes.
    EXPECT_EQ(b.position, Vec3(1, 2, 3));
    for (const Vec3& v : b.shape.mesh->vertices) EXPECT_NEAR(v.cwiseAbs().maxCoeff(), 0.5, 1e-12);
    for (const Vec3& v : b.shape.hull->vertices) EXPECT_NEAR(v.cwiseAbs().maxCoeff(), 0.5, 1e-12);
    const MassPropertiesOutput local = computeMassProperties(b.shape, 1);
    ASSERT_TRUE(local.ok) << local.error;
    EXPECT_LE(local.props.center_of_mass.norm(), 1e-12);
    // A cube's inertia: m/6 s^2.
    EXPECT_NEAR(b.inertia_body(0, 0), 10.0 / 6, 1e-12);
    EXPECT_NEAR(b.inertia_body(0, 1), 0, 1e-12);

    // The same file through parseScene with the project's scenes/ folder as the base.
    const Scene t =
        parse(withBody("  - shape: hull\n    file: ../assets/spaceship.obj\n"
                       "    position: [0, 0, 0]\n"));
    ASSERT_EQ(t.bodies.size(), 1u);
    EXPECT_GT(t.bodies[0].shape.hull->vertices.size(), 8u);
}

TEST_F(SceneMeshes, ImportedOnceAndShared) {
    std::string text = kHeader;
    for (int i = 0; i < 4; ++i) {
        text += "  - shape: mesh\n    file: ../assets/torus.obj\n    position: [" +
                std::to_string(i) + ", 0, 0]\n";
    }
    text += "  - shape: mesh\n    file: ../scenes/../assets/torus.obj\n    position: [0, 1, 0]\n";
    text +=
        "  - shape: mesh\n    file: ../assets/torus.obj\n    scale: 2\n    position: [0, 2, 0]\n";
    text += "  - shape: hull\n    file: ../assets/torus.obj\n    position: [0, 3, 0]\n";
    const Scene s = parse(text);
    ASSERT_EQ(s.bodies.size(), 7u);
    for (int i = 1; i < 5; ++i) {
        EXPECT_EQ(s.bodies[i].shape.mesh.get(), s.bodies[0].shape.mesh.get());
        EXPECT_EQ(s.bodies[i].shape.hull.get(), s.bodies[0].shape.hull.get());
    }
    EXPECT_NE(s.bodies[5].shape.mesh.get(), s.bodies[0].shape.mesh.get());  // other scale
    EXPECT_NE(s.bodies[6].shape.hull.get(), s.bodies[0].shape.hull.get());  // hull: own COM
    // The hull fills the hole: ~1.5 times the torus's mass at the same density.
    EXPECT_GT(s.bodies[6].mass, 1.3 * s.bodies[0].mass);
}

TEST_F(SceneMeshes, MeshErrorsAreReportedAtTheFileKey) {
    EXPECT_SCENE_ERROR(withBody("  - shape: mesh\n    position: [0, 0, 0]\n"
                                "    file: ../assets/missing.obj\n"),
                       "6:5: bodies[0].file: ", "no such file");
    write("meshes/garbage.obj", std::string(200, '\x07') + "\x01\x02\x03");
    write("meshes/flat.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    write("meshes/open.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n");
    write("meshes/lines.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2 3\n");
    auto error = [&](const std::string& shape, const std::string& file) {
        return sceneErrorOf(withBody("  - shape: " + shape + "\n    file: meshes/" + file +
                                     "\n    position: [0, 0, 0]\n"),
                            dir_);
    };
    const std::string garbage = error("mesh", "garbage.obj");
    EXPECT_EQ(garbage.rfind("test.yaml:5:5: bodies[0].file: ", 0), 0u) << garbage;
    const std::string flat = error("hull", "flat.obj");
    EXPECT_EQ(flat.rfind("test.yaml:5:5: bodies[0].file: ", 0), 0u) << flat;
    EXPECT_NE(flat.find("has no volume: its points lie in one plane"), std::string::npos) << flat;
    // The open tetrahedron loads as a mesh (its hull gives the mass) and as a hull.
    EXPECT_EQ(error("mesh", "open.obj"), "");
    EXPECT_EQ(error("hull", "open.obj"), "");
    // A flat mesh has no hull, which contact response needs: the message says what to use.
    const std::string flat_mesh = error("mesh", "flat.obj");
    EXPECT_EQ(flat_mesh.rfind("test.yaml:5:5: bodies[0].file: ", 0), 0u) << flat_mesh;
    EXPECT_NE(flat_mesh.find("use 'shape: box' with a zero half extent and 'mass'"),
              std::string::npos)
        << flat_mesh;
    const std::string lines = error("mesh", "lines.obj");
    EXPECT_EQ(lines.rfind("test.yaml:5:5: bodies[0].file: ", 0), 0u) << lines;
}

// The offset unit cube without its +y face (f 4 8 7 3): an open box, 4 boundary edges.

std::string openCubeObj() {
    std::string text = kOffsetCubeObj;
    const std::string top = "f 4 8 7 3\n";
    text.erase(text.find(top), top.size());
    return text;
}

// `shape: mesh` once refused every mesh that is not closed
// ("mesh is not closed", exit 2), although collision only uses its triangles. An open box
//        +  +   <- no lid
//        |  |
//        +--+
// now loads; its mass properties are its convex hull's, i.e. the closed cube's, and a note says so.

TEST_F(SceneMeshes, OpenMeshLoadsWithItsHullsMassPropertiesAndANote) {
    write("meshes/cube.obj", kOffsetCubeObj);
    write("meshes/open_cube.obj", openCubeObj());
    const auto scene = [&](const std::string& file) {
        write("s.yaml", kHeader + "  - name: lidless\n    shape: mesh\n    file: meshes/" + file +
                            "\n    position: [1, 2, 3]\n    density: 10\n");
        return loadScene(dir_ / "s.yaml");
    };
    const Scene closed = scene("cube.obj");
    const Scene open = scene("open_cube.obj");
    EXPECT_TRUE(closed.notes.empty());
    ASSERT_EQ(open.notes.size(), 1u);
    EXPECT_EQ(open.notes[0], (dir_ / "s.yaml").string() +
                                 ":6:5: bodies[0] (lidless): mesh 'meshes/open_cube.obj' is open "
                                 "(4 boundary edges); mass properties from its convex hull "
                                 "(collision: its triangles, surface contact only)");
    const Body& o = open.bodies.at(0);
    const Body& c = closed.bodies.at(0);
    EXPECT_EQ(o.shape.mesh->triangles.size(), 10u);  // the surface as it is
    // Hull = the closed cube: mass and inertia equal to rounding (1e-12 relative).
    EXPECT_NEAR(o.mass, c.mass, 1e-12 * c.mass);
    EXPECT_LE((o.inertia_body - c.inertia_body).norm(), 1e-12 * c.inertia_body.norm());
    EXPECT_NEAR(o.inertia_body(0, 0), 10.0 / 6, 1e-12);
    // Re-centred on the hull's centre of mass, as the closed cube on its own.
    for (const Vec3& v : o.shape.mesh->vertices) EXPECT_NEAR(v.cwiseAbs().maxCoeff(), 0.5, 1e-12);
    // It simulates: a World is made and steps.
    World world = makeWorld(open);
    world.step();
    EXPECT_TRUE(world.bodies()[0].position.allFinite());
}

TEST_F(SceneMeshes, MassAndInertiaOverrideTheHull) {
    write("meshes/open_cube.obj", openCubeObj());
    const std::string mesh =
        "  - name: lidless\n    shape: mesh\n    file: meshes/open_cube.obj\n"
        "    position: [0, 0, 0]\n";
    const Scene diag = parseScene(withBody(mesh + "    mass: 3\n    inertia: [0.5, 0.6, 0.7]\n"),
                                  "test.yaml", dir_);
    const Body& d = diag.bodies.at(0);
    EXPECT_EQ(d.mass, 3);
    EXPECT_EQ(d.inertia_body, Mat3(Vec3(0.5, 0.6, 0.7).asDiagonal()));
    ASSERT_EQ(diag.notes.size(), 1u);
    EXPECT_NE(diag.notes[0].find("is open (4 boundary edges); centre of mass from its convex "
                                 "hull, mass and inertia as given"),
              std::string::npos)
        << diag.notes[0];
    const Scene full = parseScene(
        withBody(mesh + "    mass: 3\n    inertia: [[1, 0.1, 0], [0.1, 1, 0], [0, 0, 1.5]]\n"),
        "test.yaml", dir_);
    Mat3 want;
    want << 1, 0.1, 0, 0.1, 1, 0, 0, 0, 1.5;
    EXPECT_EQ(full.bodies.at(0).inertia_body, want);
    // Mass alone: the hull's inertia per kilogram, scaled (cube: m/6).
    const Scene mass = parseScene(withBody(mesh + "    mass: 3\n"), "test.yaml", dir_);
    EXPECT_NEAR(mass.bodies.at(0).inertia_body(1, 1), 3.0 / 6, 1e-12);
    // Any shape takes an inertia with its mass.
    const Body ball = parse(withBody("  - shape: sphere\n    radius: 1\n    position: [0, 0, 0]\n"
                                     "    mass: 2\n    inertia: [1, 1, 1]\n"))
                          .bodies.at(0);
    EXPECT_EQ(ball.inertia_body, Mat3::Identity());
}

TEST_F(SceneMeshes, InvalidInertiaIsAnErrorAtItsKey) {
    write("meshes/open_cube.obj", openCubeObj());
    const auto error = [&](const std::string& lines) {
        return sceneErrorOf(withBody("  - shape: mesh\n    file: meshes/open_cube.obj\n"
                                     "    position: [0, 0, 0]\n" +
                                     lines),
                            dir_);
    };
    const auto expect = [](const std::string& err, const std::string& prefix,
                           const std::string& fragment) {
        EXPECT_EQ(err.rfind(prefix, 0), 0u) << err;
        EXPECT_NE(err.find(fragment), std::string::npos) << err;
    };
    expect(error("    mass: 3\n    inertia: [1, 1, 3]\n"), "test.yaml:8:14: bodies[0].inertia: ",
           "violates the triangle inequality of principal moments");
    expect(error("    mass: 3\n    inertia: [1, -1, 1]\n"),
           "test.yaml:8:14: bodies[0].inertia: ", "must be positive definite");
    expect(error("    mass: 3\n    inertia: [1, 0, 1]\n"),
           "test.yaml:8:14: bodies[0].inertia: ", "must be positive definite");
    expect(error("    mass: 3\n    inertia: [[1, 0.5, 0], [0, 1, 0], [0, 0, 1]]\n"),
           "test.yaml:8:14: bodies[0].inertia: ", "must be symmetric");
    expect(error("    mass: 3\n    inertia: [1, 2]\n"),
           "test.yaml:8:14: bodies[0].inertia: ", "expected [ix, iy, iz]");
    expect(error("    mass: 3\n    inertia: [[1, 0, 0], [0, 1, 0]]\n"),
           "test.yaml:8:14: bodies[0].inertia: ", "expected [ix, iy, iz]");
    expect(error("    mass: 3\n    inertia: [1, x, 1]\n"),
           "test.yaml:8:18: bodies[0].inertia[1]: ", "");
    expect(error("    inertia: [1, 1, 1]\n"), "test.yaml:7:5: bodies[0].inertia: ", "needs 'mass'");
    expect(error("    density: 5\n    inertia: [1, 1, 1]\n"),
           "test.yaml:8:5: bodies[0].inertia: ", "needs 'mass'");
}

// A closed mesh whose own volume is unusable (inward oriented) stays an error, naming the ways
// out; with mass and inertia given it loads (centre of mass from its hull).

TEST_F(SceneMeshes, ClosedMeshWithoutUsableVolumeNamesTheWaysOut) {
    std::string inward;
    std::istringstream in(kOffsetCubeObj);
    for (std::string line; std::getline(in, line);) {
        if (line.rfind("f ", 0) == 0) {
            std::istringstream f(line.substr(2));
            std::vector<std::string> idx;
            for (std::string t; f >> t;) idx.push_back(t);
            line = "f";
            for (auto it = idx.rbegin(); it != idx.rend(); ++it) line += " " + *it;
        }
        inward += line + "\n";
    }
    write("meshes/inward.obj", inward);
    const std::string mesh =
        "  - shape: mesh\n    file: meshes/inward.obj\n    position: [0, 0, 0]\n";
    const std::string err = sceneErrorOf(withBody(mesh), dir_);
    EXPECT_EQ(err.rfind("test.yaml:5:5: bodies[0].file: ", 0), 0u) << err;
    EXPECT_NE(err.find("inward"), std::string::npos) << err;
    EXPECT_NE(err.find("use 'shape: hull'"), std::string::npos) << err;
    EXPECT_NE(err.find("give 'mass' and 'inertia'"), std::string::npos) << err;
    EXPECT_NE(
        sceneErrorOf(withBody(mesh + "    mass: 2\n"), dir_).find("give 'mass' and 'inertia'"),
        std::string::npos);
    const Scene s =
        parseScene(withBody(mesh + "    mass: 2\n    inertia: [1, 1, 1]\n"), "test.yaml", dir_);
    EXPECT_EQ(s.bodies.at(0).mass, 2);
    ASSERT_EQ(s.notes.size(), 1u);
    EXPECT_NE(s.notes[0].find("gives no volume"), std::string::npos) << s.notes[0];
}

// What an import changed is noted once per file, at the first body that uses it.

TEST_F(SceneMeshes, ImportChangesAreNotedOncePerFile) {
    // A tetrahedron and a sliver whose fifth vertex is 1e-9 from the second: one in float.
    write("meshes/near.obj",
          "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1.000000001 0 0\n"
          "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\nf 2 5 4\n");
    const std::string body =
        "  - shape: mesh\n    file: meshes/near.obj\n    position: [0, 0, 0]\n";
    const Scene s = parseScene(withBody(body + body), "test.yaml", dir_);
    ASSERT_EQ(s.bodies.size(), 2u);
    ASSERT_EQ(s.notes.size(), 1u);
    EXPECT_EQ(s.notes[0].rfind("test.yaml:5:5: bodies[0].file: 'meshes/near.obj': import changed "
                               "the geometry: dropped 1 of 5 triangles as degenerate",
                               0),
              0u)
        << s.notes[0];
    EXPECT_NE(s.notes[0].find("merged 1 vertices"), std::string::npos) << s.notes[0];
    // The shipped meshes import without a change.
    EXPECT_TRUE(parse(withBody("  - shape: mesh\n    file: ../assets/torus.obj\n"
                               "    position: [0, 0, 0]\n"))
                    .notes.empty());
}

TEST_F(SceneMeshes, LoadSceneFileErrors) {
    try {
        loadScene(dir_ / "absent.yaml");
        FAIL() << "no error";
    } catch (const SceneError& e) {
        EXPECT_EQ(std::string(e.what()), (dir_ / "absent.yaml").string() +
                                             ":1:1: scene: cannot open the file (no such file)");
    }
    write("bad.yaml", "world:\n  bounds: {min: [0, 0, 0], max: [1, 1, 1]}\n  frames: -1\n");
    try {
        loadScene(dir_ / "bad.yaml");
        FAIL() << "no error";
    } catch (const SceneError& e) {
        EXPECT_EQ(std::string(e.what()),
                  (dir_ / "bad.yaml").string() + ":3:11: world.frames: must be >= 1");
    }
    // Regression: a 50 MB list of bodies took 4.8 GB in yaml-cpp's nodes. Past 16 MiB the file
    // is refused before it is parsed (a comment line fills this one).
    write("huge.yaml", "# " + std::string((std::size_t(16) << 20) + 1, 'x') + "\n");
    try {
        loadScene(dir_ / "huge.yaml");
        FAIL() << "no error";
    } catch (const SceneError& e) {
        EXPECT_EQ(std::string(e.what()), (dir_ / "huge.yaml").string() +
                                             ":1:1: scene: the file has 16777220 bytes, more than "
                                             "the limit of 16777216 (16 MiB); describe large "
                                             "populations with repeat:");
    }
}

// --- conventions -------------------------------------------------------------------------------

TEST_F(SceneMeshes, AFlatMeshIsRefusedAsHavingNoVolume) {
    write("tri.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    write("square.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n");
    auto errorIn = [&](const std::string& file, const char* shape) -> std::string {
        write("scene.yaml",
              "world:\n  bounds: {min: [-5, -5, -5], max: [5, 5, 5]}\nbodies:\n"
              "  - {shape: " +
                  std::string(shape) + ", file: " + file + ", position: [0, 0, 0]}\n");
        try {
            loadScene(dir_ / "scene.yaml");
        } catch (const SceneError& e) {
            return e.what();
        }
        return "";
    };
    for (const char* shape : {"hull", "mesh"}) {
        SCOPED_TRACE(shape);
        std::string err = errorIn("tri.off", shape);
        EXPECT_NE(err.find(":4:"), std::string::npos) << err;
        EXPECT_NE(err.find(": bodies[0].file: "), std::string::npos) << err;
        EXPECT_NE(err.find("has no volume: its points lie in one plane (3 vertices, 1 triangle)"),
                  std::string::npos)
            << err;
        err = errorIn("square.off", shape);
        EXPECT_NE(err.find("has no volume: its points lie in one plane (4 vertices, 2 triangles)"),
                  std::string::npos)
            << err;
    }
}

}  // namespace
}  // namespace engine
