// app/lab/sweep_measure.cpp -- see sweep_measure.h.
#include "sweep_measure.h"

#include <malloc.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "exit_codes.h"
#include "output_files.h"
#include "render/chart.h"
#include "render/image.h"
#include "run_scene.h"
#include "sweep_report.h"

namespace app::sweep {

namespace {

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

// This thread's CPU time (s): POSIX CLOCK_THREAD_CPUTIME_ID. The engine steps on the calling
// thread, so this is the step's cost, whatever else shares the cores.
double threadCpuSeconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// This machine's name (gethostname), "" when it has none.
std::string hostName() {
    char name[256] = {};
    if (gethostname(name, sizeof name - 1) != 0) return "";
    return name;
}

}  // namespace

std::string labelOf(const std::vector<engine::SceneOverride>& overrides) {
    std::string label;
    for (const engine::SceneOverride& o : overrides) {
        if (!label.empty()) label += ' ';
        label += o.key + "=" + o.value;
    }
    return label.empty() ? "scene as written" : label;
}

SweepRun measure(const engine::Scene& scene, double duration, FirstContacts* first) {
    SweepRun run;
    const bool peak_reset = resetPeakResident();
    const double resident_kb = procStatusKb("VmRSS");
    engine::World world = engine::makeWorld(scene);
    run.time_step = scene.world.time_step;
    run.host = hostName();
    run.steps = std::max<std::int64_t>(1, std::llround(duration / run.time_step));

    // Contacts the run saw: pairs confirmed at the end of a step, pairs the CCD stage stopped at
    // their time of impact within it (they never overlap at a step's end), and pairs the contact
    // solver pushed apart at its start.
    auto record = [first, &world, &run](double step_start) {
        const double dt = double(world.settings().time_step);
        for (const engine::ToiEvent& e : world.toiEvents()) {
            first->try_emplace(PairKey{std::min(e.a, e.b), std::max(e.a, e.b)},
                               step_start + double(e.t) * dt);
        }
        // The contact solver acts at the step's start, on pairs touching or about to touch
        // within the step (speculative contacts): a push counts as a contact then.
        for (const collision::ProxyPair& p : world.pushedPairs()) {
            first->try_emplace(PairKey{p.a, p.b}, step_start);
        }
        for (const collision::ProxyPair& p : world.collidingPairs()) {
            first->try_emplace(PairKey{p.a, p.b}, double(world.time()));
        }
        // Depth of convex pairs (a mesh would answer as its hull, an overestimate).
        run.max_penetration = std::max(run.max_penetration, double(world.deepestPenetration()));
    };
    double energy_scale = 0;
    double e0 = 0;
    std::vector<double> l0;
    if (first != nullptr) {
        record(double(world.time()));
        e0 = totalEnergy(world, energy_scale);
        for (const engine::Body& b : world.bodies()) l0.push_back(b.angular_momentum.norm());
    }

    // Stage times as the engine measures them inside World::step (steady_clock), so the
    // bookkeeping below is outside every timed interval.
    double ms_integrate = 0, ms_volumes = 0, ms_broad = 0, ms_narrow = 0, ms_ccd = 0,
           ms_response = 0, ms_step = 0;
    double cpu_s = 0;
    for (std::int64_t s = 0; s < run.steps; ++s) {
        const double step_start = double(world.time());
        const double cpu_before = threadCpuSeconds();
        world.step();
        cpu_s += threadCpuSeconds() - cpu_before;
        const engine::StepStats& st = world.lastStats();
        ms_integrate += 1e3 * st.integrate_s;
        ms_volumes += 1e3 * st.volumes_s;
        ms_broad += 1e3 * st.broad_phase_s;
        ms_narrow += 1e3 * st.narrow_phase_s;
        ms_ccd += 1e3 * st.ccd_s;
        ms_response += 1e3 * st.response_s;
        ms_step += 1e3 * st.total_s;
        run.toi_events += st.toi_events;
        run.flagged += double(world.flaggedPairs().size());
        run.confirmed += double(world.collidingPairs().size());
        run.bv_tests += double(st.broad.volume_tests);
        run.narrow_tests += double(st.narrow_tests);
        run.triangle_tests += double(st.triangle_tests);
        run.mesh_bv_tests += double(st.bv_tests);
        if (first == nullptr) continue;
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
    for (double* v : {&ms_integrate, &ms_volumes, &ms_broad, &ms_narrow, &ms_ccd, &ms_response,
                      &ms_step, &run.flagged, &run.confirmed, &run.bv_tests, &run.narrow_tests,
                      &run.triangle_tests, &run.mesh_bv_tests}) {
        *v /= n;
    }
    auto sample = [](double v) { return Timed{v, v, v}; };
    run.ms_integrate = sample(ms_integrate);
    run.ms_volumes = sample(ms_volumes);
    run.ms_broad = sample(ms_broad);
    run.ms_narrow = sample(ms_narrow);
    run.ms_ccd = sample(ms_ccd);
    run.ms_response = sample(ms_response);
    run.ms_step = sample(ms_step);
    run.ms_per_simulated_s = sample(ms_step / run.time_step);
    run.cpu_ms_step = sample(1e3 * cpu_s / n);
    run.cpu_ms_per_simulated_s = sample(1e3 * cpu_s / n / run.time_step);
    run.broad_false_positives = run.flagged - run.confirmed;
    run.state_hash = world.stateHash();
    if (first == nullptr) return run;
    run.pairs_confirmed_total = static_cast<std::int64_t>(first->size());
    const double peak_kb = procStatusKb("VmHWM");
    if (peak_reset && resident_kb >= 0 && peak_kb >= 0) {
        run.memory_mib = std::max(0.0, peak_kb - resident_kb) / 1024;
    }
    return run;
}

std::span<const DoubleColumn> doubleColumns() {
    static constexpr DoubleColumn kColumns[] = {
        {"time_step", &SweepRun::time_step, false},
        {"flagged", &SweepRun::flagged, true},
        {"confirmed", &SweepRun::confirmed, true},
        {"broad_false_positives", &SweepRun::broad_false_positives, true},
        {"bv_tests", &SweepRun::bv_tests, true},
        {"narrow_tests", &SweepRun::narrow_tests, true},
        {"triangle_tests", &SweepRun::triangle_tests, true},
        {"mesh_bv_tests", &SweepRun::mesh_bv_tests, true},
        {"max_penetration", &SweepRun::max_penetration, false},
        {"max_energy_drift", &SweepRun::max_energy_drift, false},
        {"max_angular_momentum_drift", &SweepRun::max_angular_momentum_drift, false},
        {"memory_mib", &SweepRun::memory_mib, false},
    };
    return kColumns;
}

std::string deterministicDifference(const SweepRun& first, const SweepRun& repeat) {
    // Exact comparison: the same scene and build must give bit-identical counts and states.
    std::string d;
    if (first.steps != repeat.steps) {
        d = "steps: " + std::to_string(first.steps) + " vs " + std::to_string(repeat.steps);
    }
    for (const DoubleColumn& c : doubleColumns()) {
        if (!d.empty()) break;
        if (c.per_step && first.*c.field != repeat.*c.field) {
            d = c.name;
            d += ": " + fmt(first.*c.field, "%.17g") + " vs " + fmt(repeat.*c.field, "%.17g");
        }
    }
    if (d.empty() && first.toi_events != repeat.toi_events) {
        d = "toi_events: " + std::to_string(first.toi_events) + " vs " +
            std::to_string(repeat.toi_events);
    }
    if (d.empty() && first.state_hash != repeat.state_hash) {
        d = "state_hash: " + std::to_string(first.state_hash) + " vs " +
            std::to_string(repeat.state_hash);
    }
    return d;
}

Timed summarize(std::vector<double> samples) {
    std::sort(samples.begin(), samples.end());
    const std::size_t n = samples.size();
    const double median = n % 2 == 1 ? samples[n / 2] : 0.5 * (samples[n / 2 - 1] + samples[n / 2]);
    return {median, samples.front(), samples.back()};
}

SweepRun combineRepeats(const std::vector<SweepRun>& repeats) {
    SweepRun run = repeats.front();
    run.repeats = int(repeats.size());
    for (Timed SweepRun::*field :
         {&SweepRun::ms_integrate, &SweepRun::ms_volumes, &SweepRun::ms_broad, &SweepRun::ms_narrow,
          &SweepRun::ms_ccd, &SweepRun::ms_response, &SweepRun::ms_step,
          &SweepRun::ms_per_simulated_s, &SweepRun::cpu_ms_step,
          &SweepRun::cpu_ms_per_simulated_s}) {
        std::vector<double> samples;
        for (const SweepRun& r : repeats) samples.push_back((r.*field).median);
        run.*field = summarize(samples);
    }
    return run;
}

StepVsReference stepVsReference(double dt, double reference_dt) {
    if (std::abs(dt - reference_dt) <= 1e-9 * std::max(std::abs(dt), std::abs(reference_dt))) {
        return StepVsReference::Same;
    }
    return dt < reference_dt ? StepVsReference::Finer : StepVsReference::Coarser;
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

}  // namespace app::sweep
