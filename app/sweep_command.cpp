// app/sweep_command.cpp -- `cdlab sweep` (see sweep_command.h).
// Every run simulates the same interval; accuracy is judged against one reference run of the
// same scene with a finer time step. Contacts are compared pair by pair through their first
// contact time: a pair the reference confirms and a run never does is missed; a pair both
// confirm contributes |t_run - t_ref| to the first-contact error (resolution: the larger of the
// two time steps). Everything but the wall-clock times is deterministic.
#include "sweep_command.h"

#include <CLI/CLI.hpp>
#include <iostream>
#include <malloc.h>
#include <memory>
#include <string>
#include <sys/wait.h>
#include <vector>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>
#include <utility>

#include "command.h"
#include "exit_codes.h"
#include "output_files.h"
#include "render/chart.h"
#include "render/image.h"
#include "run_command.h"

namespace app {

namespace fs = std::filesystem;

namespace {

using PairKey = std::pair<collision::ProxyId, collision::ProxyId>;
struct Vec3Like {
    double x, y, z;
};

using FirstContacts = std::map<PairKey, double>;

std::string trim(const std::string& s) {
    const std::size_t a = s.find_first_not_of(" \t");
    if (a == std::string::npos) return "";
    const std::size_t b = s.find_last_not_of(" \t");
    return s.substr(a, b - a + 1);
}

std::string labelOf(const std::vector<engine::SceneOverride>& overrides) {
    std::string label;
    for (const engine::SceneOverride& o : overrides) {
        if (!label.empty()) label += ' ';
        label += o.key + "=" + o.value;
    }
    return label.empty() ? "scene as written" : label;
}

// Total mechanical energy: kinetic (translation + rotation) and gravity's potential.
double totalEnergy(const engine::World& world, double& scale) {
    const engine::Vec3 g = world.settings().gravity;
    double e = 0;
    scale = 0;
    for (const engine::Body& b : world.bodies()) {
        const double kinetic = b.kineticEnergy();
        const double potential = -b.mass * g.dot(b.position);
        e += kinetic + potential;
        scale += std::abs(kinetic) + std::abs(potential);
    }
    return e;
}

// Linux /proc/self/status fields in kB (VmRSS: resident now; VmHWM: peak since the last reset),
// -1 when not available.
double procStatusKb(const char* field) {
    std::ifstream f("/proc/self/status");
    std::string line;
    const std::string key = std::string(field) + ":";
    while (std::getline(f, line)) {
        if (line.rfind(key, 0) == 0) return std::strtod(line.c_str() + key.size(), nullptr);
    }
    return -1;
}

// Resets VmHWM to the present resident set (Linux >= 4.0: "5" to clear_refs), after handing the
// heap's free pages back (glibc malloc_trim), so that a run does not grow into pages an earlier
// run left resident.
bool resetPeakResident() {
    malloc_trim(0);
    std::ofstream f("/proc/self/clear_refs");
    f << "5";
    f.flush();
    return bool(f);
}

SweepRun measure(const engine::Scene& scene, double duration, FirstContacts& first) {
    SweepRun run;
    const bool peak_reset = resetPeakResident();
    const double resident_kb = procStatusKb("VmRSS");
    engine::World world = engine::makeWorld(scene);
    run.time_step = scene.world.time_step;
    run.steps = std::max<std::int64_t>(1, std::llround(duration / run.time_step));

    // Contacts the run saw: pairs confirmed at the end of a step, pairs the CCD stage stopped at
    // their time of impact within it (they never overlap at a step's end), and pairs the contact
    // solver pushed apart at its start.
    auto record = [&first, &world, &run](double step_start) {
        const double dt = double(world.settings().time_step);
        for (const engine::ToiEvent& e : world.toiEvents()) {
            first.try_emplace(PairKey{std::min(e.a, e.b), std::max(e.a, e.b)},
                              step_start + double(e.t) * dt);
        }
        // The contact solver acts at the step's start, on pairs touching or about to touch
        // within the step (speculative contacts): a push counts as a contact then.
        for (const collision::ProxyPair& p : world.pushedPairs()) {
            first.try_emplace(PairKey{p.a, p.b}, step_start);
        }
        for (const collision::ProxyPair& p : world.collidingPairs()) {
            first.try_emplace(PairKey{p.a, p.b}, double(world.time()));
        }
        // Depth of convex pairs (a mesh would answer as its hull, an overestimate).
        run.max_penetration = std::max(run.max_penetration, double(world.deepestPenetration()));
    };
    record(double(world.time()));
    double energy_scale = 0;
    const double e0 = totalEnergy(world, energy_scale);
    std::vector<double> l0;
    for (const engine::Body& b : world.bodies()) l0.push_back(b.angular_momentum.norm());

    for (std::int64_t s = 0; s < run.steps; ++s) {
        const double step_start = double(world.time());
        world.step();
        const engine::StepStats& st = world.lastStats();
        run.ms_integrate += 1e3 * st.integrate_s;
        run.ms_volumes += 1e3 * st.volumes_s;
        run.ms_broad += 1e3 * st.broad_phase_s;
        run.ms_narrow += 1e3 * st.narrow_phase_s;
        run.ms_ccd += 1e3 * st.ccd_s;
        run.ms_response += 1e3 * st.response_s;
        run.toi_events += st.toi_events;
        run.ms_step += 1e3 * st.total_s;
        run.flagged += double(world.flaggedPairs().size());
        run.confirmed += double(world.collidingPairs().size());
        run.bv_tests += double(st.broad.volume_tests);
        run.narrow_tests += double(st.narrow_tests);
        run.triangle_tests += double(st.triangle_tests);
        run.mesh_bv_tests += double(st.bv_tests);
        record(step_start);
        double scale_now = 0;
        const double e = totalEnergy(world, scale_now);
        if (energy_scale > 0) {
            run.max_energy_drift = std::max(run.max_energy_drift, std::abs(e - e0) / energy_scale);
        }
        const auto bodies = world.bodies();
        for (std::size_t i = 0; i < bodies.size(); ++i) {
            if (l0[i] <= 0) continue;
            const double drift = std::abs(bodies[i].angular_momentum.norm() - l0[i]) / l0[i];
            run.max_angular_momentum_drift = std::max(run.max_angular_momentum_drift, drift);
        }
    }
    const double n = double(run.steps);
    for (double* v : {&run.ms_integrate, &run.ms_volumes, &run.ms_broad, &run.ms_narrow,
                      &run.ms_ccd, &run.ms_response, &run.ms_step, &run.flagged, &run.confirmed,
                      &run.bv_tests, &run.narrow_tests, &run.triangle_tests, &run.mesh_bv_tests}) {
        *v /= n;
    }
    run.broad_false_positives = run.flagged - run.confirmed;
    run.ms_per_simulated_s = run.ms_step / run.time_step;
    run.pairs_confirmed_total = static_cast<std::int64_t>(first.size());
    run.state_hash = world.stateHash();
    const double peak_kb = procStatusKb("VmHWM");
    if (peak_reset && resident_kb >= 0 && peak_kb >= 0) {
        run.memory_mib = std::max(0.0, peak_kb - resident_kb) / 1024;
    }
    return run;
}

void compareWithReference(SweepRun& run, const FirstContacts& mine, const FirstContacts& ref) {
    double sum = 0;
    std::int64_t common = 0;
    for (const auto& [pair, t_ref] : ref) {
        const auto it = mine.find(pair);
        if (it == mine.end()) {
            ++run.missed_pairs;
            continue;
        }
        const double err = std::abs(it->second - t_ref);
        run.max_first_contact_error = std::max(run.max_first_contact_error, err);
        sum += err;
        ++common;
    }
    for (const auto& entry : mine) {
        if (ref.count(entry.first) == 0) ++run.extra_pairs;
    }
    run.mean_first_contact_error = common > 0 ? sum / double(common) : 0;
}

std::string fmt(double v, const char* spec = "%.4g") {
    char text[48];
    std::snprintf(text, sizeof text, spec, v);
    return text;
}

std::string csvField(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string q = "\"";
    for (char c : s) {
        if (c == '"') q += '"';
        q += c;
    }
    return q + "\"";
}

std::string csvTable(const std::vector<SweepRun>& runs) {
    std::ostringstream csv;
    csv << "run,time_step,steps,ms_integrate,ms_volumes,ms_broad,ms_narrow,ms_ccd,ms_response,"
           "ms_step,ms_per_simulated_s,flagged,confirmed,broad_false_positives,bv_tests,"
           "narrow_tests,triangle_tests,mesh_bv_tests,toi_events,max_penetration_m,pairs_confirmed_"
           "total,"
           "missed_pairs,extra_pairs,"
           "max_first_contact_error_s,mean_first_contact_error_s,max_energy_drift,"
           "max_angular_momentum_drift,memory_mib,state_hash\n";
    for (const SweepRun& r : runs) {
        csv << csvField(r.label) << ',' << fmt(r.time_step, "%.17g") << ',' << r.steps;
        for (double v :
             {r.ms_integrate, r.ms_volumes, r.ms_broad, r.ms_narrow, r.ms_ccd, r.ms_response,
              r.ms_step, r.ms_per_simulated_s, r.flagged, r.confirmed, r.broad_false_positives,
              r.bv_tests, r.narrow_tests, r.triangle_tests, r.mesh_bv_tests}) {
            csv << ',' << fmt(v, "%.6g");
        }
        csv << ',' << r.toi_events << ',' << fmt(r.max_penetration, "%.6g");
        csv << ',' << r.pairs_confirmed_total << ',' << r.missed_pairs << ',' << r.extra_pairs;
        for (double v : {r.max_first_contact_error, r.mean_first_contact_error, r.max_energy_drift,
                         r.max_angular_momentum_drift}) {
            csv << ',' << fmt(v, "%.6g");
        }
        csv << ',' << fmt(r.memory_mib, "%.4g") << ',' << r.state_hash << '\n';
    }
    return csv.str();
}

struct Chart {
    std::string file;
    std::string title;
    double SweepRun::*field;
    bool log_scale;
    bool timing;
};

const std::vector<Chart>& charts() {
    static const std::vector<Chart> kCharts{
        {"cost.png", "wall-clock ms per simulated second (lower is cheaper)",
         &SweepRun::ms_per_simulated_s, false, true},
        {"broad_false_positives.png", "broad-phase false positives per step (flagged - confirmed)",
         &SweepRun::broad_false_positives, false, false},
        {"bv_tests.png", "bounding-volume tests per step (Nv)", &SweepRun::bv_tests, false, false},
        {"first_contact_error.png", "max first-contact time error vs reference (s)",
         &SweepRun::max_first_contact_error, false, false},
        {"energy_drift.png", "max relative energy drift (log scale)", &SweepRun::max_energy_drift,
         true, false},
    };
    return kCharts;
}

std::string floatSection(const std::vector<FloatRun>& floats, double scene_size) {
    std::ostringstream md;
    md << "## Float against double\n\n"
          "Each run above repeated by the float build (`CDLAB_USE_FLOAT=ON`) over the scene's own "
          "frames and compared frame by frame with the double build: the first frame whose "
          "confirmed pairs differ, how many frames differ, and how far bodies drift apart "
          "(scene size = bounds diagonal, "
       << fmt(scene_size) << " m).\n\n"
       << "| run | frames | first frame pairs differ | frames with different pairs | max position "
          "deviation (m) | relative to scene | final deviation (m) | max orientation "
          "deviation (rad) |\n|---|---|---|---|---|---|---|---|\n";
    for (const FloatRun& f : floats) {
        const TraceComparison& c = f.comparison;
        if (!c.error.empty()) {
            md << "| " << f.label << " | " << c.error << " | | | | | | |\n";
            continue;
        }
        md << "| " << f.label << " | " << c.frames << " | "
           << (c.first_pair_difference < 0 ? std::string("none")
                                           : std::to_string(c.first_pair_difference))
           << " | " << c.pair_frames_differing << " | " << fmt(c.max_position_deviation, "%.3g")
           << " | " << fmt(c.max_position_deviation / scene_size, "%.2e") << " | "
           << fmt(c.final_position_deviation, "%.3g") << " | "
           << fmt(c.max_orientation_deviation, "%.3g") << " |\n";
    }
    md << "\n![float against double: max position deviation](float_deviation.png)\n\n";
    return md.str();
}

std::string markdownReport(const SweepOptions& options, const engine::Scene& base, double duration,
                           const std::vector<SweepRun>& runs, const SweepRun& reference,
                           const std::vector<FloatRun>& floats) {
    std::ostringstream md;
    md << "# Sweep of `" << options.scene.filename().string() << "`\n\n";
    md << "- " << base.bodies.size() << " bodies, " << fmt(duration) << " s simulated per run, "
       << "broad phase `" << base.world.broad_phase << "` unless varied.\n";
    md << "- Reference: time step " << fmt(reference.time_step) << " s (" << reference.steps
       << " steps)" << (options.reference.empty() ? "" : ", " + reference.label)
       << "; it confirmed " << reference.pairs_confirmed_total << " distinct pairs.\n";
    md << "- A pair is *missed* when the reference confirms it and the run never does; "
          "*extra* the other way round; a pair the CCD stage stopped at its time of impact "
          "(*CCD stops*) counts as a contact at that time, and a pair the contact solver "
          "pushed apart (response: impulse, speculative contacts included) at the start of "
          "that step. First-contact error compares each common pair's first contact: the end "
          "of the first step that confirms it (resolution: the larger time step), its time of "
          "impact or the start of the step that pushed it. Max depth: the deepest "
          "overlap of a confirmed pair of convex bodies at the end of a step.\n";
    md << "- Energy drift: max over steps of |E - E0| / (sum of |kinetic| + |potential| terms at "
          "t = 0); |L| drift: max over bodies and steps of the relative change of a body's "
          "angular momentum.\n";
    if (options.report_timing) {
        md << "- Times are wall-clock, this machine, this build; they vary from run to run "
              "(results.csv keeps every stage). Memory: the process's peak resident set during "
              "the run less its resident set at the start (Linux VmHWM, reset per run).\n";
    }
    md << "\n| run | dt (s) | steps |";
    if (options.report_timing) md << " ms/step | ms per sim. s | memory (MiB) |";
    md << " flagged/step | confirmed/step | BP false pos./step | Nv/step | mesh Nv/step | Np/step "
          "| "
          "CCD stops | "
          "missed | extra | max TOI err (s) | max depth (m) | energy drift | abs L drift "
          "|\n|---|---|---|";
    if (options.report_timing) md << "---|---|---|";
    md << "---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    auto row = [&](const SweepRun& r) {
        md << "| " << r.label << " | " << fmt(r.time_step) << " | " << r.steps << " |";
        if (options.report_timing) {
            md << ' ' << fmt(r.ms_step, "%.3f") << " | " << fmt(r.ms_per_simulated_s, "%.1f")
               << " | " << fmt(r.memory_mib, "%.3g") << " |";
        }
        md << ' ' << fmt(r.flagged, "%.2f") << " | " << fmt(r.confirmed, "%.2f") << " | "
           << fmt(r.broad_false_positives, "%.2f") << " | " << fmt(r.bv_tests, "%.0f") << " | "
           << fmt(r.mesh_bv_tests, "%.0f") << " | " << fmt(r.triangle_tests, "%.0f") << " | "
           << r.toi_events << " | " << r.missed_pairs << " | " << r.extra_pairs << " | "
           << fmt(r.max_first_contact_error, "%.3g") << " | " << fmt(r.max_penetration, "%.3g")
           << " | " << fmt(r.max_energy_drift, "%.2e") << " | "
           << fmt(r.max_angular_momentum_drift, "%.2e") << " |\n";
    };
    for (const SweepRun& r : runs) row(r);
    SweepRun ref_row = reference;
    ref_row.label = "reference";
    row(ref_row);
    md << '\n';
    for (const Chart& c : charts()) {
        if (c.timing && !options.report_timing) continue;
        md << "![" << c.title << "](" << c.file << ")\n\n";
    }

    if (!floats.empty()) {
        md << floatSection(floats, (base.world.bounds.max - base.world.bounds.min).norm());
    }
    // The reading: which choice buys what, from the numbers above.
    md << "## Reading\n\n";
    const SweepRun* accurate = nullptr;
    for (const SweepRun& r : runs) {
        if (r.missed_pairs != 0 || r.extra_pairs != 0) continue;
        if (accurate == nullptr ||
            (options.report_timing ? r.ms_per_simulated_s < accurate->ms_per_simulated_s
                                   : r.bv_tests < accurate->bv_tests)) {
            accurate = &r;
        }
    }
    if (accurate != nullptr) {
        md << "- " << (options.report_timing ? "Cheapest" : "Fewest BV tests among the")
           << " runs that confirm exactly the reference's pairs: **" << accurate->label << "**";
        if (options.report_timing)
            md << " (" << fmt(accurate->ms_per_simulated_s, "%.1f") << " ms per simulated second)";
        md << ".\n";
    } else {
        md << "- No run confirms exactly the reference's pairs: every choice here trades "
              "contacts for speed; see the missed and extra columns.\n";
    }
    const auto tightest = std::min_element(runs.begin(), runs.end(), [](auto& a, auto& b) {
        return a.broad_false_positives < b.broad_false_positives;
    });
    const auto loosest = std::max_element(runs.begin(), runs.end(), [](auto& a, auto& b) {
        return a.broad_false_positives < b.broad_false_positives;
    });
    // Which keys the sweep varies: the volume lines speak only of a choice that was swept (a
    // time step changes the false positives too, but it is not a broad phase).
    auto varies = [&](std::string_view suffix) {
        for (const std::string& v : options.vary) {
            const std::string key = v.substr(0, v.find('='));
            if (key.size() >= suffix.size() &&
                key.compare(key.size() - suffix.size(), suffix.size(), suffix) == 0) {
                return true;
            }
        }
        return false;
    };
    // Named only when the difference shows in the printed figures (more than 1 %).
    if (varies("broadphase") && tightest != runs.end() &&
        loosest->broad_false_positives > 1.01 * tightest->broad_false_positives + 1e-9) {
        md << "- Tightest broad phase: **" << tightest->label << "** ("
           << fmt(tightest->broad_false_positives, "%.3g")
           << " false positives per step) against **" << loosest->label << "** ("
           << fmt(loosest->broad_false_positives, "%.3g") << "): every false positive costs a "
           << "narrow-phase test.\n";
    }
    // Mesh hierarchies: node tests against triangle tests (tight volumes test fewer triangles).
    const auto fewest_tri = std::min_element(runs.begin(), runs.end(), [](auto& a, auto& b) {
        return a.triangle_tests < b.triangle_tests;
    });
    const auto most_tri = std::max_element(runs.begin(), runs.end(), [](auto& a, auto& b) {
        return a.triangle_tests < b.triangle_tests;
    });
    if (varies("mesh_bvh") && fewest_tri != runs.end() &&
        fewest_tri->triangle_tests < most_tri->triangle_tests) {
        md << "- Fewest triangle tests: **" << fewest_tri->label << "** ("
           << fmt(fewest_tri->triangle_tests, "%.1f") << " per step, "
           << fmt(fewest_tri->mesh_bv_tests, "%.0f") << " hierarchy node tests) against **"
           << most_tri->label << "** (" << fmt(most_tri->triangle_tests, "%.1f") << ", "
           << fmt(most_tri->mesh_bv_tests, "%.0f") << "): a tighter volume costs more per node "
           << "test and saves triangle tests.\n";
    }
    if (!floats.empty()) {
        md << floatReading(floats, (base.world.bounds.max - base.world.bounds.min).norm());
    }
    std::int64_t worst_missed = 0;
    const SweepRun* worst = nullptr;
    for (const SweepRun& r : runs) {
        if (r.missed_pairs > worst_missed) {
            worst_missed = r.missed_pairs;
            worst = &r;
        }
    }
    if (worst != nullptr) {
        const bool all_same = std::all_of(runs.begin(), runs.end(), [&](const SweepRun& r) {
            return r.missed_pairs == worst_missed;
        });
        md << "- "
           << (all_same ? "Every run misses" : "Most contacts missed: **" + worst->label + "**,")
           << " " << worst->missed_pairs << " of the reference's "
           << reference.pairs_confirmed_total
           << " pairs (never confirmed nor stopped by CCD: tunnelling between steps, or contacts "
              "shorter than a step).\n";
    }
    return md.str();
}

// Single-quoted for /bin/sh: every character literal, ' written as '\''.
std::string shellQuote(const std::string& s) {
    std::string q = "'";
    for (char c : s) {
        if (c == '\'') {
            q += "'\\''";
        } else {
            q += c;
        }
    }
    return q + "'";
}

// Runs one combination through this (double) build in-process and through the float build as a
// child process, both writing traces, and compares them.
FloatRun compareFloat(const SweepOptions& options, const std::vector<engine::SceneOverride>& c,
                      const fs::path& dir, std::size_t index) {
    const std::string stem = "run" + std::to_string(index);
    RunOptions run;
    run.scene = options.scene;
    run.overrides = c;
    run.no_video = true;
    run.no_frames = true;
    run.progress = false;
    run.out_dir = dir / (stem + "_double");
    run.trace = dir / (stem + "_double.jsonl");
    std::ostringstream run_out, run_err;
    FloatRun result;
    result.label = labelOf(c);
    if (runScene(run, run_out, run_err) != 0) {
        result.comparison.error = "double run failed: " + run_err.str();
        return result;
    }
    const fs::path float_trace = dir / (stem + "_float.jsonl");
    std::string cmd = shellQuote(options.float_binary->string()) + " run " +
                      shellQuote(options.scene.string()) + " --no-frames --no-video --quiet" +
                      " --out " + shellQuote((dir / (stem + "_float")).string()) + " --trace " +
                      shellQuote(float_trace.string());
    for (const engine::SceneOverride& o : c) cmd += " --set " + shellQuote(o.key + "=" + o.value);
    cmd += " > " + shellQuote((dir / (stem + "_float.log")).string()) + " 2>&1";
    const int status = std::system(cmd.c_str());
    if (!(WIFEXITED(status) && WEXITSTATUS(status) == 0)) {
        result.comparison.error =
            "the float build failed (see " + (dir / (stem + "_float.log")).string() + ")";
        return result;
    }
    result.comparison = compareTraces(*run.trace, float_trace);
    return result;
}

}  // namespace

std::string floatReading(const std::vector<FloatRun>& floats, double scene_size) {
    std::ostringstream md;
    // Answers: one line when every run diverges the same way.
    std::vector<const FloatRun*> differing;
    std::vector<const FloatRun*> compared;
    for (const FloatRun& f : floats) {
        if (!f.comparison.error.empty()) continue;
        compared.push_back(&f);
        if (f.comparison.first_pair_difference >= 0) differing.push_back(&f);
    }
    const bool float_alike =
        !differing.empty() && differing.size() == floats.size() &&
        std::all_of(differing.begin(), differing.end(), [&](const FloatRun* f) {
            return f->comparison.first_pair_difference ==
                       differing[0]->comparison.first_pair_difference &&
                   f->comparison.pair_frames_differing ==
                       differing[0]->comparison.pair_frames_differing;
        });
    if (float_alike && differing.size() > 1) {
        md << "- Float changes the answers of every run from frame "
           << differing[0]->comparison.first_pair_difference << " on ("
           << differing[0]->comparison.pair_frames_differing << " of "
           << differing[0]->comparison.frames << " frames).\n";
    } else {
        for (const FloatRun* f : differing) {
            md << "- Float changes the answers of **" << f->label << "** from frame "
               << f->comparison.first_pair_difference << " on ("
               << f->comparison.pair_frames_differing << " of " << f->comparison.frames
               << " frames).\n";
        }
    }
    if (compared.empty()) return md.str();
    if (differing.empty()) {
        md << "- Float confirms the same pairs as double in every frame of every run";
        md << (compared.size() < floats.size() ? " that could be compared" : "") << ".\n";
    }
    // Trajectories, whatever the pairs did: a float run can confirm every pair of the double
    // run while its bodies end metres and radians away (a stop or bounce decided by the last
    // bits sends a body elsewhere), so the largest deviations are always stated, with the run.
    const auto by_position = [](const FloatRun* a, const FloatRun* b) {
        return a->comparison.max_position_deviation < b->comparison.max_position_deviation;
    };
    const auto by_orientation = [](const FloatRun* a, const FloatRun* b) {
        return a->comparison.max_orientation_deviation < b->comparison.max_orientation_deviation;
    };
    const FloatRun& far = **std::max_element(compared.begin(), compared.end(), by_position);
    const FloatRun& turned = **std::max_element(compared.begin(), compared.end(), by_orientation);
    const double dp = far.comparison.max_position_deviation;
    const double dq = turned.comparison.max_orientation_deviation;
    if (dp == 0 && dq == 0) {
        md << "- Float and double trajectories are identical in every frame of every run.\n";
        return md.str();
    }
    md << "- Largest trajectory divergence of float from double: position " << fmt(dp, "%.3g")
       << " m (" << fmt(dp / scene_size, "%.2e") << " of the scene size) in **" << far.label
       << "**; orientation " << fmt(dq, "%.3g") << " rad in **" << turned.label << "**.\n";
    return md.str();
}

TraceComparison compareTraces(const fs::path& a, const fs::path& b) {
    TraceComparison out;
    std::ifstream fa(a), fb(b);
    if (!fa || !fb) {
        out.error = "cannot read " + (fa ? b : a).string();
        return out;
    }
    std::string la, lb;
    try {
        while (std::getline(fa, la) && std::getline(fb, lb)) {
            const nlohmann::json ja = nlohmann::json::parse(la);
            const nlohmann::json jb = nlohmann::json::parse(lb);
            const auto& pa = ja.at("positions");
            const auto& pb = jb.at("positions");
            const auto& qa = ja.at("orientations_wxyz");
            const auto& qb = jb.at("orientations_wxyz");
            if (pa.size() != pb.size() || qa.size() != pa.size() || qb.size() != pb.size()) {
                out.error = "different body counts at frame " + std::to_string(out.frames);
                return out;
            }
            double frame_max = 0;
            for (std::size_t i = 0; i < pa.size(); ++i) {
                const Vec3Like d{pa[i][0].get<double>() - pb[i][0].get<double>(),
                                 pa[i][1].get<double>() - pb[i][1].get<double>(),
                                 pa[i][2].get<double>() - pb[i][2].get<double>()};
                frame_max = std::max(frame_max, std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z));
                // Rotation angle between unit quaternions, 4 atan2(|a - b|, |a + b|) with b's
                // sign matched to a's (|a -+ b| = 2 sin, 2 cos of a quarter of the angle): accurate
                // near 0, where 2 acos(a.b) loses half the digits.
                double dot = 0;
                for (int k = 0; k < 4; ++k) dot += qa[i][k].get<double>() * qb[i][k].get<double>();
                const double sign = dot < 0 ? -1 : 1;
                double diff2 = 0, sum2 = 0;
                for (int k = 0; k < 4; ++k) {
                    const double x = qa[i][k].get<double>();
                    const double y = sign * qb[i][k].get<double>();
                    diff2 += (x - y) * (x - y);
                    sum2 += (x + y) * (x + y);
                }
                const double angle = 4 * std::atan2(std::sqrt(diff2), std::sqrt(sum2));
                out.max_orientation_deviation = std::max(out.max_orientation_deviation, angle);
            }
            out.max_position_deviation = std::max(out.max_position_deviation, frame_max);
            out.final_position_deviation = frame_max;
            if (ja.at("colliding_pairs") != jb.at("colliding_pairs")) {
                ++out.pair_frames_differing;
                if (out.first_pair_difference < 0) out.first_pair_difference = out.frames;
            }
            ++out.frames;
        }
    } catch (const nlohmann::json::exception& e) {
        out.error = std::string("malformed trace: ") + e.what();
    }
    return out;
}

bool parseVary(const std::string& text, std::string& key, std::vector<std::string>& values,
               std::string& error) {
    const std::size_t eq = text.find('=');
    if (eq == std::string::npos || eq == 0) {
        error = "'" + text + "': expected KEY=V1,V2,...";
        return false;
    }
    key = trim(text.substr(0, eq));
    values.clear();
    int depth = 0;
    std::string current;
    for (std::size_t i = eq + 1; i <= text.size(); ++i) {
        const char c = i < text.size() ? text[i] : ',';
        if (c == '[' || c == '{') ++depth;
        if (c == ']' || c == '}') --depth;
        if (c == ',' && depth <= 0) {
            current = trim(current);
            if (current.empty()) {
                error = "'" + text + "': empty value";
                return false;
            }
            values.push_back(current);
            current.clear();
        } else {
            current += c;
        }
    }
    if (depth != 0) {
        error = "'" + text + "': unbalanced brackets";
        return false;
    }
    if (key.empty() || key.find_first_of(" \t") != std::string::npos) {
        error = "'" + text + "': bad key '" + key + "'";
        return false;
    }
    return true;
}

int runSweep(const SweepOptions& options, std::ostream& out, std::ostream& err) {
    // The axes of the sweep.
    std::vector<std::pair<std::string, std::vector<std::string>>> axes;
    for (const std::string& v : options.vary) {
        std::string key, error;
        std::vector<std::string> values;
        if (!parseVary(v, key, values, error)) {
            err << "--vary " << error << "\n";
            return kExitBadInput;
        }
        for (const auto& axis : axes) {
            if (axis.first == key) {
                err << "--vary " << key << ": given twice; list every value in one --vary (" << key
                    << "=A,B,...)\n";
                return kExitBadInput;
            }
        }
        axes.emplace_back(key, values);
    }
    std::vector<engine::SceneOverride> reference_overrides;
    for (const std::string& v : options.reference) {
        std::string key, error;
        std::vector<std::string> values;
        if (!parseVary(v, key, values, error) || values.size() != 1) {
            err << "--reference " << (error.empty() ? "'" + v + "': expected KEY=VALUE" : error)
                << "\n";
            return kExitBadInput;
        }
        reference_overrides.push_back({key, values[0], "--reference"});
    }
    if (!(options.reference_refine >= 1) || !std::isfinite(options.reference_refine)) {
        err << "--reference-refine: must be a finite number >= 1\n";
        return kExitBadInput;
    }
    if (options.duration && !(*options.duration > 0 && std::isfinite(*options.duration))) {
        err << "--duration: must be a finite number > 0\n";
        return kExitBadInput;
    }

    if (options.float_binary) {
        std::error_code ec;
        if (!fs::is_regular_file(*options.float_binary, ec)) {
            err << "--float-binary " << options.float_binary->string()
                << ": no such file (build one with cmake -DCDLAB_USE_FLOAT=ON)\n";
            return kExitBadInput;
        }
    }
    // Every combination is loaded (and so validated) before anything runs.
    std::vector<std::vector<engine::SceneOverride>> combos{{}};
    for (const auto& [key, values] : axes) {
        std::vector<std::vector<engine::SceneOverride>> next;
        for (const auto& c : combos) {
            for (const std::string& v : values) {
                next.push_back(c);
                next.back().push_back({key, v, "--vary"});
            }
        }
        combos = std::move(next);
    }
    engine::Scene base;
    std::vector<engine::Scene> scenes;
    try {
        base = engine::loadScene(options.scene);
    } catch (const engine::SceneError& e) {
        err << e.what() << "\n";
        return kExitBadInput;
    }
    for (const auto& c : combos) {
        try {
            scenes.push_back(engine::loadScene(options.scene, c));
        } catch (const engine::SceneError& e) {
            err << "sweep run '" << labelOf(c) << "': " << e.what() << "\n";
            return kExitBadInput;
        }
    }
    const double duration = options.duration ? *options.duration
                                             : double(std::max(base.frames - 1, 1)) *
                                                   base.steps_per_frame * base.world.time_step;
    engine::Scene reference_scene;
    try {
        std::vector<engine::SceneOverride> ref = {
            {"world.time_step", fmt(base.world.time_step / options.reference_refine, "%.17g")}};
        ref.insert(ref.end(), reference_overrides.begin(), reference_overrides.end());
        reference_scene = engine::loadScene(options.scene, ref);
    } catch (const engine::SceneError& e) {
        err << "sweep reference: " << e.what() << "\n";
        return kExitBadInput;
    }

    // Steps per run, checked before anything runs: llround of a huge quotient is undefined, and
    // a run of 1e20 s would never end.
    constexpr double kMaxSweepSteps = 1e9;
    std::vector<const engine::Scene*> all_runs{&reference_scene};
    for (const engine::Scene& s : scenes) all_runs.push_back(&s);
    for (const engine::Scene* s : all_runs) {
        const double steps = duration / s->world.time_step;
        if (!(steps <= kMaxSweepSteps)) {
            err << "--duration " << fmt(duration) << ": " << fmt(steps) << " steps at time step "
                << fmt(s->world.time_step) << " s, more than the limit of " << fmt(kMaxSweepSteps)
                << "\n";
            return kExitBadInput;
        }
    }

    const fs::path out_dir =
        options.out_dir.empty() ? fs::path("out") / ("sweep_" + base.name) : options.out_dir;
    try {
        prepareOutputDir(out_dir);
        for (const char* f :
             {"results.csv", "report.md", "float_vs_double.csv", "float_deviation.png"}) {
            fs::remove(out_dir / f);
        }
        for (const Chart& c : charts()) fs::remove(out_dir / c.file);

        FirstContacts reference_contacts;
        SweepRun reference = measure(reference_scene, duration, reference_contacts);
        reference.label = labelOf(reference_overrides);
        out << "reference: dt " << fmt(reference.time_step) << " s, " << reference.steps
            << " steps, " << reference.pairs_confirmed_total << " pairs confirmed\n";
        std::vector<SweepRun> runs;
        for (std::size_t i = 0; i < scenes.size(); ++i) {
            FirstContacts contacts;
            SweepRun run = measure(scenes[i], duration, contacts);
            run.overrides = combos[i];
            run.label = labelOf(combos[i]);
            compareWithReference(run, contacts, reference_contacts);
            out << "[" << i + 1 << "/" << scenes.size() << "] " << run.label << ": " << run.steps
                << " steps, " << fmt(run.ms_step, "%.3f") << " ms/step, "
                << fmt(run.broad_false_positives, "%.2f") << " broad false positives/step, "
                << run.missed_pairs << " missed, " << run.extra_pairs << " extra\n";
            runs.push_back(std::move(run));
        }

        for (const Chart& c : charts()) {
            if (c.timing && !options.report_timing) continue;
            render::BarChart chart;
            chart.title = c.title;
            chart.log_scale = c.log_scale;
            for (const SweepRun& r : runs) chart.bars.push_back({r.label, r.*(c.field), false});
            chart.bars.push_back({"reference", reference.*(c.field), true});
            render::writePng(out_dir / c.file, render::drawBarChart(chart));
        }
        std::vector<FloatRun> floats;
        if (options.float_binary) {
            const fs::path traces = out_dir / "traces";
            prepareOutputDir(traces);
            std::string csv =
                "run,frames,first_pair_difference,pair_frames_differing,max_position_deviation,"
                "final_position_deviation,max_orientation_deviation,error\n";
            render::BarChart chart;
            chart.title = "float vs double: max position deviation (m, log scale)";
            chart.log_scale = true;
            for (std::size_t i = 0; i < combos.size(); ++i) {
                floats.push_back(compareFloat(options, combos[i], traces, i));
                const TraceComparison& c = floats.back().comparison;
                out << "[float " << i + 1 << "/" << combos.size() << "] " << floats.back().label
                    << ": "
                    << (c.error.empty() ? "max deviation " + fmt(c.max_position_deviation) +
                                              " m, pairs differ in " +
                                              std::to_string(c.pair_frames_differing) + " frames"
                                        : c.error)
                    << "\n";
                csv += csvField(floats.back().label) + "," + std::to_string(c.frames) + "," +
                       std::to_string(c.first_pair_difference) + "," +
                       std::to_string(c.pair_frames_differing) + "," +
                       fmt(c.max_position_deviation, "%.6g") + "," +
                       fmt(c.final_position_deviation, "%.6g") + "," +
                       fmt(c.max_orientation_deviation, "%.6g") + "," + csvField(c.error) + "\n";
                chart.bars.push_back({floats.back().label, c.max_position_deviation, false});
            }
            writeTextAtomically(out_dir / "float_vs_double.csv", csv);
            if (!options.keep_traces) fs::remove_all(traces);
            render::writePng(out_dir / "float_deviation.png", render::drawBarChart(chart));
        }
        writeTextAtomically(out_dir / "results.csv", csvTable(runs));
        writeTextAtomically(out_dir / "report.md",
                            markdownReport(options, base, duration, runs, reference, floats));
        out << "wrote " << (out_dir / "report.md").string() << ", "
            << (out_dir / "results.csv").string() << " and charts\n";
    } catch (const std::exception& e) {
        err << "error: " << e.what() << "\n";
        return kExitFailure;
    }
    return kExitOk;
}

Command addSweepCommand(CLI::App& cli) {
    struct Flags {
        SweepOptions sweep;
        std::string out;
        double duration = 0;
        std::string float_binary;
        bool no_timing = false;
    };
    auto f = std::make_shared<Flags>();
    CLI::App* cmd = cli.add_subcommand(
        "sweep",
        "run one scene under every combination of choices; measure cost and accuracy "
        "against a fine reference run; write results.csv, report.md and charts");
    cmd->add_option("scene", f->sweep.scene, "scene file (YAML)")->required();
    cmd->add_option("--vary", f->sweep.vary,
                    "KEY=V1,V2,... (repeatable): a dotted scene key and its values, e.g. "
                    "broadphase=sap,hgrid or world.time_step=0.01,0.002")
        ->expected(1)
        ->take_all();
    cmd->add_option("--reference", f->sweep.reference,
                    "KEY=VALUE override for the reference run (repeatable)")
        ->expected(1)
        ->take_all();
    cmd->add_option("--reference-refine", f->sweep.reference_refine,
                    "the reference's time step is the scene's divided by this")
        ->capture_default_str();
    cmd->add_option("--duration", f->duration,
                    "simulated seconds per run (default: the scene's frames)");
    cmd->add_option("--out", f->out, "output directory (default out/sweep_<scene>)");
    cmd->add_option("--float-binary", f->float_binary,
                    "a cdlab built with -DCDLAB_USE_FLOAT=ON: compare every run's frames "
                    "with it (float_vs_double.csv, a report section)");
    cmd->add_flag("--keep-traces", f->sweep.keep_traces,
                  "keep DIR/traces/ (both builds' frames) after the float comparison");
    cmd->add_flag("--no-report-timing", f->no_timing,
                  "leave wall-clock times out of report.md so it is bit-identical");
    return {cmd, [cmd, f]() {
                SweepOptions& sweep = f->sweep;
                if (!f->out.empty()) sweep.out_dir = f->out;
                if (cmd->count("--duration") > 0) sweep.duration = f->duration;
                sweep.report_timing = !f->no_timing;
                if (!f->float_binary.empty()) sweep.float_binary = f->float_binary;
                return runSweep(sweep, std::cout, std::cerr);
            }};
}

}  // namespace app
