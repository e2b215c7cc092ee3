// app/lab/sweep_job.cpp -- see sweep_job.h.
// A job repeats its run back to back (the one-process sweep interleaves repeats across runs);
// the deterministic columns do not depend on the order, the timed ones are summarised the same
// way (combineRepeats). A result file is written whole or not at all (write, then rename).
#include "sweep_job.h"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "exit_codes.h"
#include "output_files.h"
#include "sweep_measure.h"
#include "sweep_report.h"

namespace app::sweep {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr const char* kResultFormat = "cdlab-sweep-result 1";

// JSON has no infinities or NaN: those are written as strings.
json number(double v) {
    if (std::isfinite(v)) return v;
    if (std::isnan(v)) return "nan";
    return v > 0 ? "inf" : "-inf";
}

double numberFrom(const json& j) {
    if (j.is_number()) return j.get<double>();
    const std::string s = j.get<std::string>();
    if (s == "nan") return std::numeric_limits<double>::quiet_NaN();
    if (s == "inf") return std::numeric_limits<double>::infinity();
    if (s == "-inf") return -std::numeric_limits<double>::infinity();
    std::string message = "'";
    message += s;
    message += "' is not a number";
    throw std::runtime_error(message);
}

using TimedField = Timed SweepRun::*;
using CountField = std::int64_t SweepRun::*;

const std::pair<const char*, TimedField> kTimed[] = {
    {"ms_integrate", &SweepRun::ms_integrate},
    {"ms_volumes", &SweepRun::ms_volumes},
    {"ms_broad", &SweepRun::ms_broad},
    {"ms_narrow", &SweepRun::ms_narrow},
    {"ms_ccd", &SweepRun::ms_ccd},
    {"ms_response", &SweepRun::ms_response},
    {"ms_step", &SweepRun::ms_step},
    {"ms_per_simulated_s", &SweepRun::ms_per_simulated_s},
    {"cpu_ms_step", &SweepRun::cpu_ms_step},
    {"cpu_ms_per_simulated_s", &SweepRun::cpu_ms_per_simulated_s},
};
const std::pair<const char*, CountField> kCounts[] = {
    {"steps", &SweepRun::steps},
    {"toi_events", &SweepRun::toi_events},
    {"pairs_confirmed_total", &SweepRun::pairs_confirmed_total},
};

json runJson(const SweepRun& r) {
    json j;
    for (const DoubleColumn& c : doubleColumns()) j[c.name] = number(r.*c.field);
    for (const auto& [name, field] : kTimed) {
        const Timed& t = r.*field;
        j[name] = {{"median", number(t.median)}, {"min", number(t.min)}, {"max", number(t.max)}};
    }
    for (const auto& [name, field] : kCounts) j[name] = r.*field;
    j["repeats"] = r.repeats;
    j["state_hash"] = r.state_hash;
    j["host"] = r.host;
    return j;
}

SweepRun runFrom(const json& j) {
    SweepRun r;
    for (const DoubleColumn& c : doubleColumns()) r.*c.field = numberFrom(j.at(c.name));
    for (const auto& [name, field] : kTimed) {
        const json& t = j.at(name);
        r.*field = {numberFrom(t.at("median")), numberFrom(t.at("min")), numberFrom(t.at("max"))};
    }
    for (const auto& [name, field] : kCounts) r.*field = j.at(name).get<std::int64_t>();
    r.repeats = j.at("repeats").get<int>();
    r.state_hash = j.at("state_hash").get<std::uint64_t>();
    r.host = j.at("host").get<std::string>();
    return r;
}

double epochSeconds() {
    return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch())
        .count();
}

// Measures the run `plan.repeat` times; the first repeat measures everything, the others must
// reproduce its deterministic columns. Returns the failure, empty on success.
std::string measureRepeats(const SweepPlan& plan, const engine::Scene& scene, JobResult& result) {
    std::vector<SweepRun> repeats{measure(scene, plan.duration, &result.contacts)};
    for (int pass = 1; pass < plan.repeat; ++pass) {
        repeats.push_back(measure(scene, plan.duration, nullptr));
        const std::string difference = deterministicDifference(repeats.front(), repeats.back());
        if (!difference.empty()) {
            return "repeat " + std::to_string(pass + 1) + " of " + std::to_string(plan.repeat) +
                   " differs from repeat 1 in " + difference +
                   ": the simulation is not deterministic";
        }
    }
    result.measured = combineRepeats(repeats);
    return "";
}

}  // namespace

std::string resultJson(const SweepPlan& plan, const JobResult& result) {
    json j = {{"format", kResultFormat},
              {"plan_id", plan.id},
              {"run", result.run},
              {"label", plan.runs.at(result.run).label},
              {"started", number(result.started)},
              {"finished", number(result.finished)},
              {"pid", result.pid}};
    if (!result.failure.empty()) {
        j["failure"] = result.failure;
        return j.dump(1) + "\n";
    }
    j["measured"] = runJson(result.measured);
    json contacts = json::array();
    for (const auto& [pair, t] : result.contacts) {
        contacts.push_back({pair.first, pair.second, number(t)});
    }
    j["first_contacts"] = contacts;
    return j.dump(1) + "\n";
}

JobResult parseResult(const std::string& text, const SweepPlan& plan, std::size_t k) {
    JobResult result;
    try {
        const json j = json::parse(text);
        if (!j.is_object() || j.value("format", "") != kResultFormat) {
            throw std::runtime_error(std::string("not a cdlab sweep result (format '") +
                                     kResultFormat + "')");
        }
        const std::string id = j.at("plan_id").get<std::string>();
        if (id != plan.id) {
            throw std::runtime_error("written for plan " + id + ", not this plan (" + plan.id +
                                     "): a result of another sweep");
        }
        result.run = j.at("run").get<std::size_t>();
        if (result.run != k) {
            throw std::runtime_error("the result of job " + std::to_string(result.run) +
                                     ", not of job " + std::to_string(k));
        }
        result.started = numberFrom(j.at("started"));
        result.finished = numberFrom(j.at("finished"));
        result.pid = j.at("pid").get<long>();
        if (j.contains("failure")) {
            result.failure = j.at("failure").get<std::string>();
            if (result.failure.empty()) result.failure = "failed (no reason given)";
            return result;
        }
        result.measured = runFrom(j.at("measured"));
        for (const json& c : j.at("first_contacts")) {
            result
                .contacts[{c.at(0).get<collision::ProxyId>(), c.at(1).get<collision::ProxyId>()}] =
                numberFrom(c.at(2));
        }
    } catch (const json::exception& e) {
        throw std::runtime_error(std::string("malformed result: ") + e.what());
    }
    return result;
}

int runSweepJob(const fs::path& plan_path, long k, std::ostream& out, std::ostream& err) {
    const std::optional<SweepPlan> plan = readPlan(plan_path, err);
    if (!plan) return kExitBadInput;
    if (k < 0 || static_cast<std::size_t>(k) >= plan->runs.size()) {
        err << "--run " << k << ": the plan " << (plan->dir / "plan.json").string()
            << " has jobs 0 to " << plan->runs.size() - 1 << "\n";
        return kExitBadInput;
    }
    const std::size_t run = static_cast<std::size_t>(k);
    const PlannedRun& planned = plan->runs[run];
    JobResult result;
    result.run = run;
    result.pid = long(::getpid());
    result.started = epochSeconds();
    int code = kExitOk;
    const std::string hash = fnv1aHex(fileBytes(plan->scene));
    if (hash != plan->scene_hash) {
        result.failure = plan->scene.string() + " is not the scene planned (FNV-1a " + hash +
                         ", planned " + plan->scene_hash +
                         "): every host must see the same scene file";
        code = kExitBadInput;
    } else {
        try {
            const engine::Scene scene = engine::loadScene(plan->scene, planned.overrides);
            result.failure = measureRepeats(*plan, scene, result);
            if (!result.failure.empty()) code = kExitFailure;
        } catch (const engine::SceneError& e) {
            result.failure = e.what();
            code = kExitBadInput;
        }
    }
    result.finished = epochSeconds();
    const std::string what = run == 0 ? "reference" : "run '" + planned.label + "'";
    if (!writeTextReporting(resultPath(*plan, run), resultJson(*plan, result), err)) {
        return kExitFailure;
    }
    if (!result.failure.empty()) {
        err << "sweep job " << run << " (" << what << "): " << result.failure << "\n";
        return code;
    }
    out << "sweep job " << run << " (" << what << "): " << result.measured.steps << " steps, "
        << fmt(result.measured.ms_step.median, "%.3f") << " ms/step wall, "
        << fmt(result.measured.cpu_ms_step.median, "%.3f") << " CPU, wrote "
        << resultPath(*plan, run).string() << "\n";
    return kExitOk;
}

}  // namespace app::sweep
