// app/lab/sweep_plan.cpp -- see sweep_plan.h.
// A plan's id covers every field of plan.json, its creation time and 64 random bits, so the
// results of one plan can never be taken for another's, even a re-plan of the same sweep in the
// same second.
#include "sweep_plan.h"

#include <chrono>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "exit_codes.h"
#include "output_files.h"
#include "sweep_measure.h"
#include "sweep_report.h"

namespace app::sweep {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr const char* kPlanFormat = "cdlab-sweep-plan 1";

// The current time, UTC, to the second.
std::string utcNow() {
    const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
    std::tm tm{};
    gmtime_r(&now, &tm);
    char text[32];
    std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &tm);
    return text;
}

// plan.json without its id: what the id is computed over (nlohmann keeps object keys sorted, so
// the text is canonical).
json planContent(const SweepPlan& plan) {
    json runs = json::array();
    for (const PlannedRun& r : plan.runs) {
        json overrides = json::array();
        for (const engine::SceneOverride& o : r.overrides) {
            overrides.push_back({{"key", o.key}, {"value", o.value}, {"option", o.option}});
        }
        runs.push_back({{"label", r.label}, {"overrides", overrides}});
    }
    // duration and reference_refine: nlohmann prints the shortest text that reads back to the
    // same double, so the plan pins them bit for bit.
    return {{"format", kPlanFormat},
            {"scene", plan.scene.string()},
            {"scene_fnv1a", plan.scene_hash},
            {"binary", plan.binary.string()},
            {"duration", plan.duration},
            {"repeat", plan.repeat},
            {"reference_refine", plan.reference_refine},
            {"vary", plan.vary},
            {"reference", plan.reference},
            {"created", plan.created},
            {"nonce", plan.nonce},
            {"runs", runs}};
}

std::string planId(const SweepPlan& plan) { return fnv1aHex(planContent(plan).dump()); }

// The plan's fields from plan.json; throws json::exception on a missing or mistyped field.
SweepPlan planFromJson(const json& j) {
    SweepPlan plan;
    plan.id = j.at("id").get<std::string>();
    plan.scene = j.at("scene").get<std::string>();
    plan.scene_hash = j.at("scene_fnv1a").get<std::string>();
    plan.binary = j.at("binary").get<std::string>();
    plan.duration = j.at("duration").get<double>();
    plan.repeat = j.at("repeat").get<int>();
    plan.reference_refine = j.at("reference_refine").get<double>();
    plan.vary = j.at("vary").get<std::vector<std::string>>();
    plan.reference = j.at("reference").get<std::vector<std::string>>();
    plan.created = j.at("created").get<std::string>();
    plan.nonce = j.at("nonce").get<std::string>();
    for (const json& r : j.at("runs")) {
        PlannedRun run;
        run.label = r.at("label").get<std::string>();
        for (const json& o : r.at("overrides")) {
            run.overrides.push_back({o.at("key").get<std::string>(),
                                     o.at("value").get<std::string>(),
                                     o.at("option").get<std::string>()});
        }
        plan.runs.push_back(std::move(run));
    }
    return plan;
}

}  // namespace

std::string fnv1aHex(const std::string& bytes) {
    std::uint64_t h = 14695981039346656037ull;  // FNV-1a offset basis and prime (Fowler, Noll, Vo)
    for (unsigned char c : bytes) {
        h ^= c;
        h *= 1099511628211ull;
    }
    char text[17];
    std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
    return text;
}

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

SweepPlan makePlan(const SweepOptions& options, const SweepSetup& setup, const fs::path& binary,
                   const fs::path& dir) {
    SweepPlan plan;
    plan.dir = fs::absolute(dir).lexically_normal();
    plan.scene = fs::absolute(options.scene).lexically_normal();
    plan.scene_hash = fnv1aHex(fileBytes(plan.scene));
    plan.binary = fs::absolute(binary).lexically_normal();
    plan.duration = setup.duration;
    plan.repeat = options.repeat;
    plan.reference_refine = options.reference_refine;
    plan.vary = options.vary;
    plan.reference = options.reference;
    plan.created = utcNow();
    std::random_device random;
    plan.nonce = fnv1aHex(std::to_string(random()) + "/" + std::to_string(random()) + "/" +
                          plan.dir.string());
    plan.runs.push_back({labelOf(setup.reference_overrides), setup.reference_run});
    for (const auto& c : setup.combos) plan.runs.push_back({labelOf(c), c});
    plan.id = planId(plan);
    return plan;
}

fs::path resultPath(const SweepPlan& plan, std::size_t k) {
    return plan.dir / "results" / (std::to_string(k) + ".json");
}

std::string jobCommand(const SweepPlan& plan, std::size_t k) {
    return shellQuote(plan.binary.string()) + " sweep --job " +
           shellQuote((plan.dir / "plan.json").string()) + " --run " + std::to_string(k);
}

std::string slurmScript(const SweepPlan& plan) {
    const std::string dir = plan.dir.string();
    std::ostringstream s;
    s << "#!/bin/bash\n"
      << "# The jobs of the cdlab sweep planned in " << dir << " (plan " << plan.id
      << ") as a Slurm job array:\n"
      << "# task K runs line K + 1 of jobs.txt, which writes results/K.json. Submit, then\n"
      << "# collect once every task has ended (afterany: failed tasks are named, not waited "
         "for):\n"
      << "#   jobid=$(sbatch --parsable " << shellQuote(dir + "/sweep.sbatch") << ")\n"
      << "#   sbatch --dependency=afterany:$jobid --wrap "
      << shellQuote(shellQuote(plan.binary.string()) + " sweep --collect " + shellQuote(dir))
      << "\n"
      << "#SBATCH --job-name=cdlab-sweep\n"
      << "#SBATCH --array=0-" << plan.runs.size() - 1 << "\n"
      << "#SBATCH --ntasks=1\n"
      << "#SBATCH --cpus-per-task=1\n"
      << "#SBATCH --output=" << dir << "/logs/slurm-%A_%a.log\n"
      << "set -euo pipefail\n"
      << ": \"${SLURM_ARRAY_TASK_ID:?run this script with sbatch (a job array task)}\"\n"
      << "line=$(sed -n \"$((SLURM_ARRAY_TASK_ID + 1))p\" " << shellQuote(dir + "/jobs.txt")
      << ")\n"
      << "if [ -z \"$line\" ]; then\n"
      << "  echo \"no job $SLURM_ARRAY_TASK_ID in " << dir << "/jobs.txt\" >&2\n"
      << "  exit 2\n"
      << "fi\n"
      << "eval \"$line\"\n";
    return s.str();
}

void writePlan(const SweepPlan& plan, bool slurm) {
    prepareOutputDir(plan.dir);
    for (const char* sub : {"results", "logs"}) {
        fs::remove_all(plan.dir / sub);
        prepareOutputDir(plan.dir / sub);
    }
    fs::remove(plan.dir / "sweep.sbatch");
    json j = planContent(plan);
    j["id"] = plan.id;
    std::string jobs;
    for (std::size_t k = 0; k < plan.runs.size(); ++k) jobs += jobCommand(plan, k) + "\n";
    // plan.json last: a directory whose plan.json exists was planned completely.
    fs::remove(plan.dir / "plan.json");
    writeTextAtomically(plan.dir / "jobs.txt", jobs);
    if (slurm) writeTextAtomically(plan.dir / "sweep.sbatch", slurmScript(plan));
    writeTextAtomically(plan.dir / "plan.json", j.dump(2) + "\n");
}

std::optional<SweepPlan> readPlan(const fs::path& path, std::ostream& err) {
    std::error_code ec;
    const fs::path file = fs::is_directory(path, ec) ? path / "plan.json" : path;
    if (!fs::is_regular_file(file, ec)) {
        err << file.string() << ": no such plan (write one with cdlab sweep SCENE --vary ... "
            << "--plan DIR)\n";
        return std::nullopt;
    }
    SweepPlan plan;
    try {
        const json j = json::parse(fileBytes(file));
        if (!j.is_object() || j.value("format", "") != kPlanFormat) {
            err << file.string() << ": not a cdlab sweep plan (format '" << kPlanFormat << "')\n";
            return std::nullopt;
        }
        plan = planFromJson(j);
    } catch (const json::exception& e) {
        err << file.string() << ": malformed plan: " << e.what() << "\n";
        return std::nullopt;
    }
    if (plan.runs.empty() || plan.repeat < 1 || !(plan.duration > 0)) {
        err << file.string() << ": malformed plan: no runs, repeat < 1 or duration <= 0\n";
        return std::nullopt;
    }
    if (planId(plan) != plan.id) {
        err << file.string() << ": the plan's content does not match its id " << plan.id
            << " (edited after planning?): plan again\n";
        return std::nullopt;
    }
    plan.dir = fs::absolute(file.parent_path()).lexically_normal();
    return plan;
}

int planSweep(const SweepOptions& options, const fs::path& dir, bool slurm, const fs::path& binary,
              std::ostream& out, std::ostream& err) {
    if (options.float_binary) {
        err << "--plan: the float comparison (--float-binary) runs in one process only\n";
        return kExitBadInput;
    }
    const std::optional<SweepSetup> setup = setUpSweep(options, err);
    if (!setup) return kExitBadInput;
    if (options.dry_run) return kExitOk;
    const SweepPlan plan = makePlan(options, *setup, binary, dir);
    try {
        writePlan(plan, slurm);
    } catch (const std::exception& e) {
        err << "error: " << e.what() << "\n";
        return kExitFailure;
    }
    const std::string d = plan.dir.string();
    out << "planned " << plan.runs.size() << " jobs (the reference and " << plan.runs.size() - 1
        << " combinations), plan " << plan.id << ": " << d << "/jobs.txt, one command a line\n"
        << "run them, e.g.  parallel --jobs 2 :::: " << shellQuote(d + "/jobs.txt") << "\n";
    if (slurm) out << "or on Slurm:    sbatch " << shellQuote(d + "/sweep.sbatch") << "\n";
    out << "then collect:   cdlab sweep --collect " << shellQuote(d) << "\n";
    return kExitOk;
}

}  // namespace app::sweep
