// app/lab/sweep_collect.cpp -- see sweep_collect.h.
// Accuracy is computed here, from each job's first contacts and the reference job's, exactly as
// the one-process sweep computes it (compareWithReference), so the collected deterministic
// columns are bit-identical to its.
#include "sweep_collect.h"

#include <algorithm>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>

#include "exit_codes.h"
#include "output_files.h"
#include "sweep_job.h"
#include "sweep_measure.h"
#include "sweep_report.h"

namespace app::sweep {

namespace fs = std::filesystem;

namespace {

// Marks every run whose timed interval overlapped another job's on the same host; true when any
// did, or when the runs were timed on more than one host (their clocks are not comparable).
bool markConcurrent(std::vector<JobResult>& results) {
    std::map<std::string, int> hosts;
    bool any = false;
    for (JobResult& a : results) {
        ++hosts[a.measured.host];
        for (const JobResult& b : results) {
            if (&a == &b || a.measured.host != b.measured.host) continue;
            if (a.started < b.finished && b.started < a.finished) a.measured.concurrent = true;
        }
        any = any || a.measured.concurrent;
    }
    return any || hosts.size() > 1;
}

// The report when the reference left no result: the failures, and why nothing else is there.
std::string failureOnlyReport(const SweepPlan& plan, const std::vector<SweepFailure>& failures) {
    std::ostringstream md;
    md << "# Sweep of `" << plan.scene.filename().string() << "`\n\n"
       << "The reference run left no result, so no run's accuracy can be measured: no table, "
          "no charts, no results.csv. Run the missing jobs again (lines of jobs.txt) and "
          "collect again.\n\n## Missing or failed runs\n\n";
    for (const SweepFailure& f : failures) md << "- **" << f.label << "**: " << f.reason << "\n";
    return md.str();
}

}  // namespace

std::optional<CollectedSweep> gatherResults(const SweepPlan& plan, std::ostream& err) {
    CollectedSweep collected;
    std::vector<JobResult> results;
    std::vector<std::string> bad;
    for (std::size_t k = 0; k < plan.runs.size(); ++k) {
        const std::string label = k == 0 ? "reference" : plan.runs[k].label;
        const fs::path file = resultPath(plan, k);
        std::error_code ec;
        if (!fs::exists(file, ec)) {
            collected.failures.push_back(
                {label, "job " + std::to_string(k) + " left no result (" + file.string() +
                            "): it did not run, is still running, or was killed"});
            continue;
        }
        try {
            JobResult r = parseResult(fileBytes(file), plan, k);
            if (!r.failure.empty()) {
                collected.failures.push_back(
                    {label, "job " + std::to_string(k) + " failed: " + r.failure});
                continue;
            }
            results.push_back(std::move(r));
        } catch (const std::runtime_error& e) {
            bad.push_back(file.string() + ": " + e.what());
        }
    }
    if (!bad.empty()) {
        for (const std::string& b : bad) err << b << "\n";
        err << "sweep --collect: " << bad.size() << " unusable result file"
            << (bad.size() == 1 ? "" : "s") << "; nothing written (remove "
            << (bad.size() == 1 ? "it" : "them") << " and run the jobs again)\n";
        return std::nullopt;
    }
    collected.timed_concurrently = markConcurrent(results);
    if (results.empty() || results.front().run != 0) return collected;
    const JobResult& ref = results.front();
    collected.reference = ref.measured;
    collected.reference->label = plan.runs[0].label;
    for (std::size_t i = 1; i < results.size(); ++i) {
        SweepRun run = results[i].measured;
        compareWithReference(run, results[i].contacts, ref.contacts);
        run.overrides = plan.runs[results[i].run].overrides;
        run.label = plan.runs[results[i].run].label;
        run.step_vs_reference = stepVsReference(run.time_step, ref.measured.time_step);
        collected.runs.push_back(std::move(run));
    }
    return collected;
}

int collectSweep(const CollectOptions& options, std::ostream& out, std::ostream& err) {
    const std::optional<SweepPlan> plan = readPlan(options.plan, err);
    if (!plan) return kExitBadInput;
    const std::optional<CollectedSweep> collected = gatherResults(*plan, err);
    if (!collected) return kExitBadInput;
    engine::Scene base;
    try {
        base = engine::loadScene(plan->scene);
    } catch (const engine::SceneError& e) {
        err << e.what() << "\n";
        return kExitBadInput;
    }
    SweepOptions sweep;
    sweep.scene = plan->scene;
    sweep.vary = plan->vary;
    sweep.reference = plan->reference;
    sweep.reference_refine = plan->reference_refine;
    sweep.repeat = plan->repeat;
    sweep.duration = plan->duration;
    sweep.report_timing = options.report_timing;
    sweep.planned = true;
    sweep.timed_concurrently = collected->timed_concurrently;
    const fs::path out_dir = options.out_dir.empty() ? plan->dir : options.out_dir;
    try {
        prepareOutputDir(out_dir);
        removeSweepOutputs(out_dir);
        if (collected->reference) {
            writeSweepOutputs(sweep, base, plan->duration, collected->runs, *collected->reference,
                              {}, collected->failures, out_dir);
        } else {
            writeTextAtomically(out_dir / "report.md",
                                failureOnlyReport(*plan, collected->failures));
        }
    } catch (const std::exception& e) {
        err << "error: " << e.what() << "\n";
        return kExitFailure;
    }
    out << "collected " << plan->runs.size() - collected->failures.size() << " of "
        << plan->runs.size() << " jobs"
        << (collected->timed_concurrently ? " (timed concurrently: the reading ranks by CPU time)"
                                          : "")
        << "; wrote " << (out_dir / "report.md").string()
        << (collected->reference ? ", report.html, results.csv and charts" : "") << "\n";
    for (const SweepFailure& f : collected->failures) {
        err << "sweep --collect: missing " << f.label << ": " << f.reason << "\n";
    }
    return collected->failures.empty() ? kExitOk : kExitFailure;
}

}  // namespace app::sweep
