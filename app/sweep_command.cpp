// app/sweep_command.cpp -- the settings sweep: every combination of the --vary axes, one
// headless run each, summed step counters and stage times. Combinations run in a fixed order
// (odometer over the axes, the last axis fastest), so results.csv rows are in the same order
// every time; only the *_ms columns depend on the machine.
#include "sweep_command.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "collision/broad_phase.h"
#include "engine/scene.h"

namespace app {

namespace fs = std::filesystem;

namespace {

constexpr int kExitOk = 0;
constexpr int kExitFailure = 1;
constexpr int kExitBadInput = 2;
// Energies below this (J) count as zero when the drift is made relative.
constexpr double kMinReferenceEnergy = 1e-12;

constexpr const char* kKeys = "broadphase, time_step, steps_per_frame";

struct RunResult {
    std::vector<std::string> settings;  // one value per axis
    int frames = 0;
    std::int64_t steps = 0;
    double integrate_s = 0, volumes_s = 0, broad_s = 0, narrow_s = 0, total_s = 0;
    std::int64_t volume_tests = 0;
    std::int64_t flagged = 0;  // flagged pairs summed over steps
    std::int64_t narrow_tests = 0;
    std::int64_t colliding = 0;  // confirmed pairs summed over steps
    std::int64_t triangle_tests = 0;
    double energy_drift = 0;
    std::uint64_t state_hash = 0;
};

double totalEnergy(const engine::World& world) {
    double e = 0;
    const engine::Vec3 g = world.settings().gravity;
    for (const engine::Body& b : world.bodies()) {
        e += double(b.kineticEnergy()) - double(b.mass) * double(g.dot(b.position));
    }
    return e;
}

// Applies one axis value to the scene; returns an error message or "".
std::string apply(engine::Scene& scene, const std::string& key, const std::string& value) {
    if (key == "broadphase") {
        if (collision::findBroadPhase(value) == nullptr) {
            return "unknown broad phase '" + value +
                   "' (expected one of: " + collision::broadPhaseNames() + ")";
        }
        scene.world.broad_phase = value;
        return {};
    }
    std::size_t used = 0;
    try {
        if (key == "time_step") {
            const double dt = std::stod(value, &used);
            if (used != value.size() || !(dt > 0 && dt <= 1)) throw std::invalid_argument("");
            scene.world.time_step = static_cast<engine::Real>(dt);
            return {};
        }
        if (key == "steps_per_frame") {
            const int n = std::stoi(value, &used);
            if (used != value.size() || n < 1) throw std::invalid_argument("");
            scene.steps_per_frame = n;
            return {};
        }
    } catch (const std::exception&) {
        return key == "time_step" ? "'" + value + "' is not a time step in (0, 1] s"
                                  : "'" + value + "' is not an integer >= 1";
    }
    return "unknown key '" + key + "' (expected one of: " + kKeys + ")";
}

RunResult runOne(const engine::Scene& scene, int frames) {
    RunResult r;
    r.frames = frames;
    engine::World world = engine::makeWorld(scene);
    const double e0 = totalEnergy(world);
    for (int frame = 1; frame < frames; ++frame) {
        for (int s = 0; s < scene.steps_per_frame; ++s) {
            world.step();
            const engine::StepStats& st = world.lastStats();
            r.integrate_s += st.integrate_s;
            r.volumes_s += st.volumes_s;
            r.broad_s += st.broad_phase_s;
            r.narrow_s += st.narrow_phase_s;
            r.total_s += st.total_s;
            r.volume_tests += st.broad.volume_tests;
            r.flagged += static_cast<std::int64_t>(world.flaggedPairs().size());
            r.narrow_tests += st.narrow_tests;
            r.colliding += static_cast<std::int64_t>(world.collidingPairs().size());
            r.triangle_tests += st.triangle_tests;
            r.energy_drift =
                std::max(r.energy_drift, std::abs(totalEnergy(world) - e0) /
                                             std::max(std::abs(e0), kMinReferenceEnergy));
        }
    }
    r.steps = world.stepCount();
    r.state_hash = world.stateHash();
    return r;
}

void writeFile(const fs::path& file, const std::string& text) {
    const fs::path partial = fs::path(file.string() + ".partial");
    {
        std::ofstream f(partial, std::ios::binary | std::ios::trunc);
        f << text;
        f.flush();
        if (!f) throw std::runtime_error("cannot write " + partial.string());
    }
    std::error_code ec;
    fs::rename(partial, file, ec);
    if (ec) throw std::runtime_error("cannot rename " + partial.string() + ": " + ec.message());
}

std::string fixed(double v, int digits) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", digits, v);
    return buf;
}

}  // namespace

SweepAxis parseSweepAxis(const std::string& arg) {
    const std::size_t eq = arg.find('=');
    if (eq == std::string::npos || eq == 0) {
        throw std::invalid_argument("--vary " + arg +
                                    ": expected KEY=V1,V2,... (KEY one of: " + kKeys + ")");
    }
    SweepAxis axis;
    axis.key = arg.substr(0, eq);
    std::string rest = arg.substr(eq + 1);
    std::size_t start = 0;
    while (true) {
        const std::size_t comma = rest.find(',', start);
        const std::string v =
            rest.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
        if (v.empty()) throw std::invalid_argument("--vary " + arg + ": empty value");
        axis.values.push_back(v);
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    return axis;
}

int runSweep(const SweepOptions& options, std::ostream& out, std::ostream& err) {
    engine::Scene scene;
    try {
        scene = engine::loadScene(options.scene);
    } catch (const engine::SceneError& e) {
        err << e.what() << "\n";
        return kExitBadInput;
    }
    if (options.frames && *options.frames < 2) {
        err << "--frames: must be >= 2 (frame 0 is the initial state)\n";
        return kExitBadInput;
    }
    const int frames = options.frames.value_or(scene.frames);
    if (frames < 2) {
        err << options.scene.string() << ": the scene has 1 frame; pass --frames N (N >= 2)\n";
        return kExitBadInput;
    }
    // Every value is validated before anything runs; a key given twice is an error.
    for (std::size_t a = 0; a < options.axes.size(); ++a) {
        const SweepAxis& axis = options.axes[a];
        for (std::size_t b = 0; b < a; ++b) {
            if (options.axes[b].key == axis.key) {
                err << "--vary " << axis.key << ": given twice\n";
                return kExitBadInput;
            }
        }
        for (const std::string& v : axis.values) {
            engine::Scene probe = scene;
            const std::string problem = apply(probe, axis.key, v);
            if (!problem.empty()) {
                err << "--vary " << axis.key << ": " << problem << "\n";
                return kExitBadInput;
            }
        }
    }

    std::size_t total = 1;
    for (const SweepAxis& axis : options.axes) total *= axis.values.size();
    std::vector<RunResult> results;
    for (std::size_t k = 0; k < total; ++k) {
        // Mixed-radix digits of k, the last axis fastest.
        engine::Scene s = scene;
        std::vector<std::string> settings(options.axes.size());
        std::size_t rest = k;
        for (std::size_t a = options.axes.size(); a-- > 0;) {
            const SweepAxis& axis = options.axes[a];
            settings[a] = axis.values[rest % axis.values.size()];
            rest /= axis.values.size();
        }
        for (std::size_t a = 0; a < options.axes.size(); ++a) {
            apply(s, options.axes[a].key, settings[a]);
        }
        RunResult r = runOne(s, frames);
        r.settings = std::move(settings);
        results.push_back(std::move(r));
    }

    std::ostringstream csv;
    std::ostringstream md;
    csv << "run";
    md << "# Sweep of " << options.scene.string() << "\n\n"
       << scene.bodies.size() << " bodies, " << frames << " frames per run. Times are wall-clock "
       << "means per frame on the machine that ran it; every other column is deterministic.\n"
       << "`rejected` are flagged pairs the narrow phase turned down (the broad phase's false "
       << "positives); pair counts are summed over all steps.\n\n| run |";
    for (const SweepAxis& axis : options.axes) {
        csv << "," << axis.key;
        md << " " << axis.key << " |";
    }
    csv << ",frames,steps,ms_per_frame,integrate_ms,volumes_ms,broadphase_ms,narrowphase_ms,"
           "volume_tests,flagged_pairs,narrow_tests,colliding_pairs,narrow_rejections,"
           "false_positive_rate,triangle_tests,energy_drift,state_hash\n";
    md << " ms/frame | broad ms | narrow ms | BV tests | flagged | rejected | FP rate | drift |\n|";
    for (std::size_t k = 0; k < options.axes.size() + 9; ++k) md << "---|";
    md << "\n";
    for (std::size_t i = 0; i < results.size(); ++i) {
        const RunResult& r = results[i];
        const double per_frame = 1e3 / double(frames - 1);
        const std::int64_t rejected = r.narrow_tests - r.colliding;
        const double fp_rate = r.narrow_tests > 0 ? double(rejected) / double(r.narrow_tests) : 0;
        csv << i;
        md << "| " << i << " |";
        for (const std::string& v : r.settings) {
            csv << "," << v;
            md << " " << v << " |";
        }
        char drift[32];
        std::snprintf(drift, sizeof drift, "%.3g", r.energy_drift);
        csv << "," << r.frames << "," << r.steps << "," << fixed(r.total_s * per_frame, 4) << ","
            << fixed(r.integrate_s * per_frame, 4) << "," << fixed(r.volumes_s * per_frame, 4)
            << "," << fixed(r.broad_s * per_frame, 4) << "," << fixed(r.narrow_s * per_frame, 4)
            << "," << r.volume_tests << "," << r.flagged << "," << r.narrow_tests << ","
            << r.colliding << "," << rejected << "," << fixed(fp_rate, 4) << "," << r.triangle_tests
            << "," << drift << "," << r.state_hash << "\n";
        md << " " << fixed(r.total_s * per_frame, 3) << " | " << fixed(r.broad_s * per_frame, 3)
           << " | " << fixed(r.narrow_s * per_frame, 3) << " | " << r.volume_tests << " | "
           << r.flagged << " | " << rejected << " | " << fixed(fp_rate, 3) << " | " << drift
           << " |\n";
    }
    const auto fewest_fp = std::min_element(
        results.begin(), results.end(), [](const RunResult& a, const RunResult& b) {
            return a.narrow_tests - a.colliding < b.narrow_tests - b.colliding;
        });
    const auto fewest_bv = std::min_element(
        results.begin(), results.end(),
        [](const RunResult& a, const RunResult& b) { return a.volume_tests < b.volume_tests; });
    md << "\nFewest broad-phase false positives: run " << (fewest_fp - results.begin())
       << ". Fewest bounding-volume tests: run " << (fewest_bv - results.begin()) << ".\n";

    try {
        std::error_code ec;
        fs::create_directories(options.out_dir, ec);
        if (ec || !fs::is_directory(options.out_dir)) {
            throw std::runtime_error("cannot create output directory " + options.out_dir.string());
        }
        writeFile(options.out_dir / "results.csv", csv.str());
        writeFile(options.out_dir / "report.md", md.str());
    } catch (const std::exception& e) {
        err << "error: " << e.what() << "\n";
        return kExitFailure;
    }
    out << "wrote " << results.size() << " runs to " << (options.out_dir / "results.csv").string()
        << " and report.md\n";
    return kExitOk;
}

}  // namespace app
