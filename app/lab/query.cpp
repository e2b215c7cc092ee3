// app/lab/query.cpp -- `cdlab query`: loads two meshes, builds every requested BVH type, and
// runs the first-contact and all-pairs queries with B at the given pose in A's frame.
// Trees and queries are collision/bvh.h; mesh loading is engine/mesh_import.h.
#include "query.h"

#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <ostream>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "bvh_unit_costs.h"
#include "collision/bvh/bvh.h"
#include "engine/mesh_import.h"

namespace app {

namespace {

using Clock = std::chrono::steady_clock;

struct Row {
    std::string_view bv;
    bool colliding = false;
    std::vector<collision::TrianglePair> pairs;
    collision::BvhQueryStats first;
    collision::BvhQueryStats all;
    std::int32_t nodes = 0;
    double build_ms = 0;  // both trees
    double first_us = 0;  // per query
    double all_us = 0;    // per query
    BvhUnitCosts unit;    // Cv, Cp: measured after the timed queries
    RefitUnitCost refit;  // Cu on mesh A
};

// Mean time per call of `fn`, repeated until ~20 ms have passed (at most 1000 calls).
template <class Fn>
double timePerCall(Fn&& fn) {
    const auto start = Clock::now();
    int calls = 0;
    double elapsed = 0;
    do {
        fn();
        ++calls;
        elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    } while (elapsed < 0.02 && calls < 1000);
    return elapsed / calls;
}

// The rows as JSON (every volume type's own pair list, so a reader can compare them).
// What importing changed in one mesh (engine::MeshImportReport), for --json.
nlohmann::json importJson(const engine::MeshImportReport& r) {
    nlohmann::json j = {{"triangles_read", r.triangles_read},
                        {"degenerate_dropped", r.degenerate_dropped},
                        {"coordinates_checked", r.coordinates_checked},
                        {"changed", r.changed()},
                        {"max_coordinate", r.max_coordinate},
                        {"size", r.size},
                        {"recentred", r.recentred}};
    if (r.coordinates_checked) {
        j["vertices_merged"] = r.vertices_merged;
        j["max_rounding"] = r.max_rounding;
        j["degenerate_in_file"] = r.degenerate_in_file;
        j["degenerate_by_rounding"] = r.degenerate_by_rounding;
    }
    if (r.changed()) j["warning"] = engine::describeImportChanges(r);
    return j;
}

void writeQueryJson(std::ostream& out, const std::filesystem::path (&paths)[2],
                    const collision::TriangleMesh (&meshes)[2],
                    const engine::MeshImportReport (&reports)[2], const collision::Pose& pose_b,
                    const std::vector<Row>& rows, bool agree) {
    nlohmann::json j;
    j["mesh_a"] = {{"path", paths[0].string()},
                   {"triangles", meshes[0].triangles.size()},
                   {"import", importJson(reports[0])}};
    j["mesh_b"] = {{"path", paths[1].string()},
                   {"triangles", meshes[1].triangles.size()},
                   {"import", importJson(reports[1])}};
    const auto& q = pose_b.orientation;
    j["pose_b"] = {
        pose_b.position.x(), pose_b.position.y(), pose_b.position.z(), q.w(), q.x(), q.y(), q.z()};
    j["volumes_agree"] = agree;
    nlohmann::json results = nlohmann::json::array();
    for (const Row& r : rows) {
        // Every type writes its own list (sorted by (a, b)), so a reader can compare them.
        nlohmann::json pairs = nlohmann::json::array();
        for (const collision::TrianglePair& p : r.pairs) pairs.push_back({p.a, p.b});
        results.push_back({
            {"bv", std::string(r.bv)},
            {"colliding", r.colliding},
            {"triangle_pair_count", r.pairs.size()},
            {"triangle_pairs", std::move(pairs)},
            {"nodes", r.nodes},
            {"build_ms", r.build_ms},
            {"first_contact",
             {{"bv_tests", r.first.bv_tests},
              {"triangle_tests", r.first.triangle_tests},
              {"time_us", r.first_us}}},
            {"all_pairs",
             {{"bv_tests", r.all.bv_tests},
              {"triangle_tests", r.all.triangle_tests},
              {"time_us", r.all_us}}},
            {"unit_costs",
             {{"bv_test_ns", r.unit.measured ? nlohmann::json(r.unit.bv_test_ns) : nullptr},
              {"triangle_test_ns",
               r.unit.measured ? nlohmann::json(r.unit.triangle_test_ns) : nullptr},
              {"bv_tests_timed", r.unit.bv_tests_timed},
              {"triangle_tests_timed", r.unit.triangle_tests_timed},
              {"triangle_tests_from_query", r.unit.triangles_from_queries},
              {"refit_node_ns", r.refit.refit_node_ns},
              {"refit_nodes_timed", r.refit.nodes_timed},
              // F = Nv Cv + Np Cp for the all-pairs query, beside its measured time_us.
              {"all_pairs_model_us",
               r.unit.measured ? nlohmann::json(1e-3 * (static_cast<double>(r.all.bv_tests) *
                                                            r.unit.bv_test_ns +
                                                        static_cast<double>(r.all.triangle_tests) *
                                                            r.unit.triangle_test_ns))
                               : nullptr}}},
        });
    }
    j["results"] = results;
    out << j.dump(2) << "\n";
}

// The rows as a table, with the cost counters and unit costs.
void writeQueryTable(std::ostream& out, const std::filesystem::path (&paths)[2],
                     const collision::TriangleMesh (&meshes)[2], const std::vector<Row>& rows) {
    out << "A: " << paths[0].string() << " (" << meshes[0].triangles.size()
        << " triangles)  B: " << paths[1].string() << " (" << meshes[1].triangles.size()
        << " triangles)\n";
    out << std::left << std::setw(8) << "bv" << std::right << std::setw(10) << "answer"
        << std::setw(8) << "pairs" << std::setw(10) << "first Nv" << std::setw(10) << "first Np"
        << std::setw(10) << "all Nv" << std::setw(10) << "all Np" << std::setw(11) << "build ms"
        << std::setw(11) << "first us" << std::setw(11) << "all us" << std::setw(8) << "Cv ns"
        << std::setw(8) << "Cp ns" << std::setw(8) << "Cu ns"
        << "\n";
    out << std::fixed;
    for (const Row& r : rows) {
        out << std::left << std::setw(8) << r.bv << std::right << std::setw(10)
            << (r.colliding ? "colliding" : "apart") << std::setw(8) << r.pairs.size()
            << std::setw(10) << r.first.bv_tests << std::setw(10) << r.first.triangle_tests
            << std::setw(10) << r.all.bv_tests << std::setw(10) << r.all.triangle_tests
            << std::setprecision(2) << std::setw(11) << r.build_ms << std::setw(11) << r.first_us
            << std::setw(11) << r.all_us << std::setprecision(1);
        if (r.unit.measured) {
            out << std::setw(8) << r.unit.bv_test_ns << std::setw(8) << r.unit.triangle_test_ns;
        } else {
            out << std::setw(8) << "-" << std::setw(8) << "-";
        }
        out << std::setw(8) << r.refit.refit_node_ns << (r.unit.triangles_from_queries ? "" : "*")
            << "\n";
    }
    out << "(Nv: BV tests, Np: triangle tests; build: both trees; Cv, Cp: ns per BV test and\n"
           " per triangle test, timed by replaying the all-pairs query's own tests; Cu: ns per\n"
           " node of a refit of A's tree";
    bool random_cp = false;
    for (const Row& r : rows) random_cp = random_cp || !r.unit.triangles_from_queries;
    if (random_cp) out << ";\n * the query tested no triangles: Cp on random triangle pairs";
    bool unmeasured = false;
    for (const Row& r : rows) unmeasured = unmeasured || !r.unit.measured;
    if (unmeasured) out << ";\n " << kUnmeasuredUnitCostsNote;
    out << ")\n";
}

// Self-collision of one mesh: every requested tree against itself beside the brute-force loop.
int runSelfQuery(const std::vector<std::string_view>& names, const std::filesystem::path& path,
                 const collision::TriangleMesh& mesh, bool json, std::int64_t unit_cost_tests,
                 std::ostream& out, std::ostream& err) {
    struct SelfRow {
        std::string_view bv;
        std::vector<collision::TrianglePair> pairs;
        collision::BvhQueryStats stats;
        double build_ms = 0;
        double query_us = 0;
        RefitUnitCost refit;
    };
    collision::BvhQueryStats brute_stats;
    const std::vector<collision::TrianglePair> brute =
        collision::intersectSelfBruteForce(mesh, &brute_stats);
    const double brute_us =
        1e6 * timePerCall([&] { (void)collision::intersectSelfBruteForce(mesh); });
    std::vector<SelfRow> rows;
    bool agree = true;
    for (const std::string_view name : names) {
        SelfRow row;
        row.bv = name;
        const auto b0 = Clock::now();
        const std::unique_ptr<collision::MeshBvh> tree = collision::buildMeshBvh(name, mesh);
        row.build_ms = std::chrono::duration<double, std::milli>(Clock::now() - b0).count();
        row.pairs = tree->intersectSelf(&row.stats);
        row.query_us = 1e6 * timePerCall([&] { (void)tree->intersectSelf(); });
        row.refit = measureRefitUnitCost(name, mesh, unit_cost_tests);
        agree = agree && row.pairs == brute;
        rows.push_back(std::move(row));
    }
    if (json) {
        nlohmann::json j;
        j["mesh"] = {{"path", path.string()}, {"triangles", mesh.triangles.size()}};
        j["agrees_with_brute_force"] = agree;
        nlohmann::json pairs = nlohmann::json::array();
        for (const collision::TrianglePair& p : brute) pairs.push_back({p.a, p.b});
        j["brute_force"] = {{"self_pair_count", brute.size()},
                            {"self_pairs", std::move(pairs)},
                            {"triangle_tests", brute_stats.triangle_tests},
                            {"time_us", brute_us}};
        nlohmann::json results = nlohmann::json::array();
        for (const SelfRow& r : rows) {
            nlohmann::json rp = nlohmann::json::array();
            for (const collision::TrianglePair& p : r.pairs) rp.push_back({p.a, p.b});
            results.push_back({{"bv", std::string(r.bv)},
                               {"self_pair_count", r.pairs.size()},
                               {"self_pairs", std::move(rp)},
                               {"bv_tests", r.stats.bv_tests},
                               {"triangle_tests", r.stats.triangle_tests},
                               {"build_ms", r.build_ms},
                               {"time_us", r.query_us},
                               {"refit_node_ns", r.refit.refit_node_ns}});
        }
        j["results"] = results;
        out << j.dump(2) << "\n";
    } else {
        out << "self-collision of " << path.string() << " (" << mesh.triangles.size()
            << " triangles; pairs sharing a vertex index are adjacent and not counted)\n";
        out << std::left << std::setw(8) << "bv" << std::right << std::setw(8) << "pairs"
            << std::setw(10) << "Nv" << std::setw(10) << "Np" << std::setw(11) << "build ms"
            << std::setw(11) << "self us" << std::setw(8) << "Cu ns"
            << "\n"
            << std::fixed;
        for (const SelfRow& r : rows) {
            out << std::left << std::setw(8) << r.bv << std::right << std::setw(8) << r.pairs.size()
                << std::setw(10) << r.stats.bv_tests << std::setw(10) << r.stats.triangle_tests
                << std::setprecision(2) << std::setw(11) << r.build_ms << std::setw(11)
                << r.query_us << std::setprecision(1) << std::setw(8) << r.refit.refit_node_ns
                << "\n";
        }
        out << std::left << std::setw(8) << "brute" << std::right << std::setw(8) << brute.size()
            << std::setw(10) << 0 << std::setw(10) << brute_stats.triangle_tests << std::setw(11)
            << "-" << std::setprecision(2) << std::setw(11) << brute_us << "\n";
        out << "(Nv: BV tests, Np: triangle tests; brute: every non-adjacent pair after a box "
               "reject;\n Cu: ns per node of a refit of the tree)\n";
    }
    if (!agree) {
        err << "error: a tree's self pairs differ from the brute force's (a BVH bug)\n";
        return 1;
    }
    return 0;
}

}  // namespace

std::optional<collision::Pose> parsePose(std::string_view text, std::string* error) {
    std::vector<double> v;
    std::string item;
    std::istringstream in{std::string(text)};
    while (std::getline(in, item, ',')) {
        std::size_t used = 0;
        double x = 0;
        try {
            x = std::stod(item, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        // Allow surrounding blanks, nothing else.
        while (used < item.size() && std::isspace(static_cast<unsigned char>(item[used]))) ++used;
        if (used == 0 || used != item.size()) {
            *error = "'" + item + "' is not a number";
            return std::nullopt;
        }
        if (!std::isfinite(x)) {
            *error = "'" + item + "' is not finite";
            return std::nullopt;
        }
        v.push_back(x);
    }
    if (v.size() != 7) {
        *error =
            "expected 7 comma-separated numbers x,y,z,qw,qx,qy,qz, got " + std::to_string(v.size());
        return std::nullopt;
    }
    const collision::Quat q(v[3], v[4], v[5], v[6]);
    // As the scene loader's orientation_wxyz: a length that overflows (1e200 components) would
    // normalise to the zero quaternion and answer for another pose.
    const double norm = q.norm();
    if (!(norm > 1e-12) || !std::isfinite(norm)) {
        *error = "the quaternion (qw,qx,qy,qz) must have a non-zero, finite length (it is "
                 "normalised); this one's is " + std::string(std::isfinite(norm) ? "zero" : "too large to compute");
        return std::nullopt;
    }
    return collision::Pose{collision::Vec3(v[0], v[1], v[2]), q.normalized()};
}

int runQuery(const QueryOptions& options, std::ostream& out, std::ostream& err) {
    collision::Pose pose_b;
    if (!options.pose_b.empty()) {
        std::string error;
        const auto parsed = parsePose(options.pose_b, &error);
        if (!parsed) {
            err << "--pose-b: " << error << "\n";
            return 2;
        }
        pose_b = *parsed;
    }
    std::vector<std::string_view> names;
    if (options.bv == "all") {
        names = collision::bvhVolumeNames();
    } else {
        for (const std::string_view n : collision::bvhVolumeNames()) {
            if (n == options.bv) names.push_back(n);
        }
        if (names.empty()) {
            err << "--bv: unknown volume '" << options.bv << "' (all";
            for (const std::string_view n : collision::bvhVolumeNames()) err << ", " << n;
            err << ")\n";
            return 2;
        }
    }
    if (options.self) {
        if (!options.mesh_b.empty() || !options.pose_b.empty()) {
            err << "--self: takes one mesh and no --pose-b\n";
            return 2;
        }
        engine::MeshImportOutput imported = engine::importMesh(options.mesh_a, 1.0);
        if (!imported.ok) {
            err << options.mesh_a.string() << ": " << imported.error << "\n";
            return 2;
        }
        if (imported.report.changed()) {
            err << "warning: " << options.mesh_a.string() << ": "
                << engine::describeImportChanges(imported.report) << "\n";
        }
        if (options.dry_run) return 0;
        return runSelfQuery(names, options.mesh_a, imported.mesh, options.json,
                            options.unit_cost_tests, out, err);
    }
    if (options.mesh_b.empty()) {
        err << "mesh_b: required (or --self for one mesh against itself)\n";
        return 2;
    }
    collision::TriangleMesh meshes[2];
    engine::MeshImportReport reports[2];
    const std::filesystem::path paths[2] = {options.mesh_a, options.mesh_b};
    for (int i = 0; i < 2; ++i) {
        engine::MeshImportOutput imported = engine::importMesh(paths[i], 1.0);
        if (!imported.ok) {
            err << paths[i].string() << ": " << imported.error << "\n";
            return 2;
        }
        meshes[i] = std::move(imported.mesh);
        reports[i] = imported.report;
        if (reports[i].changed() && !(i == 1 && paths[1] == paths[0])) {  // once per file
            err << "warning: " << paths[i].string() << ": "
                << engine::describeImportChanges(reports[i]) << "\n";
        }
    }
    if (options.dry_run) return 0;

    std::vector<Row> rows;
    for (const std::string_view name : names) {
        Row row;
        row.bv = name;
        const auto b0 = Clock::now();
        const std::unique_ptr<collision::MeshBvh> a = collision::buildMeshBvh(name, meshes[0]);
        const std::unique_ptr<collision::MeshBvh> b = collision::buildMeshBvh(name, meshes[1]);
        row.build_ms = std::chrono::duration<double, std::milli>(Clock::now() - b0).count();
        row.nodes = a->nodeCount() + b->nodeCount();
        row.colliding = a->testOverlap(*b, pose_b, &row.first);
        row.pairs = a->intersect(*b, pose_b, &row.all);
        row.first_us = 1e6 * timePerCall([&] { (void)a->testOverlap(*b, pose_b); });
        row.all_us = 1e6 * timePerCall([&] { (void)a->intersect(*b, pose_b); });
        // Cv and Cp: the all-pairs query's own tests replayed in batches, outside its timing.
        row.unit = measureBvhUnitCosts(*a, *b, std::span<const collision::Pose>(&pose_b, 1),
                                       options.unit_cost_tests, options.unit_cost_tests / 2);
        row.refit = measureRefitUnitCost(name, meshes[0], options.unit_cost_tests);
        rows.push_back(std::move(row));
    }
    bool agree = true;
    for (const Row& r : rows) {
        agree = agree && r.pairs == rows.front().pairs && r.colliding == !r.pairs.empty();
    }

    if (options.json) {
        writeQueryJson(out, paths, meshes, reports, pose_b, rows, agree);
    } else {
        writeQueryTable(out, paths, meshes, rows);
    }
    if (!agree) {
        err << "error: the volume types disagree on the triangle pairs (a BVH bug)\n";
        return 1;
    }
    return 0;
}

}  // namespace app
