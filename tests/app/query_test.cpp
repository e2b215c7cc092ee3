// End-to-end: `cdlab query` answers for every BVH volume type side by side, agrees across types,
// writes JSON on request, and rejects bad flags and unreadable meshes with exit code 2.
#include "query.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "collision/bvh/bvh.h"
#include "engine/mesh_import.h"
#include "test_scale.h"

namespace {

namespace fs = std::filesystem;

struct QueryResult {
    int exit_code = -1;
    std::string out;
    std::string err;
};

std::string readAll(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

// The unit costs' timing batches, smaller at a smaller CDLAB_TEST_SCALE (the sanitizer tier): the
// size of a measurement, which no answer depends on. At scale 1 the command's own default.
std::int64_t unitCostTests() { return cdlab_test::scaled(200000, 1000); }
std::string unitCostFlag() {
    if (cdlab_test::testScale() >= 1) return "";
    return " --unit-cost-tests " + std::to_string(unitCostTests());
}

// `cdlab query ARGS`; unit_cost_flag: with unitCostFlag() after ARGS.
QueryResult runQueryCli(const std::string& args, bool unit_cost_flag = true) {
    const fs::path dir = fs::temp_directory_path() / ("cdlab_query_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const fs::path out = dir / "stdout.txt";
    const fs::path err = dir / "stderr.txt";
    const std::string cmd = std::string("cd ") + CDLAB_SOURCE_DIR + " && " + CDLAB_BINARY +
                            " query " + args + (unit_cost_flag ? unitCostFlag() : "") + " > " +
                            out.string() + " 2> " + err.string() + " < /dev/null";
    const int status = std::system(cmd.c_str());
    QueryResult r;
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = readAll(out);
    r.err = readAll(err);
    fs::remove_all(dir);
    return r;
}

TEST(Query, JsonHasEveryVolumeTypeAndTheyAgree) {
    // The torus against itself shifted along x by a quarter of its size: the tubes cross.
    const QueryResult r =
        runQueryCli("assets/torus.obj assets/torus.obj --pose-b 0.5,0,0.1,1,0,0,0 --json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_TRUE(j["volumes_agree"].get<bool>());
    ASSERT_EQ(j["results"].size(), 10u);

    // The reference: the brute-force triangle loop on the same mesh, as the CLI imports it.
    const engine::MeshImportOutput torus =
        engine::importMesh(fs::path(CDLAB_SOURCE_DIR) / "assets/torus.obj", 1.0);
    ASSERT_TRUE(torus.ok) << torus.error;
    const collision::Pose pose{collision::Vec3(0.5, 0, 0.1), collision::Quat::Identity()};
    const std::vector<collision::TrianglePair> brute =
        collision::intersectMeshMeshBruteForce(torus.mesh, torus.mesh, pose);
    ASSERT_FALSE(brute.empty());
    nlohmann::json expected = nlohmann::json::array();
    for (const collision::TrianglePair& p : brute) expected.push_back({p.a, p.b});

    const std::size_t pairs = brute.size();
    for (const auto& row : j["results"]) {
        EXPECT_TRUE(row["colliding"].get<bool>()) << row["bv"];
        EXPECT_EQ(row["triangle_pair_count"].get<std::size_t>(), pairs) << row["bv"];
        EXPECT_EQ(row["triangle_pairs"], expected) << row["bv"];
        EXPECT_GT(row["all_pairs"]["bv_tests"].get<std::int64_t>(), 0);
        EXPECT_GE(row["all_pairs"]["triangle_tests"].get<std::int64_t>(),
                  static_cast<std::int64_t>(pairs));
        EXPECT_LE(row["first_contact"]["triangle_tests"].get<std::int64_t>(),
                  row["all_pairs"]["triangle_tests"].get<std::int64_t>());
        // Cv and Cp timed on batches of the query's own tests (at least 2e5 and 1e5); none for
        // the wide tree, whose node tests the replay cannot record.
        const auto& unit = row["unit_costs"];
        if (row["bv"] == "obb4") {
            EXPECT_TRUE(unit["bv_test_ns"].is_null());
            EXPECT_TRUE(unit["triangle_test_ns"].is_null());
            EXPECT_TRUE(unit["all_pairs_model_us"].is_null());
            continue;
        }
        EXPECT_GT(unit["bv_test_ns"].get<double>(), 0) << row["bv"];
        EXPECT_GT(unit["triangle_test_ns"].get<double>(), 0) << row["bv"];
        EXPECT_GE(unit["bv_tests_timed"].get<std::int64_t>(), unitCostTests()) << row["bv"];
        EXPECT_GE(unit["triangle_tests_timed"].get<std::int64_t>(), unitCostTests() / 2)
            << row["bv"];
        EXPECT_TRUE(unit["triangle_tests_from_query"].get<bool>()) << row["bv"];
        EXPECT_GT(unit["all_pairs_model_us"].get<double>(), 0) << row["bv"];
    }
    EXPECT_EQ(j["results"][7]["bv"], "rss");
    EXPECT_EQ(j["results"][8]["bv"], "lss");
    EXPECT_EQ(j["results"][9]["bv"], "obb4");
}

// `--bv obb4` picks the wide tree alone: its answer and pairs, and "-" for the unit costs it has
// no measurement of, with the reason under the table.
TEST(Query, WideObbTreeByNameAnswersAndMarksItsUnitCosts) {
    const QueryResult r =
        runQueryCli("assets/torus.obj assets/torus.obj --bv obb4 --pose-b 0.5,0,0.1,1,0,0,0");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::istringstream table(r.out);
    std::string line;
    int rows = 0;
    while (std::getline(table, line)) {
        if (line.rfind("obb4 ", 0) != 0) continue;
        ++rows;
        EXPECT_NE(line.find("colliding"), std::string::npos) << line;
        EXPECT_NE(line.find(" - "), std::string::npos) << line;
    }
    EXPECT_EQ(rows, 1) << r.out;
    EXPECT_NE(r.out.find("not measured: obb4"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("\nobb "), std::string::npos) << r.out;  // no other volume's row
}

TEST(Query, FarApartIsNotCollidingAndTableIsPrinted) {
    const QueryResult r = runQueryCli(
        "assets/torus.obj assets/crystal.obj --bv obb "
        "--pose-b 100,0,0,0.7071,0.7071,0,0");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("obb"), std::string::npos);
    EXPECT_NE(r.out.find("apart"), std::string::npos);
    EXPECT_EQ(r.out.find("colliding"), std::string::npos);
    // Apart at the root volumes: no triangle test to replay, so Cp comes from random pairs and
    // the table says so.
    EXPECT_NE(r.out.find("Cv ns"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("Cp on random triangle pairs"), std::string::npos) << r.out;
}

TEST(Query, BadInputExitsTwoWithAMessage) {
    QueryResult r = runQueryCli("assets/torus.obj assets/torus.obj --bv kdop7");
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--bv: unknown volume 'kdop7'"), std::string::npos) << r.err;
    r = runQueryCli("assets/torus.obj assets/torus.obj --pose-b 1,2,3");
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--pose-b: expected 7"), std::string::npos) << r.err;
    r = runQueryCli("assets/torus.obj no/such/mesh.obj");
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("no/such/mesh.obj"), std::string::npos) << r.err;
}

// Import once dropped triangles without a word. The query warns on
// stderr with the counts and puts the import report beside each mesh in --json.
TEST(Query, ImportChangesAreReportedOnStderrAndInJson) {
    const fs::path dir =
        fs::temp_directory_path() / ("cdlab_query_import_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const fs::path near = dir / "near.obj";
    // Vertex 5 is 1e-9 from vertex 2: one vertex in float, and the sliver 2-5-4 collapses.
    std::ofstream(near) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1.000000001 0 0\n"
                           "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\nf 2 5 4\n";
    QueryResult r = runQueryCli(near.string() + " assets/torus.obj --bv obb --json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("warning: " + near.string() +
                         ": import changed the geometry: dropped 1 of 5 triangles"),
              std::string::npos)
        << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    const nlohmann::json& a = j["mesh_a"]["import"];
    EXPECT_EQ(a["triangles_read"], 5);
    EXPECT_EQ(a["degenerate_dropped"], 1);
    EXPECT_EQ(a["vertices_merged"], 1);
    EXPECT_TRUE(a["changed"].get<bool>());
    EXPECT_NE(a["warning"].get<std::string>().find("near its own origin"), std::string::npos);
    const nlohmann::json& b = j["mesh_b"]["import"];
    EXPECT_FALSE(b["changed"].get<bool>());
    EXPECT_EQ(b["degenerate_dropped"], 0);
    EXPECT_FALSE(b.contains("warning"));
    // The shipped meshes: nothing to say.
    r = runQueryCli("assets/torus.obj assets/crystal.obj --bv obb");
    EXPECT_EQ(r.err, "");
    fs::remove_all(dir);
}

TEST(Query, SelfListsTheBruteForcePairsForEveryVolumeType) {
    // The figure-eight ribbon passes through itself once, at the origin, between vertices.
    const QueryResult r = runQueryCli("assets/figure_eight_ribbon.obj --self --json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_TRUE(j["agrees_with_brute_force"].get<bool>());
    const engine::MeshImportOutput ribbon =
        engine::importMesh(fs::path(CDLAB_SOURCE_DIR) / "assets/figure_eight_ribbon.obj", 1.0);
    ASSERT_TRUE(ribbon.ok) << ribbon.error;
    const std::vector<collision::TrianglePair> brute =
        collision::intersectSelfBruteForce(ribbon.mesh);
    ASSERT_FALSE(brute.empty());
    nlohmann::json expected = nlohmann::json::array();
    for (const collision::TrianglePair& p : brute) expected.push_back({p.a, p.b});
    EXPECT_EQ(j["brute_force"]["self_pairs"], expected);
    ASSERT_EQ(j["results"].size(), 10u);
    for (const auto& row : j["results"]) {
        EXPECT_EQ(row["self_pairs"], expected) << row["bv"];
        EXPECT_GT(row["bv_tests"].get<std::int64_t>(), 0) << row["bv"];
    }
    // The table names the count per volume type; a closed torus has no self pairs.
    const QueryResult t = runQueryCli("assets/torus.obj --self --bv obb");
    ASSERT_EQ(t.exit_code, 0) << t.err;
    EXPECT_NE(t.out.find("self-collision of assets/torus.obj"), std::string::npos) << t.out;
    std::istringstream table(t.out);
    std::string line;
    bool obb_row = false;
    while (std::getline(table, line)) {
        std::istringstream cells(line);
        std::string bv;
        std::string pairs;
        cells >> bv >> pairs;
        if (bv != "obb") continue;
        obb_row = true;
        EXPECT_EQ(pairs, "0") << line;
    }
    EXPECT_TRUE(obb_row) << t.out;
    // One mesh only; and without --self the second mesh is required.
    EXPECT_EQ(runQueryCli("assets/torus.obj assets/torus.obj --self").exit_code, 2);
    const QueryResult missing = runQueryCli("assets/torus.obj");
    EXPECT_EQ(missing.exit_code, 2);
    EXPECT_NE(missing.err.find("mesh_b"), std::string::npos) << missing.err;
}

TEST(Query, ParsePose) {
    std::string error;
    const auto pose = app::parsePose("1, 2, 3, 2, 0, 0, 0", &error);
    ASSERT_TRUE(pose.has_value()) << error;
    EXPECT_EQ(pose->position, collision::Vec3(1, 2, 3));
    EXPECT_DOUBLE_EQ(pose->orientation.w(), 1.0);  // normalised
    EXPECT_FALSE(app::parsePose("1,2,3,0,0,0,0", &error).has_value());
    EXPECT_NE(error.find("zero"), std::string::npos);
    EXPECT_FALSE(app::parsePose("1,2,x,1,0,0,0", &error).has_value());
    EXPECT_FALSE(app::parsePose("1,2,inf,1,0,0,0", &error).has_value());
    // Finite components whose length overflows were once normalised to the zero quaternion.
    EXPECT_FALSE(app::parsePose("0,0,0,1e200,1e200,0,0", &error).has_value());
    EXPECT_NE(error.find("too large"), std::string::npos) << error;
}

// --unit-cost-tests sizes the batches the unit costs are timed over (at least that many volume
// tests, half as many triangle tests, that many refitted nodes); the answer does not change.
TEST(Query, UnitCostTestsSizeTheTimedBatches) {
    const std::string args =
        "assets/torus.obj assets/torus.obj --bv obb --pose-b 0.5,0,0.1,1,0,0,0 --json";
    const QueryResult small = runQueryCli(args + " --unit-cost-tests 4000", false);
    ASSERT_EQ(small.exit_code, 0) << small.err;
    const nlohmann::json s_row = nlohmann::json::parse(small.out)["results"][0];
    const nlohmann::json& s = s_row["unit_costs"];
    EXPECT_GE(s["bv_tests_timed"].get<std::int64_t>(), 4000);
    EXPECT_LT(s["bv_tests_timed"].get<std::int64_t>(), 200000);
    EXPECT_GE(s["triangle_tests_timed"].get<std::int64_t>(), 2000);
    EXPECT_GE(s["refit_nodes_timed"].get<std::int64_t>(), 4000);
    EXPECT_LT(s["refit_nodes_timed"].get<std::int64_t>(), 200000);
    const QueryResult large = runQueryCli(args + " --unit-cost-tests 40000", false);
    ASSERT_EQ(large.exit_code, 0) << large.err;
    const nlohmann::json l_row = nlohmann::json::parse(large.out)["results"][0];
    EXPECT_GE(l_row["unit_costs"]["bv_tests_timed"].get<std::int64_t>(), 40000);
    EXPECT_GT(l_row["unit_costs"]["bv_tests_timed"].get<std::int64_t>(),
              s["bv_tests_timed"].get<std::int64_t>());
    EXPECT_EQ(l_row["triangle_pairs"], s_row["triangle_pairs"]);
    EXPECT_GT(s_row["triangle_pair_count"].get<std::int64_t>(), 0);
    for (const char* bad : {" --unit-cost-tests 0", " --unit-cost-tests x"}) {
        const QueryResult r = runQueryCli(args + bad, false);
        EXPECT_EQ(r.exit_code, 2) << bad;
        EXPECT_NE(r.err.find("--unit-cost-tests"), std::string::npos) << bad << ": " << r.err;
    }
}

}  // namespace
