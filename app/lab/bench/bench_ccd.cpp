// app/lab/bench/bench_ccd.cpp -- `cdlab bench ccd`: loads CCD query CSVs (8 rows per query, rational
// coordinates as numerator/denominator pairs, last column the exact ground truth), runs each
// method on every query and tabulates correctness and time per query.
// Rows come out sorted by (method, set, kind), so two runs compare line by line.
#include "bench_ccd.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "bench_ccd_peer.h"
#include "collision/ccd/ccd.h"
#include "engine/scene.h"
#include "engine/world.h"
#include "output_files.h"

namespace app {
namespace {

namespace fs = std::filesystem;
using collision::CcdOutput;
using collision::CcdState;
using collision::Vec3;

const char* const kDefaultDir = "tests/data/ccd-sample-queries";

// A default data path (the query sets, the tunnelling scenes): relative to the working directory
// when it is there, else in the source tree this program was built from, else as given (the
// caller then says what is missing and what to pass).
fs::path defaultDataPath(const fs::path& relative) {
    std::error_code ec;
    if (fs::exists(relative, ec)) return relative;
    const fs::path in_source = fs::path(CDLAB_SOURCE_DIR) / relative;
    if (fs::exists(in_source, ec)) return in_source;
    return relative;
}

struct Query {
    std::array<Vec3, 4> t0{Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
    std::array<Vec3, 4> t1{Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
    bool truth = false;
    bool exact_input = true;  ///< the double input equals the rational input
};

/// A decimal integer as long double; false if not an integer. `exact` false when the value
/// needed more than the 64-bit mantissa (checked by printing it back).
bool parseInteger(const std::string& s, long double& value, bool& exact) {
    if (s.empty()) return false;
    size_t i = (s[0] == '-' || s[0] == '+') ? 1 : 0;
    if (i == s.size()) return false;
    for (size_t k = i; k < s.size(); ++k) {
        if (s[k] < '0' || s[k] > '9') return false;
    }
    value = std::strtold(s.c_str(), nullptr);
    char buf[512];
    std::snprintf(buf, sizeof buf, "%.0Lf", value);
    const std::string digits = s[0] == '+' ? s.substr(1) : s;
    exact = digits == buf;
    return true;
}

struct Group {
    std::string set;
    std::string kind;  ///< vertex-face | edge-edge
    std::vector<Query> queries;
};

/// Loads one CSV into `group`. Returns false with `file:line:col: message` in `error`.
bool loadCsv(const fs::path& file, Group& group, std::string& error) {
    std::ifstream in(file);
    if (!in) {
        error = file.string() + ":1:1: cannot open";
        return false;
    }
    std::string line;
    int line_no = 0;
    Query q;
    int row = 0;
    while (std::getline(in, line)) {
        ++line_no;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.empty()) continue;
        std::vector<std::string> cells;
        std::vector<int> cols;
        size_t start = 0;
        while (true) {
            const size_t comma = line.find(',', start);
            cells.push_back(line.substr(start, comma - start));
            cols.push_back(static_cast<int>(start) + 1);
            if (comma == std::string::npos) break;
            start = comma + 1;
        }
        const std::string where = file.string() + ":" + std::to_string(line_no) + ":";
        if (cells.size() != 7) {
            error = where + "1: expected 7 columns, found " + std::to_string(cells.size());
            return false;
        }
        Vec3 p;
        for (int a = 0; a < 3; ++a) {
            long double num = 0, den = 0;
            bool num_exact = true, den_exact = true;
            if (!parseInteger(cells[2 * a], num, num_exact)) {
                error = where + std::to_string(cols[2 * a]) + ": not an integer";
                return false;
            }
            if (!parseInteger(cells[2 * a + 1], den, den_exact) || den == 0) {
                error = where + std::to_string(cols[2 * a + 1]) + ": bad denominator";
                return false;
            }
            // numerator / denominator to the nearest double. When the denominator is a power
            // of two and both integers fit the 64-bit mantissa, the long double quotient is
            // exact and the only rounding is the final one; the check below tells whether the
            // double *is* the rational (then the ground truth applies exactly).
            const double value = static_cast<double>(num / den);
            int e = 0;
            const bool pow2 = std::frexp(std::abs(den), &e) == 0.5L;
            q.exact_input = q.exact_input && num_exact && den_exact && pow2 &&
                            static_cast<long double>(value) * den == num;
            p[a] = value;
        }
        if (cells[6] != "0" && cells[6] != "1") {
            error = where + std::to_string(cols[6]) + ": ground truth must be 0 or 1";
            return false;
        }
        (row < 4 ? q.t0[row] : q.t1[row - 4]) = p;
        if (row == 0) q.truth = cells[6] == "1";
        if (++row == 8) {
            group.queries.push_back(q);
            q = Query{};
            row = 0;
        }
    }
    if (row != 0) {
        error = file.string() + ":" + std::to_string(line_no) +
                ":1: query count: rows not a multiple of 8";
        return false;
    }
    return true;
}

/// Every CSV under `dir` whose parent directory is vertex-face or edge-edge, grouped.
bool loadDir(const fs::path& dir, std::map<std::pair<std::string, std::string>, Group>& groups,
             std::string& error) {
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) {
        error = dir.string() + ":1:1: not a directory";
        return false;
    }
    std::vector<fs::path> files;
    for (auto it = fs::recursive_directory_iterator(dir, ec);
         !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
        const fs::path& p = it->path();
        const std::string kind = p.parent_path().filename().string();
        if (p.extension() == ".csv" && (kind == "vertex-face" || kind == "edge-edge")) {
            files.push_back(p);
        }
    }
    std::sort(files.begin(), files.end());
    if (files.empty()) {
        error = dir.string() + ":1:1: no */vertex-face/*.csv or */edge-edge/*.csv files";
        return false;
    }
    for (const fs::path& f : files) {
        const std::string kind = f.parent_path().filename().string();
        std::string set = f.parent_path().parent_path().filename().string();
        if (set.empty()) set = dir.filename().string();
        Group& g = groups[{set, kind}];
        g.set = set;
        g.kind = kind;
        if (!loadCsv(f, g, error)) return false;
    }
    return true;
}

struct Row {
    std::string method, set, kind;
    int queries = 0, positives = 0, false_negatives = 0, false_positives = 0, failed = 0;
    int inexact_inputs = 0, inexact_false_negatives = 0;
    double mean_us = 0, median_us = 0, p99_us = 0, max_us = 0;
};

const char* const kTightInclusion = "tight-inclusion";

CcdOutput runOne(const std::string& method, const std::string& kind, const Query& q) {
    if (kind == "vertex-face") {
        const collision::VertexFaceCcdInput in{q.t0, q.t1};
        if (method == "naive") return collision::vertexFaceCcdNaive(in);
        if (method == kTightInclusion) return tightInclusionVertexFace(in);
        return collision::vertexFaceCcd(in);
    }
    const collision::EdgeEdgeCcdInput in{q.t0, q.t1};
    if (method == "naive") return collision::edgeEdgeCcdNaive(in);
    if (method == kTightInclusion) return tightInclusionEdgeEdge(in);
    return collision::edgeEdgeCcd(in);
}

/// Fills the timing columns from per-query microseconds (nearest-rank percentiles).
void summarise(std::vector<double>& us, Row& row) {
    if (us.empty()) return;
    std::sort(us.begin(), us.end());
    double sum = 0;
    for (double x : us) sum += x;
    row.mean_us = sum / static_cast<double>(us.size());
    const size_t n = us.size();
    row.median_us = n % 2 ? us[n / 2] : 0.5 * (us[n / 2 - 1] + us[n / 2]);
    const size_t rank = static_cast<size_t>(std::ceil(0.99 * static_cast<double>(n)));
    row.p99_us = us[std::max<size_t>(rank, 1) - 1];
    row.max_us = us.back();
}

/// Each query runs `reps` times; its time is the fastest run (the others lost time to the
/// machine, not to the method). The answer is the last run's (every method is deterministic).
Row runGroup(const std::string& method, const Group& g, int reps, std::vector<double>& all_us) {
    Row row;
    row.method = method;
    row.set = g.set;
    row.kind = g.kind;
    std::vector<double> us;
    us.reserve(g.queries.size());
    for (const Query& q : g.queries) {
        CcdOutput o;
        double best = std::numeric_limits<double>::infinity();
        for (int r = 0; r < reps; ++r) {
            const auto start = std::chrono::steady_clock::now();
            o = runOne(method, g.kind, q);
            const auto stop = std::chrono::steady_clock::now();
            best = std::min(best, std::chrono::duration<double, std::micro>(stop - start).count());
        }
        us.push_back(best);
        // Failed counts as a reported contact: the caller must treat the pair as colliding.
        const bool hit = o.state != CcdState::Separated;
        ++row.queries;
        row.positives += q.truth;
        row.failed += o.state == CcdState::Failed;
        row.inexact_inputs += !q.exact_input;
        if (q.truth && !hit) {
            // Ground truth is for the rational input; a miss on a query whose double rounding
            // changed the input is counted apart, not skipped.
            ++(q.exact_input ? row.false_negatives : row.inexact_false_negatives);
        }
        row.false_positives += !q.truth && hit;
    }
    all_us.insert(all_us.end(), us.begin(), us.end());
    summarise(us, row);
    return row;
}

nlohmann::json rowJson(const Row& r) {
    return nlohmann::json{{"method", r.method},
                          {"set", r.set},
                          {"kind", r.kind},
                          {"queries", r.queries},
                          {"positives", r.positives},
                          {"false_negatives", r.false_negatives},
                          {"false_positives", r.false_positives},
                          {"failed", r.failed},
                          {"inexact_inputs", r.inexact_inputs},
                          {"inexact_false_negatives", r.inexact_false_negatives},
                          {"mean_us", r.mean_us},
                          {"median_us", r.median_us},
                          {"p99_us", r.p99_us},
                          {"max_us", r.max_us}};
}

void printTable(const std::vector<Row>& rows, std::ostream& out) {
    size_t method_width = 13;
    for (const Row& r : rows) method_width = std::max(method_width, r.method.size() + 1);
    const int mw = static_cast<int>(method_width);
    out << std::left << std::setw(mw) << "method" << std::setw(29) << "set" << std::setw(12)
        << "kind" << std::right << std::setw(8) << "queries" << std::setw(6) << "FN" << std::setw(6)
        << "FP" << std::setw(7) << "failed" << std::setw(8) << "inexact" << std::setw(11)
        << "mean_us" << std::setw(11) << "median_us" << std::setw(11) << "p99_us" << std::setw(11)
        << "max_us"
        << "\n";
    for (const Row& r : rows) {
        out << std::left << std::setw(mw) << r.method << std::setw(29) << r.set << std::setw(12)
            << r.kind << std::right << std::setw(8) << r.queries << std::setw(6)
            << r.false_negatives << std::setw(6) << r.false_positives << std::setw(7) << r.failed
            << std::setw(8) << r.inexact_inputs << std::fixed << std::setprecision(2)
            << std::setw(11) << r.mean_us << std::setw(11) << r.median_us << std::setw(11)
            << r.p99_us << std::setw(11) << r.max_us << std::defaultfloat << "\n";
    }
}

/// The conservative method's time over the peer's, per kind over all sets, when both ran.
nlohmann::json printRatios(const std::vector<Row>& rows, std::ostream& out) {
    nlohmann::json ratios = nlohmann::json::array();
    for (const Row& ours : rows) {
        if (ours.method != "conservative" || ours.set != "all") continue;
        for (const Row& peer : rows) {
            if (peer.method != kTightInclusion || peer.set != "all" || peer.kind != ours.kind) {
                continue;
            }
            if (ratios.empty()) out << "\nconservative / tight-inclusion, all sets:\n";
            const double median = ours.median_us / peer.median_us;
            const double p99 = ours.p99_us / peer.p99_us;
            const double max = ours.max_us / peer.max_us;
            out << "  " << std::left << std::setw(12) << ours.kind << std::right
                << std::setprecision(3) << " median " << median << "x  p99 " << p99 << "x  max "
                << max << "x\n"
                << std::setprecision(6);
            ratios.push_back({{"kind", ours.kind}, {"median", median}, {"p99", p99}, {"max", max}});
        }
    }
    return ratios;
}

struct SceneRow {
    std::string scene;
    std::string ccd;
    int frames = 0;
    double step_us = 0;           ///< mean World::step wall time per frame, microseconds
    double ccd_us = 0;            ///< mean CCD stage time per frame, microseconds
    double toi_queries = 0;       ///< mean timeOfImpact calls per frame
    std::int64_t toi_events = 0;  ///< total times of impact acted on
};

// Runs the scene's frames with the given CCD method; times come from World::lastStats.
SceneRow runScene(const engine::Scene& scene, engine::CcdMethod method) {
    engine::Scene copy = scene;
    copy.world.ccd = method;
    engine::World world = engine::makeWorld(copy);
    SceneRow row;
    row.scene = scene.name;
    row.ccd = std::string(engine::ccdMethodName(method));
    row.frames = scene.frames;
    double step_s = 0, ccd_s = 0, queries = 0;
    for (int f = 0; f < scene.frames; ++f) {
        for (int k = 0; k < scene.steps_per_frame; ++k) {
            world.step();
            step_s += world.lastStats().total_s;
            ccd_s += world.lastStats().ccd_s;
            queries += static_cast<double>(world.lastStats().toi_queries);
            row.toi_events += world.lastStats().toi_events;
        }
    }
    row.step_us = 1e6 * step_s / scene.frames;
    row.ccd_us = 1e6 * ccd_s / scene.frames;
    row.toi_queries = queries / scene.frames;
    return row;
}

// Sphere-sphere pairs of the continuous stage, advancement against the exact root.
struct SphereRow {
    std::string spheres;          ///< world.ccd_spheres
    double first_toi_s = -1;      ///< simulated time of the first time of impact acted on
    double ccd_us = 0;            ///< mean CCD stage time per frame, microseconds
    std::int64_t queries = 0;     ///< time-of-impact calls over the run
    std::int64_t iterations = 0;  ///< their iterations (distance queries or roots)
};

SphereRow runSpheres(const engine::Scene& scene, engine::CcdSpheres spheres) {
    engine::Scene copy = scene;
    copy.world.ccd = engine::CcdMethod::ConservativeAdvancement;
    copy.world.ccd_spheres = spheres;
    engine::World world = engine::makeWorld(copy);
    SphereRow row;
    row.spheres = std::string(engine::ccdSpheresName(spheres));
    double ccd_s = 0;
    for (int f = 0; f < scene.frames; ++f) {
        for (int k = 0; k < scene.steps_per_frame; ++k) {
            const double t0 = world.time();
            world.step();
            ccd_s += world.lastStats().ccd_s;
            row.queries += world.lastStats().toi_queries;
            row.iterations += world.lastStats().toi_iterations;
            if (row.first_toi_s < 0 && !world.toiEvents().empty()) {
                row.first_toi_s = t0 + world.toiEvents()[0].t * copy.world.time_step;
            }
        }
    }
    row.ccd_us = 1e6 * ccd_s / std::max(1, scene.frames);
    return row;
}

}  // namespace

std::vector<std::string> ccdBenchMethods() {
    std::vector<std::string> methods = {"conservative", "naive"};
    if (tightInclusionBuiltIn()) methods.push_back(kTightInclusion);
    return methods;
}

int runBenchCcd(const BenchCcdOptions& options, std::ostream& out, std::ostream& err) {
    std::vector<std::string> methods;
    if (options.method == "all") {
        methods = ccdBenchMethods();
        if (!tightInclusionBuiltIn()) {
            err << "cdlab bench ccd: Tight-Inclusion: not found at configure time ("
                << kTightInclusionHint << ")\n";
        }
    } else if (options.method == kTightInclusion && !tightInclusionBuiltIn()) {
        err << "cdlab bench ccd: Tight-Inclusion: not found at configure time ("
            << kTightInclusionHint << ")\n";
        return 2;
    } else if (options.method == "conservative" || options.method == "naive" ||
               options.method == kTightInclusion) {
        methods = {options.method};
    } else {
        err << "cdlab bench ccd: unknown method '" << options.method
            << "' (conservative, naive, tight-inclusion, all)\n";
        return 2;
    }
    if (options.reps < 1) {
        err << "cdlab bench ccd: --reps must be >= 1\n";
        return 2;
    }
    std::vector<fs::path> dirs = options.dirs;
    if (dirs.empty()) {
        dirs.push_back(defaultDataPath(kDefaultDir));
        std::error_code ec;
        if (!fs::is_directory(dirs.back(), ec)) {
            err << "cdlab bench ccd: no query directory given, and " << kDefaultDir
                << " is neither in the working directory nor in the source tree "
                << CDLAB_SOURCE_DIR << "; pass the query directories (cdlab bench ccd DIR...)\n";
            return 2;
        }
    }
    std::map<std::pair<std::string, std::string>, Group> groups;
    for (const fs::path& dir : dirs) {
        std::string error;
        if (!loadDir(dir, groups, error)) {
            err << error << "\n";
            return 2;
        }
    }

    std::vector<Row> rows;
    for (const std::string& method : methods) {
        for (const std::string kind : {"vertex-face", "edge-edge"}) {
            Row total;
            total.method = method;
            total.set = "all";
            total.kind = kind;
            std::vector<double> all_us;
            bool any = false;
            for (const auto& [key, g] : groups) {
                if (g.kind != kind) continue;
                any = true;
                const Row r = runGroup(method, g, options.reps, all_us);
                total.queries += r.queries;
                total.positives += r.positives;
                total.false_negatives += r.false_negatives;
                total.false_positives += r.false_positives;
                total.failed += r.failed;
                total.inexact_inputs += r.inexact_inputs;
                total.inexact_false_negatives += r.inexact_false_negatives;
                rows.push_back(r);
            }
            if (!any) continue;
            summarise(all_us, total);
            rows.push_back(total);
        }
    }
    printTable(rows, out);
    const nlohmann::json ratios = printRatios(rows, out);

    int status = 0;
    for (const Row& r : rows) {
        if (r.method == "conservative" && r.set == "all" && r.false_negatives > 0) {
            err << "cdlab bench ccd: conservative method missed " << r.false_negatives << " "
                << r.kind << " contacts\n";
            status = 1;
        }
    }
    // The engine's CCD stage per frame in the tunnelling scenes, off vs on.
    std::vector<SceneRow> scene_rows;
    if (options.scenes) {
        const fs::path dir =
            options.scenes_explicit ? options.scenes_dir : defaultDataPath(options.scenes_dir);
        const bool found = fs::is_regular_file(dir / "tunnel_sphere.yaml") &&
                           fs::is_regular_file(dir / "tunnel_bar.yaml");
        if (!found && options.scenes_explicit) {
            err << dir.string() << ":1:1: no tunnel_sphere.yaml and tunnel_bar.yaml here\n";
            return 2;
        }
        if (!found) {
            err << "cdlab bench ccd: tunnelling table skipped: no " << options.scenes_dir.string()
                << "/tunnel_sphere.yaml and tunnel_bar.yaml in the working directory nor in the "
                   "source tree (pass --scenes DIR, or --no-scenes)\n";
        }
        if (found) {
            for (const char* name : {"tunnel_sphere.yaml", "tunnel_bar.yaml"}) {
                engine::Scene scene;
                try {
                    scene = engine::loadScene(dir / name);
                } catch (const engine::SceneError& e) {
                    err << e.what() << "\n";
                    return 2;
                }
                for (const engine::CcdMethod m :
                     {engine::CcdMethod::Off, engine::CcdMethod::ConservativeAdvancement}) {
                    scene_rows.push_back(runScene(scene, m));
                }
            }
            out << "\n"
                << std::left << std::setw(16) << "scene" << std::setw(26) << "ccd" << std::right
                << std::setw(7) << "frames" << std::setw(14) << "step_us/frame" << std::setw(13)
                << "ccd_us/frame" << std::setw(15) << "queries/frame" << std::setw(11)
                << "toi_events"
                << "\n";
            for (const SceneRow& r : scene_rows) {
                out << std::left << std::setw(16) << r.scene << std::setw(26) << r.ccd << std::right
                    << std::setw(7) << r.frames << std::fixed << std::setprecision(2)
                    << std::setw(14) << r.step_us << std::setw(13) << r.ccd_us << std::setw(15)
                    << r.toi_queries << std::setw(11) << r.toi_events << std::defaultfloat << "\n";
            }
        }
    }

    // Sphere pairs (scenes/ccd_spheres.yaml when present): the exact root against advancement.
    std::vector<SphereRow> sphere_rows;
    if (options.scenes) {
        const fs::path dir =
            options.scenes_explicit ? options.scenes_dir : defaultDataPath(options.scenes_dir);
        if (fs::is_regular_file(dir / "ccd_spheres.yaml")) {
            engine::Scene scene;
            try {
                scene = engine::loadScene(dir / "ccd_spheres.yaml");
            } catch (const engine::SceneError& e) {
                err << e.what() << "\n";
                return 2;
            }
            for (const engine::CcdSpheres m :
                 {engine::CcdSpheres::Advancement, engine::CcdSpheres::Exact}) {
                sphere_rows.push_back(runSpheres(scene, m));
            }
            out << "\nsphere pairs (ccd_spheres.yaml)\n"
                << std::left << std::setw(13) << "ccd_spheres" << std::right << std::setw(22)
                << "first_toi_s" << std::setw(9) << "queries" << std::setw(12) << "iterations"
                << std::setw(12) << "iter/query" << std::setw(13) << "ccd_us/frame"
                << "\n";
            for (const SphereRow& r : sphere_rows) {
                out << std::left << std::setw(13) << r.spheres << std::right << std::setw(22)
                    << std::setprecision(17) << r.first_toi_s << std::setw(9) << r.queries
                    << std::setw(12) << r.iterations << std::fixed << std::setprecision(2)
                    << std::setw(12)
                    << (r.queries > 0 ? static_cast<double>(r.iterations) / r.queries : 0.0)
                    << std::setw(13) << r.ccd_us << std::defaultfloat << "\n";
            }
        }
    }

    if (options.json) {
        nlohmann::json doc;
        doc["benchmark"] = "ccd";
        doc["rows"] = nlohmann::json::array();
        doc["reps"] = options.reps;
        for (const Row& r : rows) doc["rows"].push_back(rowJson(r));
        doc["ratios"] = ratios;
        doc["scenes"] = nlohmann::json::array();
        for (const SceneRow& r : scene_rows) {
            doc["scenes"].push_back(nlohmann::json{{"scene", r.scene},
                                                   {"ccd", r.ccd},
                                                   {"frames", r.frames},
                                                   {"step_us_per_frame", r.step_us},
                                                   {"ccd_us_per_frame", r.ccd_us},
                                                   {"toi_queries_per_frame", r.toi_queries},
                                                   {"toi_events", r.toi_events}});
        }
        doc["sphere_pairs"] = nlohmann::json::array();
        for (const SphereRow& r : sphere_rows) {
            doc["sphere_pairs"].push_back(nlohmann::json{{"ccd_spheres", r.spheres},
                                                         {"first_toi_s", r.first_toi_s},
                                                         {"toi_queries", r.queries},
                                                         {"toi_iterations", r.iterations},
                                                         {"ccd_us_per_frame", r.ccd_us}});
        }
        if (!writeTextReporting(*options.json, doc.dump(2) + "\n", err)) return 1;
    }
    return status;
}

}  // namespace app
