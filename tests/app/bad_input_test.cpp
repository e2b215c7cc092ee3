// tests/app/bad_input_test.cpp -- bad input anywhere, through the binary: NaN/Inf, inverted
// boxes and bounds, zero mass, malformed YAML, meshes without triangles, models assimp rejects.
// Each must give "FILE:LINE:COL: key.path: what" on stderr, exit code 2 and no output, from both
// `cdlab run` and `cdlab check`.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "cli_run.h"

namespace {

namespace fs = std::filesystem;
using Result = cdlab_test::CliResult;
using cdlab_test::slurp;

Result runBadInput(const std::string& args, const fs::path& work) {
    return cdlab_test::runCdlab(args, work, "", work);
}

const std::string kHead =
    "world:\n"                                         // 1
    "  bounds: {min: [-4, -4, -4], max: [4, 4, 4]}\n"  // 2
    "bodies:\n";                                       // 3

struct BadCase {
    std::string name;
    std::string scene;                                       // bad.yaml
    std::vector<std::pair<std::string, std::string>> files;  // extra files beside it
    std::string prefix;                                      // after "bad.yaml:"
    std::string fragment;
};

// gtest prints the case by name instead of its bytes.
void PrintTo(const BadCase& c, std::ostream* os) { *os << c.name; }

std::vector<BadCase> badCases() {
    const std::string obj_points = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";
    const std::string obj_flat = "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n";
    const std::string obj_nan = "v 0 0 0\nv nan 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\n";
    const std::string garbage = std::string("this is not a model\n\x01\x02 {{{\n");
    return {
        {"NaN",
         kHead + "  - {shape: sphere, radius: .nan, position: [0, 0, 0]}\n",
         {},
         "4:29: bodies[0].radius: ",
         "must be finite, got '.nan'"},
        {"Inf",
         kHead + "  - {shape: sphere, radius: 1, position: [0, .inf, 0]}\n",
         {},
         "4:46: bodies[0].position[1]: ",
         "must be finite, got '.inf'"},
        {"Overflow",
         kHead + "  - {shape: sphere, radius: 1, position: [0, 0, 0], velocity: [1e999, 0, 0]}\n",
         {},
         "4:64: bodies[0].velocity[0]: ",
         "got '1e999'"},
        {"InvertedBox",
         kHead + "  - {shape: box, half_extents: [1, -1, 1], position: [0, 0, 0]}\n",
         {},
         "4:36: bodies[0].half_extents[1]: ",
         "must be >= 0"},
        {"InvertedBounds",
         "world:\n  bounds: {min: [4, -4, -4], max: [-4, 4, 4]}\nbodies:\n",
         {},
         "2:35: world.bounds.max: ",
         "must be greater than min on every axis (axis x)"},
        {"ZeroMass",
         kHead + "  - {shape: sphere, radius: 1, position: [0, 0, 0], mass: 0}\n",
         {},
         "4:59: bodies[0].mass: ",
         "must be > 0 (kg)"},
        {"ZeroDensity",
         kHead + "  - {shape: sphere, radius: 1, position: [0, 0, 0], density: 0}\n",
         {},
         "4:62: bodies[0].density: ",
         "must be > 0 (kg/m^3)"},
        {"ZeroVolumeBoxWithoutMass",
         kHead + "  - {shape: box, half_extents: [0, 0, 0], position: [0, 0, 0]}\n",
         {},
         "4:32: bodies[0].half_extents: ",
         "a box with zero volume needs 'mass'"},
        {"MassUnderflows",
         kHead + "  - {shape: sphere, radius: 1e-200, position: [0, 0, 0]}\n",
         {},
         "4:29: bodies[0].radius: ",
         "degenerate mass properties"},
        {"MalformedYaml",
         "world:\n  bounds: {min: [-4, -4, -4], max: [4, 4, 4]\nbodies:\n",
         {},
         "3:1: malformed YAML: ",
         "end of map flow not found"},
        {"TruncatedYaml", "world: [\n", {}, "2:1: malformed YAML: ", "not found"},
        {"MeshWithoutTriangles",
         kHead + "  - {shape: mesh, file: points.obj, position: [0, 0, 0]}\n",
         {{"points.obj", obj_points}},
         "4:19: bodies[0].file: ",
         "contains no faces"},
        {"MeshOfDegenerateTriangles",
         kHead + "  - {shape: hull, file: flat.obj, position: [0, 0, 0]}\n",
         {{"flat.obj", obj_flat}},
         "4:19: bodies[0].file: ",
         "no triangles in"},
        {"MeshWithNaNVertex",
         kHead + "  - {shape: mesh, file: nan.obj, position: [0, 0, 0]}\n",
         {{"nan.obj", obj_nan}},
         "4:19: bodies[0].file: ",
         "non-finite vertex in './nan.obj'"},
        {"ModelAssimpRejects",
         kHead + "  - {shape: hull, file: garbage.obj, position: [0, 0, 0]}\n",
         {{"garbage.obj", garbage}},
         "4:19: bodies[0].file: ",
         "cannot read"},
        {"ModelIsADevice",
         kHead + "  - {shape: mesh, file: /dev/zero, position: [0, 0, 0]}\n",
         {},
         "4:19: bodies[0].file: ",
         "not a regular file"},
        {"ModelMissing",
         kHead + "  - {shape: mesh, file: missing.obj, position: [0, 0, 0]}\n",
         {},
         "4:19: bodies[0].file: ",
         "no such file"},
        {"BadExpectation",
         kHead + "  - {name: a, shape: sphere, radius: 1, position: [0, 0, 0]}\n" +
             "expect:\n  pairs:\n    - {a: a, b: ghost, frames: 0, colliding: true}\n",
         {},
         "7:17: expect.pairs[0].b: ",
         "no body is named 'ghost'"},
    };
}

class BadInput : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadInput, PreciseMessageExit2NoOutput) {
    const BadCase& c = GetParam();
    const fs::path work =
        fs::temp_directory_path() / ("cdlab_bad_" + c.name + "_" + std::to_string(::getpid()));
    fs::remove_all(work);
    fs::create_directories(work);
    std::ofstream(work / "bad.yaml", std::ios::binary) << c.scene;
    for (const auto& [name, text] : c.files) std::ofstream(work / name, std::ios::binary) << text;

    for (const std::string command : {"run bad.yaml --no-video --out out", "check bad.yaml"}) {
        const Result r = runBadInput(command, work);
        EXPECT_EQ(r.exit_code, 2) << command << "\n" << r.err;
        EXPECT_EQ(r.err.rfind("bad.yaml:" + c.prefix, 0), 0u) << command << "\n" << r.err;
        EXPECT_NE(r.err.find(c.fragment), std::string::npos) << command << "\n" << r.err;
        // One line: the message, nothing else.
        EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << command << "\n" << r.err;
        EXPECT_EQ(r.out, "") << command;
    }
    EXPECT_FALSE(fs::exists(work / "out")) << "run wrote output for bad input";
    fs::remove_all(work);
}

INSTANTIATE_TEST_SUITE_P(Cli, BadInput, ::testing::ValuesIn(badCases()),
                         [](const ::testing::TestParamInfo<BadCase>& param) {
                             return param.param.name;
                         });

}  // namespace
