// app/lab/sweep.cpp -- `cdlab sweep` (see sweep.h): the combinations of --vary, the
// reference run, every run measured (sweep_measure.h) and written (sweep_report.h), and the
// float build's comparison.
// Every run simulates the same interval; accuracy is judged against one reference run of the
// same scene with a finer time step. Contacts are compared pair by pair through their first
// contact time: a pair the reference confirms and a run never does is missed; a pair both
// confirm contributes |t_run - t_ref| to the first-contact error (resolution: the larger of the
// two time steps). Everything but the wall-clock times is deterministic.
#include "sweep.h"

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

#include "exit_codes.h"
#include "output_files.h"
#include "render/chart.h"
#include "render/image.h"
#include "run_scene.h"
#include "sweep_measure.h"
#include "sweep_plan.h"
#include "sweep_local.h"
#include "sweep_setup.h"
#include "sweep_report.h"

namespace app {

namespace fs = std::filesystem;

using sweep::compareWithReference;
using sweep::csvField;
using sweep::FirstContacts;
using sweep::fmt;
using sweep::labelOf;
using sweep::measure;
using sweep::shellQuote;

namespace {

std::string trim(const std::string& s) {
    const std::size_t a = s.find_first_not_of(" \t");
    if (a == std::string::npos) return "";
    const std::size_t b = s.find_last_not_of(" \t");
    return s.substr(a, b - a + 1);
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

namespace {

// Every combination run again through the float build (--float-binary): float_vs_double.csv
// and its chart, and the comparisons for the report.
std::vector<FloatRun> compareFloatBuild(
    const SweepOptions& options, const std::vector<std::vector<engine::SceneOverride>>& combos,
    const fs::path& out_dir, std::ostream& out) {
    std::vector<FloatRun> floats;
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
    return floats;
}

// Runs every scene `options.repeat` times, the reference first, the repeats interleaved (all
// runs once, then all again) so that a slow spell of the machine spreads over every run instead
// of one run's repeats. The first pass measures everything; later passes only time the steps
// and must reproduce the first pass's deterministic columns. False (with a message) when one
// does not: determinism is a guarantee of the engine.
bool measureAll(const SweepOptions& options, const sweep::SweepSetup& setup, std::ostream& out,
                std::ostream& err, SweepRun& reference, std::vector<SweepRun>& runs) {
    const engine::Scene& reference_scene = setup.reference_scene;
    const std::vector<engine::Scene>& scenes = setup.scenes;
    const std::vector<std::vector<engine::SceneOverride>>& combos = setup.combos;
    const double duration = setup.duration;
    // repeats[0] is the reference, repeats[i + 1] scene i; each holds one SweepRun per pass.
    std::vector<std::vector<SweepRun>> repeats(scenes.size() + 1);
    FirstContacts reference_contacts;
    repeats[0].push_back(measure(reference_scene, duration, &reference_contacts));
    out << "reference: dt " << fmt(repeats[0][0].time_step) << " s, " << repeats[0][0].steps
        << " steps, " << repeats[0][0].pairs_confirmed_total << " pairs confirmed\n";
    for (std::size_t i = 0; i < scenes.size(); ++i) {
        FirstContacts contacts;
        SweepRun run = measure(scenes[i], duration, &contacts);
        compareWithReference(run, contacts, reference_contacts);
        out << "[" << i + 1 << "/" << scenes.size() << "] " << labelOf(combos[i]) << ": "
            << run.steps << " steps, " << fmt(run.ms_step.median, "%.3f") << " ms/step (repeat 1/"
            << options.repeat << "), " << fmt(run.broad_false_positives, "%.2f")
            << " broad false positives/step, " << run.missed_pairs << " missed, " << run.extra_pairs
            << " extra\n";
        repeats[i + 1].push_back(std::move(run));
    }
    for (int pass = 1; pass < options.repeat; ++pass) {
        for (std::size_t i = 0; i < repeats.size(); ++i) {
            const engine::Scene& scene = i == 0 ? reference_scene : scenes[i - 1];
            SweepRun again = measure(scene, duration, nullptr);
            const std::string difference = sweep::deterministicDifference(repeats[i][0], again);
            if (!difference.empty()) {
                err << "sweep " << (i == 0 ? "reference" : "run '" + labelOf(combos[i - 1]) + "'")
                    << ": repeat " << pass + 1 << " of " << options.repeat
                    << " differs from repeat 1 in " << difference
                    << ": the simulation is not deterministic\n";
                return false;
            }
            repeats[i].push_back(std::move(again));
        }
        out << "repeat " << pass + 1 << "/" << options.repeat << ": " << repeats.size()
            << " runs timed again, deterministic columns identical\n";
    }
    reference = sweep::combineRepeats(repeats[0]);
    reference.label = labelOf(setup.reference_overrides);
    for (std::size_t i = 0; i < scenes.size(); ++i) {
        SweepRun run = sweep::combineRepeats(repeats[i + 1]);
        run.overrides = combos[i];
        run.label = labelOf(combos[i]);
        run.step_vs_reference = sweep::stepVsReference(run.time_step, reference.time_step);
        runs.push_back(std::move(run));
    }
    return true;
}

}  // namespace

int runSweep(const SweepOptions& options, std::ostream& out, std::ostream& err) {
    if (options.float_binary) {
        std::error_code ec;
        if (!fs::is_regular_file(*options.float_binary, ec)) {
            err << "--float-binary " << options.float_binary->string()
                << ": no such file (build one with cmake -DCDLAB_USE_FLOAT=ON)\n";
            return kExitBadInput;
        }
        if (options.jobs != 1) {
            err << "-j " << options.jobs << ": the float comparison runs in one process; "
                << "leave out -j or --float-binary\n";
            return kExitBadInput;
        }
    }
    if (options.jobs < 1) {
        err << "-j " << options.jobs << ": must be >= 1 (runs at a time)\n";
        return kExitBadInput;
    }
    const std::optional<sweep::SweepSetup> setup = sweep::setUpSweep(options, err);
    if (!setup) return kExitBadInput;
    if (options.dry_run) return kExitOk;
    if (options.jobs > 1) return sweep::runPlannedLocally(options, *setup, out, err);
    const fs::path& out_dir = setup->out_dir;
    try {
        prepareOutputDir(out_dir);
        sweep::removeSweepOutputs(out_dir);

        std::vector<SweepRun> runs;
        SweepRun reference;
        if (!measureAll(options, *setup, out, err, reference, runs)) return kExitFailure;
        const std::vector<FloatRun> floats =
            options.float_binary ? compareFloatBuild(options, setup->combos, out_dir, out)
                                 : std::vector<FloatRun>{};
        sweep::writeSweepOutputs(options, setup->base, setup->duration, runs, reference, floats,
                                 {}, out_dir);
        out << "wrote " << (out_dir / "report.md").string() << ", "
            << (out_dir / "report.html").string() << ", "
            << (out_dir / "results.csv").string() << " and charts\n";
    } catch (const std::exception& e) {
        err << "error: " << e.what() << "\n";
        return kExitFailure;
    }
    return kExitOk;
}

}  // namespace app
