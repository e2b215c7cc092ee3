// app/lab/sweep.h -- `cdlab sweep`: one scene under every combination of the choices asked
// for, measured for cost (time per stage, bounding-volume and pair tests) and for the accuracy
// that cost buys (broad-phase false positives, missed and late contacts against a fine reference
// run, energy drift). Writes results.csv, report.md and bar charts.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "engine/scene.h"

namespace app {

struct SweepOptions {
    std::filesystem::path scene;
    /// "KEY=V1,V2,...": KEY a dotted scene path (`broadphase`, `world.time_step`), values YAML
    /// scalars or flow sequences ([1, 2, 3] stays one value). Runs the Cartesian product, the
    /// last --vary changing fastest.
    std::vector<std::string> vary;
    /// "KEY=V" overrides for the reference run, applied after its refined time step.
    std::vector<std::string> reference;
    /// The reference run takes the scene's time step divided by this (>= 1).
    double reference_refine = 10;
    /// Simulated time per run (s); default the scene's (frames - 1) * steps_per_frame * dt, so
    /// runs with different time steps cover the same interval.
    std::optional<double> duration;
    std::filesystem::path out_dir;  ///< default out/sweep_<scene stem>
    /// A cdlab executable built with CDLAB_USE_FLOAT=ON: every combination is also run by it
    /// (`cdlab run --set ... --trace`) and its frames compared with the double build's.
    std::optional<std::filesystem::path> float_binary;
    /// Keep DIR/traces/ (every frame of both builds, JSON lines); removed after comparing
    /// otherwise, since it is large (about 1 MB per run of a few hundred frames).
    bool keep_traces = false;
    /// Timings in report.md (off: the report is bit-identical from run to run; the CSV keeps
    /// them).
    bool report_timing = true;
    /// Every run (the reference included) is timed this many times (>= 1; 0 or less is bad
    /// input); tables give the median and the min..max range. The first repeat also measures
    /// accuracy; the others only step the world, and must end in the same state with the same
    /// counters.
    int repeat = 3;
    /// Runs at a time: 1 runs every run in this process; N > 1 plans the sweep into
    /// OUT/plan (sweep_plan.h), runs its jobs N at a time as child processes of `cdlab_binary`
    /// and collects them (sweep_collect.h). Not with float_binary.
    int jobs = 1;
    /// The cdlab executable the jobs run with jobs > 1 (the command sets its own, /proc/self/exe).
    std::filesystem::path cdlab_binary;
    /// The runs were timed while sharing the machine with each other (jobs run concurrently, or
    /// on different hosts): their wall-clock times are disturbed, so the reading ranks runs by
    /// thread CPU time instead. Set by the collect step from the jobs' own records.
    bool timed_concurrently = false;
    /// The runs were the jobs of a plan, each timed in a process of its own (set by collect).
    bool planned = false;
    /// Check the options and load every run's scene (runSweep, planSweep), then return 0 before
    /// anything is run or written (`cdlab --dry-run sweep ...`).
    bool dry_run = false;
};

/// A run of a planned sweep that left no usable result: named on stderr and in report.md,
/// never silently left out.
struct SweepFailure {
    std::string label;   ///< the run, as SweepRun::label ("reference" for the reference run)
    std::string reason;  ///< why: no result file, or the job's own error
};

/// A wall-clock figure over the repeats of one run (ms): median and range.
struct Timed {
    double median = 0;
    double min = 0;
    double max = 0;
};

/// Where a run's time step sits against the reference's (relative tolerance 1e-9).
enum class StepVsReference { Coarser, Same, Finer };

/// What one run measured. Times are wall-clock (std::chrono::steady_clock, inside World::step)
/// means per step (ms), summarised over the repeats, except the cpu_ ones; counts are means per step unless named
/// total.
struct SweepRun {
    std::string label;  ///< "broadphase=hgrid world.time_step=0.01", or "reference"
    std::vector<engine::SceneOverride> overrides;
    double time_step = 0;
    std::int64_t steps = 0;
    int repeats = 1;  ///< times the run was timed
    Timed ms_integrate, ms_volumes, ms_broad, ms_narrow, ms_ccd, ms_response, ms_step;
    Timed ms_per_simulated_s;
    /// Thread CPU time (CLOCK_THREAD_CPUTIME_ID) around World::step, ms per step and per
    /// simulated second: what the run cost this thread, nearly undisturbed by other processes
    /// sharing the cores (unlike the wall-clock columns above).
    Timed cpu_ms_step, cpu_ms_per_simulated_s;
    std::string host;         ///< the machine the run was timed on
    bool concurrent = false;  ///< timed while another run of the sweep ran on the same host
    StepVsReference step_vs_reference = StepVsReference::Coarser;
    double flagged = 0;                ///< broad-phase pairs per step
    double confirmed = 0;              ///< narrow-phase confirmed pairs per step
    double broad_false_positives = 0;  ///< flagged - confirmed, per step
    double bv_tests = 0;               ///< broad-phase bounding-volume tests per step (Nv)
    double narrow_tests = 0;           ///< narrow-phase pair tests per step
    double triangle_tests = 0;         ///< triangle tests per step (Np)
    double mesh_bv_tests = 0;          ///< mesh-hierarchy node tests per step
    std::int64_t toi_events = 0;       ///< pairs the CCD stage stopped, whole run
    double max_penetration = 0;  ///< m, deepest overlap of a confirmed convex pair at a step end
    std::int64_t pairs_confirmed_total = 0;  ///< distinct pairs ever confirmed (or CCD-stopped)
    std::int64_t missed_pairs = 0;           ///< confirmed in the reference, never in this run
    std::int64_t extra_pairs = 0;            ///< confirmed in this run, never in the reference
    /// s, |first contact - reference's|, common pairs. A pair's first contact is the end of the
    /// first step that confirms it, or the time of impact when the CCD stage stopped it first.
    double max_first_contact_error = 0;
    double mean_first_contact_error = 0;  ///< s
    double max_energy_drift = 0;  ///< max over steps |E - E0| / (sum of |energy terms| at 0)
    double max_angular_momentum_drift = 0;  ///< max over bodies and steps | |L| - |L0| | / |L0|
    /// MiB: the process's peak resident set during the run (Linux VmHWM, reset at the run's
    /// start) less its resident set at the start: what building and stepping this world took.
    /// Process-wide, so allocator reuse between runs makes it a lower bound; 0 where /proc is
    /// not available. Measured in the first repeat only.
    double memory_mib = 0;
    std::uint64_t state_hash = 0;
};

/// How two traces of the same scene (`cdlab run --trace`) differ, frame by frame.
struct TraceComparison {
    int frames = 0;                        ///< frames present in both
    int first_pair_difference = -1;        ///< first frame whose confirmed pairs differ; -1: none
    int pair_frames_differing = 0;         ///< frames whose confirmed pair sets differ
    double max_position_deviation = 0;     ///< m, over bodies and frames
    double final_position_deviation = 0;   ///< m, last common frame
    double max_orientation_deviation = 0;  ///< rad
    std::string error;                     ///< non-empty: the traces could not be compared
};

/// One combination's float-against-double comparison (sweep --float-binary).
struct FloatRun {
    TraceComparison comparison;
    std::string label;  ///< the combination, as in SweepRun::label
};

/// The float-against-double lines of report.md's reading (Markdown list items): which runs
/// confirm different pairs from which frame, and always the largest position deviation (also
/// relative to `scene_size`, m, the bounds diagonal) and the largest orientation deviation,
/// each with the run it occurs in. Runs whose comparison has an error are left out.
std::string floatReading(const std::vector<FloatRun>& floats, double scene_size);

/// Reads two trace files and compares them; `error` says why when they cannot be compared
/// (unreadable, malformed, different body counts).
TraceComparison compareTraces(const std::filesystem::path& a, const std::filesystem::path& b);

/// Parses "KEY=V1,V2" (commas inside [] or {} do not split). Returns false with a message.
bool parseVary(const std::string& text, std::string& key, std::vector<std::string>& values,
               std::string& error);

/// Runs the sweep in this process, or with options.jobs > 1 as a plan whose jobs run that many
/// at a time (sweep_local.h). Exit codes: 0 success, 1 output failure, a repeat that differs
/// from the first in a deterministic column (pairs, tests, CCD stops, final state) or a job
/// that left no result, 2 bad input (flags, a combination's scene error).
int runSweep(const SweepOptions& options, std::ostream& out, std::ostream& err);

}  // namespace app
