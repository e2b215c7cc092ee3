// app/lab/sweep_report.cpp -- see sweep_report.h.
#include "sweep_report.h"

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
#include "sweep_html.h"

namespace app {

namespace fs = std::filesystem;

namespace sweep {

namespace {


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

}  // namespace

std::string csvField(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string q = "\"";
    for (char c : s) {
        if (c == '"') q += '"';
        q += c;
    }
    return q + "\"";
}

std::string fmt(double v, const char* spec) {
    char text[48];
    std::snprintf(text, sizeof text, spec, v);
    return text;
}

namespace {

// Where the dt column says a run sits against the reference's step.
const char* stepVsReferenceName(StepVsReference s) {
    switch (s) {
        case StepVsReference::Same:
            return "same";
        case StepVsReference::Finer:
            return "finer";
        case StepVsReference::Coarser:
            break;
    }
    return "coarser";
}

}  // namespace

std::string csvTable(const std::vector<SweepRun>& runs) {
    std::ostringstream csv;
    const char* timed_names[] = {"ms_integrate", "ms_volumes",  "ms_broad", "ms_narrow",
                                 "ms_ccd",       "ms_response", "ms_step",  "ms_per_simulated_s"};
    csv << "run,time_step,dt_vs_reference,steps,repeats,clock";
    for (const char* name : timed_names) {
        csv << ',' << name << "_median," << name << "_min," << name << "_max";
    }
    csv << ",flagged,confirmed,broad_false_positives,bv_tests,"
           "narrow_tests,triangle_tests,mesh_bv_tests,toi_events,max_penetration_m,"
           "pairs_confirmed_total,missed_pairs,extra_pairs,"
           "max_first_contact_error_s,mean_first_contact_error_s,max_energy_drift,"
           "max_angular_momentum_drift,memory_mib,state_hash,cpu_clock";
    for (const char* name : {"cpu_ms_step", "cpu_ms_per_simulated_s"}) {
        csv << ',' << name << "_median," << name << "_min," << name << "_max";
    }
    csv << ",host,concurrent\n";
    for (const SweepRun& r : runs) {
        csv << csvField(r.label) << ',' << fmt(r.time_step, "%.17g") << ','
            << stepVsReferenceName(r.step_vs_reference) << ',' << r.steps << ',' << r.repeats
            << ",steady_clock";
        for (const Timed& t : {r.ms_integrate, r.ms_volumes, r.ms_broad, r.ms_narrow, r.ms_ccd,
                               r.ms_response, r.ms_step, r.ms_per_simulated_s}) {
            csv << ',' << fmt(t.median, "%.6g") << ',' << fmt(t.min, "%.6g") << ','
                << fmt(t.max, "%.6g");
        }
        for (double v : {r.flagged, r.confirmed, r.broad_false_positives, r.bv_tests,
                         r.narrow_tests, r.triangle_tests, r.mesh_bv_tests}) {
            csv << ',' << fmt(v, "%.6g");
        }
        csv << ',' << r.toi_events << ',' << fmt(r.max_penetration, "%.6g");
        csv << ',' << r.pairs_confirmed_total << ',' << r.missed_pairs << ',' << r.extra_pairs;
        for (double v : {r.max_first_contact_error, r.mean_first_contact_error, r.max_energy_drift,
                         r.max_angular_momentum_drift}) {
            csv << ',' << fmt(v, "%.6g");
        }
        csv << ',' << fmt(r.memory_mib, "%.4g") << ',' << r.state_hash << ",thread_cputime";
        for (const Timed& t : {r.cpu_ms_step, r.cpu_ms_per_simulated_s}) {
            csv << ',' << fmt(t.median, "%.6g") << ',' << fmt(t.min, "%.6g") << ','
                << fmt(t.max, "%.6g");
        }
        csv << ',' << csvField(r.host) << ',' << (r.concurrent ? 1 : 0) << '\n';
    }
    return csv.str();
}

const std::vector<Chart>& charts() {
    static const std::vector<Chart> kCharts{
        {"cost.png", "wall-clock ms per simulated second, median of the repeats (lower is cheaper)",
         [](const SweepRun& r) { return r.ms_per_simulated_s.median; }, false, true},
        {"broad_false_positives.png", "broad-phase false positives per step (flagged - confirmed)",
         [](const SweepRun& r) { return r.broad_false_positives; }, false, false},
        {"bv_tests.png", "bounding-volume tests per step (Nv)",
         [](const SweepRun& r) { return r.bv_tests; }, false, false},
        {"first_contact_error.png", "max first-contact time error vs reference (s)",
         [](const SweepRun& r) { return r.max_first_contact_error; }, false, false},
        {"energy_drift.png", "max relative energy drift (log scale)",
         [](const SweepRun& r) { return r.max_energy_drift; }, true, false},
    };
    return kCharts;
}

Ranking rankLowest(const std::vector<Timed>& values, int repeats) {
    Ranking ranking;
    if (values.empty()) return ranking;
    std::vector<std::size_t> order(values.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return values[a].median < values[b].median;
    });
    ranking.best = order.front();
    if (values.size() == 1) {
        ranking.state = Ranking::State::Only;
        return ranking;
    }
    if (repeats < 2) {
        ranking.state = Ranking::State::NoSpread;
        return ranking;
    }
    const Timed& best = values[ranking.best];
    ranking.overlapping.push_back(ranking.best);
    for (std::size_t k = 1; k < order.size(); ++k) {
        if (!(best.max < values[order[k]].min)) ranking.overlapping.push_back(order[k]);
    }
    ranking.state =
        ranking.overlapping.size() == 1 ? Ranking::State::Separated : Ranking::State::WithinSpread;
    if (ranking.state == Ranking::State::Separated) ranking.overlapping.clear();
    return ranking;
}

namespace {

// A timed figure as a table cell: "median (min..max)", the median alone for one repeat.
std::string timedCell(const Timed& t, int repeats, const char* spec) {
    if (repeats < 2) return fmt(t.median, spec);
    std::string cell = fmt(t.median, spec);
    cell += " (";
    cell += fmt(t.min, spec);
    cell += "..";
    cell += fmt(t.max, spec);
    cell += ")";
    return cell;
}

// The table of every run and the reference, one row each.
std::string resultsTable(const SweepOptions& options, const std::vector<SweepRun>& runs,
                         const SweepRun& reference) {
    std::ostringstream md;
    md << "\n| run | dt (s) | steps |";
    if (options.report_timing) {
        md << " ms/step, median (min..max) | ms per sim. s, median (min..max) | CPU ms per sim. "
              "s, median (min..max) | memory (MiB) |";
    }
    md << " flagged/step | confirmed/step | BP false pos./step | Nv/step | mesh Nv/step | Np/step "
          "| "
          "CCD stops | "
          "missed | extra | max TOI err (s) | max depth (m) | energy drift | abs L drift "
          "|\n|---|---|---|";
    if (options.report_timing) md << "---|---|---|---|";
    md << "---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    auto row = [&](const SweepRun& r, bool is_reference) {
        md << "| " << r.label << " | " << fmt(r.time_step);
        if (!is_reference && r.step_vs_reference != StepVsReference::Coarser) {
            md << (r.step_vs_reference == StepVsReference::Same ? " (= reference)"
                                                                : " (< reference)");
        }
        md << " | " << r.steps << " |";
        if (options.report_timing) {
            md << ' ' << timedCell(r.ms_step, r.repeats, "%.3f") << " | "
               << timedCell(r.ms_per_simulated_s, r.repeats, "%.3g") << " | "
               << timedCell(r.cpu_ms_per_simulated_s, r.repeats, "%.3g") << " | "
               << fmt(r.memory_mib, "%.3g") << " |";
        }
        md << ' ' << fmt(r.flagged, "%.2f") << " | " << fmt(r.confirmed, "%.2f") << " | "
           << fmt(r.broad_false_positives, "%.2f") << " | " << fmt(r.bv_tests, "%.0f") << " | "
           << fmt(r.mesh_bv_tests, "%.0f") << " | " << fmt(r.triangle_tests, "%.0f") << " | "
           << r.toi_events << " | " << r.missed_pairs << " | " << r.extra_pairs << " | "
           << fmt(r.max_first_contact_error, "%.3g") << " | " << fmt(r.max_penetration, "%.3g")
           << " | " << fmt(r.max_energy_drift, "%.2e") << " | "
           << fmt(r.max_angular_momentum_drift, "%.2e") << " |\n";
    };
    for (const SweepRun& r : runs) row(r, false);
    SweepRun ref_row = reference;
    ref_row.label = "reference";
    row(ref_row, true);
    return md.str();
}

// The timed column the reading ranks runs by: wall-clock ms per simulated second, or thread
// CPU ms per simulated second when the runs were timed concurrently (their wall-clock times
// then measure the machine's load as much as the run).
struct CostClock {
    Timed SweepRun::*field;
    const char* unit;  // "ms per simulated second", "CPU ms per simulated second"
};

CostClock costClock(const SweepOptions& options) {
    if (options.timed_concurrently) {
        return {&SweepRun::cpu_ms_per_simulated_s, "CPU ms per simulated second"};
    }
    return {&SweepRun::ms_per_simulated_s, "ms per simulated second"};
}

// The cost of a run for the reading: median (min..max).
std::string costFigure(const SweepRun& r, const CostClock& clock) {
    return timedCell(r.*clock.field, r.repeats, "%.3g");
}

// The reading's line on cost among `runs`: the cheapest is named only when its whole min..max
// range lies below every other run's (rankLowest), otherwise the runs within its spread are
// listed and no winner is named.
std::string costReading(const std::string& what, const std::vector<const SweepRun*>& runs,
                        const CostClock& clock) {
    std::vector<Timed> cost;
    for (const SweepRun* r : runs) cost.push_back(r->*clock.field);
    const int repeats = runs.front()->repeats;
    const Ranking ranking = rankLowest(cost, repeats);
    const SweepRun& best = *runs[ranking.best];
    std::ostringstream md;
    const std::string spread = std::string(clock.unit) + ", median (min..max of " +
                               std::to_string(repeats) + " repeats)";
    switch (ranking.state) {
        case Ranking::State::Empty:
            break;
        case Ranking::State::Only:
            md << "- Only one of the " << what << ": **" << best.label << "** ("
               << costFigure(best, clock) << " " << clock.unit << ").\n";
            break;
        case Ranking::State::NoSpread:
            md << "- Cheapest of the " << what << ": none named, each was timed once "
               << "(--repeat 1), so there is no spread to compare the differences with.\n";
            break;
        case Ranking::State::Separated:
            md << "- Cheapest of the " << what << ": **" << best.label << "** ("
               << costFigure(best, clock) << " " << spread
               << "); its slowest repeat beat every other run's fastest.\n";
            break;
        case Ranking::State::WithinSpread: {
            md << "- Cheapest of the " << what << ": none named, the lowest costs are within "
               << "measurement spread of each other (" << spread << "): ";
            for (std::size_t k = 0; k < ranking.overlapping.size(); ++k) {
                const SweepRun& r = *runs[ranking.overlapping[k]];
                md << (k == 0 ? "" : ", ") << "**" << r.label << "** " << costFigure(r, clock);
            }
            md << ".\n";
            break;
        }
    }
    return md.str();
}

// A reading line for every run at the reference's time step or finer: its missed, extra and
// first-contact figures measure no time-step error.
std::string referenceStepReading(const std::vector<SweepRun>& runs, const SweepRun& reference) {
    std::ostringstream md;
    for (const SweepRun& r : runs) {
        if (r.step_vs_reference == StepVsReference::Coarser) continue;
        const bool same = r.step_vs_reference == StepVsReference::Same;
        md << "- **" << r.label << "** runs at "
           << (same ? "the reference's time step" : "a time step finer than the reference's")
           << " (" << fmt(r.time_step) << " s against " << fmt(reference.time_step)
           << " s): its missed, extra and first-contact figures "
           << (same ? "compare the reference's step with itself" : "compare it with a coarser run")
           << ", so they prove nothing about the time step. Choose a finer reference "
              "(--reference-refine, or --reference world.time_step=...).\n";
    }
    return md.str();
}

// "Reading": which choice buys what, from the numbers of the table.
std::string readingSection(const SweepOptions& options, const engine::Scene& base,
                           const std::vector<SweepRun>& runs, const SweepRun& reference,
                           const std::vector<FloatRun>& floats) {
    std::ostringstream md;
    md << "## Reading\n\n";
    md << referenceStepReading(runs, reference);
    // Accurate: confirms exactly the reference's pairs, each in time, at a coarser step than the
    // reference's (at its step or finer the comparison proves nothing about the step). In time:
    // a discrete step confirms a contact at the end of the step it began in, so a first contact
    // may be late by up to the run's step plus the reference's; later, the pair was found by
    // chance (after a bounce, on a later pass), not where it happened.
    std::vector<const SweepRun*> accurate;
    for (const SweepRun& r : runs) {
        if (r.missed_pairs != 0 || r.extra_pairs != 0 ||
            r.step_vs_reference != StepVsReference::Coarser) {
            continue;
        }
        const double allowed = r.time_step + reference.time_step;
        if (r.max_first_contact_error <= allowed) {
            accurate.push_back(&r);
            continue;
        }
        md << "- **" << r.label << "** confirms the reference's pairs, but a first contact comes "
           << fmt(r.max_first_contact_error) << " s off the reference's, more than its step plus "
           << "the reference's (" << fmt(allowed) << " s): found by chance, not where it "
           << "happened; not counted as accurate.\n";
    }
    const char* const accurate_runs = "runs that confirm exactly the reference's pairs in time";
    if (accurate.empty()) {
        md << "- No run coarser than the reference confirms exactly the reference's pairs in "
              "time: every choice here trades contacts for speed; see the missed, extra and "
              "first-contact columns.\n";
    } else if (options.report_timing) {
        md << costReading(accurate_runs, accurate, costClock(options));
    } else {
        const SweepRun* fewest = *std::min_element(
            accurate.begin(), accurate.end(),
            [](const SweepRun* a, const SweepRun* b) { return a->bv_tests < b->bv_tests; });
        md << "- Fewest BV tests among the " << accurate_runs << ": **" << fewest->label
           << "**.\n";
    }
    // Among all runs too, unless the lowest median is an accurate run (the line above said it).
    if (options.report_timing && runs.size() > 1) {
        std::vector<const SweepRun*> all;
        for (const SweepRun& r : runs) all.push_back(&r);
        const CostClock clock = costClock(options);
        const SweepRun* lowest = *std::min_element(
            all.begin(), all.end(), [&clock](const SweepRun* a, const SweepRun* b) {
                return (a->*clock.field).median < (b->*clock.field).median;
            });
        if (std::find(accurate.begin(), accurate.end(), lowest) == accurate.end()) {
            md << costReading("runs, whatever their accuracy", all, clock);
        }
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

// The report's note on the clocks: which clock each timed column reads, how the repeats were
// taken, and which clock the reading ranks by.
std::string timingNote(const SweepOptions& options, const std::vector<SweepRun>& runs,
                       const SweepRun& reference) {
    const int repeats = runs.empty() ? reference.repeats : runs.front().repeats;
    std::ostringstream md;
    md << "- Times are wall-clock (std::chrono::steady_clock inside World::step), this "
          "machine, this build; they vary from run to run. Every run, the reference too, "
          "was timed "
       << repeats;
    if (options.planned) {
        md << (repeats == 1 ? " time" : " times, back to back")
           << ", each run a job in a process of its own";
    } else {
        md << (repeats == 1 ? " time" : " times, the repeats interleaved across runs");
    }
    md << "; the table gives the median and the min..max range (results.csv: every stage). "
          "The reading names a run cheapest only when its slowest repeat beat every other "
          "run's fastest. Memory: the process's peak resident set during the first repeat "
          "less its resident set at the start (Linux VmHWM, reset per run).\n";
    md << "- CPU columns: the stepping thread's CPU time (CLOCK_THREAD_CPUTIME_ID around "
          "World::step), which other processes sharing the cores disturb far less than the "
          "wall clock.";
    if (options.timed_concurrently) {
        md << " The runs were timed concurrently (jobs overlapping on one host, or on several "
              "hosts; results.csv: host, concurrent), so their wall-clock times include waiting "
              "for shared cores: the reading ranks them by CPU time.";
    }
    md << "\n";
    return md.str();
}

// The runs that left no result, each with its reason: the table and the reading leave them out.
std::string failureSection(const std::vector<SweepFailure>& failures) {
    if (failures.empty()) return "";
    std::ostringstream md;
    md << "\n## Missing or failed runs\n\n"
       << failures.size() << (failures.size() == 1 ? " run" : " runs")
       << " of the plan left no result; the table and the reading below leave "
       << (failures.size() == 1 ? "it" : "them") << " out.\n\n";
    for (const SweepFailure& f : failures) md << "- **" << f.label << "**: " << f.reason << "\n";
    return md.str();
}

}  // namespace

std::string markdownReport(const SweepOptions& options, const engine::Scene& base, double duration,
                           const std::vector<SweepRun>& runs, const SweepRun& reference,
                           const std::vector<FloatRun>& floats,
                           const std::vector<SweepFailure>& failures) {
    std::ostringstream md;
    md << "# Sweep of `" << options.scene.filename().string() << "`\n\n";
    md << "- " << base.bodies.size() << " bodies, " << fmt(duration) << " s simulated per run, "
       << "broad phase `" << base.world.broad_phase << "` unless varied.\n";
    md << "- Reference: the same scene at time step " << fmt(reference.time_step) << " s ("
       << reference.steps << " steps; the scene's " << fmt(base.world.time_step)
       << " s divided by --reference-refine " << fmt(options.reference_refine)
       << (options.reference.empty() ? "" : ", then --reference " + reference.label)
       << "); it confirmed " << reference.pairs_confirmed_total << " distinct pairs. A run at "
       << "its time step or finer is marked in the dt column: its accuracy figures prove "
          "nothing about the step.\n";
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
    if (options.report_timing) md << timingNote(options, runs, reference);
    md << failureSection(failures);
    md << resultsTable(options, runs, reference);
    md << '\n';
    for (const Chart& c : charts()) {
        if (c.timing && !options.report_timing) continue;
        md << "![" << c.title << "](" << c.file << ")\n\n";
    }

    if (!floats.empty()) {
        md << floatSection(floats, (base.world.bounds.max - base.world.bounds.min).norm());
    }
    md << readingSection(options, base, runs, reference, floats);
    return md.str();
}

void writeSweepOutputs(const SweepOptions& options, const engine::Scene& base, double duration,
                       const std::vector<SweepRun>& runs, const SweepRun& reference,
                       const std::vector<FloatRun>& floats,
                       const std::vector<SweepFailure>& failures, const fs::path& out_dir) {
    // One bar chart per column of charts() (timings only with report_timing), reference last.
    for (const Chart& c : charts()) {
        if (c.timing && !options.report_timing) continue;
        render::BarChart chart;
        chart.title = c.title;
        chart.log_scale = c.log_scale;
        for (const SweepRun& r : runs) chart.bars.push_back({r.label, c.value(r), false});
        chart.bars.push_back({"reference", c.value(reference), true});
        render::writePng(out_dir / c.file, render::drawBarChart(chart));
    }
    writeTextAtomically(out_dir / "results.csv", csvTable(runs));
    writeTextAtomically(out_dir / "report.md", markdownReport(options, base, duration, runs,
                                                              reference, floats, failures));
    writeSweepHtml(out_dir / "report.html", options, runs, reference, floats, failures);
}

void removeSweepOutputs(const fs::path& out_dir) {
    for (const char* f :
         {"results.csv", "report.md", "report.html", "float_vs_double.csv",
          "float_deviation.png"}) {
        fs::remove(out_dir / f);
    }
    for (const Chart& c : charts()) fs::remove(out_dir / c.file);
}

}  // namespace sweep

using sweep::fmt;

namespace {

struct Vec3Like {
    double x, y, z;
};

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

}  // namespace app
