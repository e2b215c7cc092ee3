// app/lab/sweep_measure.h -- one run of `cdlab sweep`: the scene simulated for the sweep's
// interval, its stage times, counters, accuracy measures and memory, and its comparison with the
// reference run pair by pair through first-contact times.
#pragma once

#include <map>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "collision/broadphase/broad_phase.h"
#include "engine/scene.h"
#include "sweep.h"

namespace app::sweep {

using PairKey = std::pair<collision::ProxyId, collision::ProxyId>;
/// Every pair a run saw in contact, with the simulated time it first did.
using FirstContacts = std::map<PairKey, double>;

/// "key=value key=value", or "scene as written" without overrides.
std::string labelOf(const std::vector<engine::SceneOverride>& overrides);

/// Runs `scene` for `duration` simulated seconds and measures it: stage times (one sample:
/// median = min = max), per-step counters and the final state hash. With `first`, also the
/// accuracy measures and memory, and every pair's first contact in `first` (confirmed at a
/// step's end, stopped by CCD, or pushed by the solver); without, the world is only stepped (a
/// timing repeat: the untimed bookkeeping is skipped).
SweepRun measure(const engine::Scene& scene, double duration, FirstContacts* first);

/// A double-valued column of SweepRun, by its name in results and job files. `per_step`: one of
/// the per-step pair and test counters, which deterministicDifference compares between repeats.
struct DoubleColumn {
    const char* name;
    double SweepRun::*field;
    bool per_step;
};
/// Every double-valued column of SweepRun (the timed and integer ones are separate fields).
std::span<const DoubleColumn> doubleColumns();

/// The first deterministic column in which `repeat` (a timing repeat of `first`) differs:
/// "column: value in first vs value in repeat"; empty when they agree. Compared: steps, the
/// per-step pair and test counters, CCD stops and the final state hash (which covers the
/// trajectory the accuracy columns are computed from).
std::string deterministicDifference(const SweepRun& first, const SweepRun& repeat);

/// Median (mean of the middle two for an even count) and min..max of `samples` (non-empty).
Timed summarize(std::vector<double> samples);

/// `repeats[0]` (the measuring repeat) with every timed column summarised over all repeats.
/// Precondition: non-empty, every repeat of the same run.
SweepRun combineRepeats(const std::vector<SweepRun>& repeats);

/// Whether time step `dt` is coarser than, equal to (relative 1e-9: a value typed in the
/// scene matches the computed dt / refine) or finer than the reference's `reference_dt`.
StepVsReference stepVsReference(double dt, double reference_dt);

/// Missed and extra pairs and first-contact errors of `run` against the reference's contacts.
void compareWithReference(SweepRun& run, const FirstContacts& mine, const FirstContacts& ref);

}  // namespace app::sweep
