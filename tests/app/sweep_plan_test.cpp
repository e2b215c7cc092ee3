// cdlab sweep as independent jobs: --plan DIR writes one command per run, each job writes its
// own result, --collect DIR merges them into the one-process sweep's outputs. The deterministic
// columns must come out bit-identical whichever engine ran the jobs (one after another, -j,
// GNU Parallel, the Slurm array script), and a missing, failed or foreign result must be named.
#include "sweep_plan.h"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli_run.h"
#include "engine/scene.h"
#include "sweep.h"
#include "sweep_job.h"
#include "sweep_report.h"

namespace {

namespace fs = std::filesystem;
using cdlab_test::runCdlab;
using cdlab_test::slurp;

fs::path planDir(const std::string& name) { return cdlab_test::tempDir("cdlab_plan_", name); }

// 2 broad phases x 2 time steps (one tunnels, one catches the plate) and the reference.
const std::string kVary =
    " --vary broadphase=sap,hgrid --vary world.time_step=0.05,0.005 "
    "--repeat 2";

// One CSV line split into fields (RFC 4180 quotes).
std::vector<std::string> csvFields(const std::string& line) {
    std::vector<std::string> cells(1);
    bool quoted = false;
    for (std::size_t i = 0; i < line.size(); ++i) {
        const char c = line[i];
        if (quoted && c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
            cells.back() += c;
            ++i;
        } else if (c == '"') {
            quoted = !quoted;
        } else if (c == ',' && !quoted) {
            cells.emplace_back();
        } else {
            cells.back() += c;
        }
    }
    return cells;
}

// Timed (wall or CPU), per-process (memory) or per-machine (host, concurrent) columns: the rest
// of results.csv is deterministic.
bool isTimedColumn(const std::string& name) {
    return name.rfind("ms_", 0) == 0 || name.rfind("cpu_ms_", 0) == 0 || name == "memory_mib" ||
           name == "host" || name == "concurrent";
}

// results.csv with the timed columns left out, text as written.
std::string deterministicColumns(const fs::path& csv) {
    std::istringstream lines(slurp(csv));
    std::string line, text;
    std::vector<bool> keep;
    while (std::getline(lines, line)) {
        const std::vector<std::string> cells = csvFields(line);
        if (keep.empty()) {
            for (const std::string& c : cells) keep.push_back(!isTimedColumn(c));
        }
        for (std::size_t i = 0; i < cells.size(); ++i) {
            if (i < keep.size() && keep[i]) text += cells[i] + "|";
        }
        text += "\n";
    }
    return text;
}

// The scene copied into `dir`, so a test may change it after planning.
fs::path sceneCopy(const fs::path& dir) {
    const fs::path scene = dir / "tunnel_small.yaml";
    fs::copy_file(fs::path(CDLAB_SOURCE_DIR) / "tests/data/tunnel_small.yaml", scene,
                  fs::copy_options::overwrite_existing);
    return scene;
}

// The one-process sweep of `scene` into DIR/one, without report timings.
fs::path oneProcessSweep(const fs::path& scene, const fs::path& work) {
    const fs::path out = work / "one";
    const auto r = runCdlab(
        "sweep " + scene.string() + kVary + " --no-report-timing --out " + out.string(), work);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return out;
}

// Plans the sweep into DIR/plan; returns the plan directory.
fs::path plan(const fs::path& scene, const fs::path& work, const std::string& extra = "") {
    const fs::path dir = work / "plan";
    const auto r =
        runCdlab("sweep " + scene.string() + kVary + " --plan " + dir.string() + extra, work);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("jobs.txt"), std::string::npos) << r.out;
    return dir;
}

std::vector<std::string> jobLines(const fs::path& dir) {
    std::istringstream lines(slurp(dir / "jobs.txt"));
    std::vector<std::string> jobs;
    for (std::string line; std::getline(lines, line);) jobs.push_back(line);
    return jobs;
}

int shell(const std::string& cmd) {
    const int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Collects DIR and checks the deterministic columns and the untimed report against the
// one-process sweep's.
void expectSameAsOneProcess(const fs::path& dir, const fs::path& one, const fs::path& work) {
    const auto r = runCdlab("sweep --collect " + dir.string() + " --no-report-timing", work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string collected = deterministicColumns(dir / "results.csv");
    EXPECT_EQ(std::count(collected.begin(), collected.end(), '\n'), 5) << collected;
    EXPECT_EQ(collected, deterministicColumns(one / "results.csv"));
    EXPECT_EQ(slurp(dir / "report.md"), slurp(one / "report.md"));
    EXPECT_TRUE(fs::exists(dir / "bv_tests.png"));
}

TEST(SweepPlan, JobsRunOneByOneCollectToTheOneProcessSweep) {
    const fs::path work = planDir("serial");
    const fs::path scene = sceneCopy(work);
    const fs::path one = oneProcessSweep(scene, work);
    const fs::path dir = plan(scene, work);
    const std::vector<std::string> jobs = jobLines(dir);
    ASSERT_EQ(jobs.size(), 5u);  // the reference and 4 combinations
    // Run from another directory: the plan pins absolute paths.
    for (const std::string& job : jobs) {
        ASSERT_EQ(shell("cd / && " + job + " > /dev/null 2>&1"), 0) << job;
    }
    expectSameAsOneProcess(dir, one, work);
    // Jobs one after another never overlap: the reading ranks by wall-clock time.
    EXPECT_NE(slurp(dir / "results.csv").find(",0\n"), std::string::npos);
    fs::remove_all(work);
}

TEST(SweepPlan, GnuParallelRunsTheJobs) {
    if (shell("parallel --version > /dev/null 2>&1") != 0) {
        GTEST_SKIP() << "GNU Parallel not installed (Debian package parallel)";
    }
    const fs::path work = planDir("parallel");
    const fs::path scene = sceneCopy(work);
    const fs::path one = oneProcessSweep(scene, work);
    const fs::path dir = plan(scene, work);
    ASSERT_EQ(
        shell("parallel --will-cite --jobs 2 --halt never :::: " + (dir / "jobs.txt").string() +
              " > " + (work / "parallel.log").string() + " 2>&1"),
        0)
        << slurp(work / "parallel.log");
    expectSameAsOneProcess(dir, one, work);
    // The across-hosts command of docs/distributed-sweeps.md, with this machine as its only host
    // (":" in the login file: no ssh), two job slots.
    fs::remove_all(dir / "results");
    fs::create_directories(dir / "results");
    std::ofstream(work / "hosts.txt") << "2/:\n";
    ASSERT_EQ(shell("cd " + work.string() + " && parallel --will-cite --sshloginfile hosts.txt " +
                    "--workdir . :::: " + (dir / "jobs.txt").string() + " > parallel.log 2>&1"),
              0)
        << slurp(work / "parallel.log");
    expectSameAsOneProcess(dir, one, work);
    fs::remove_all(work);
}

TEST(SweepPlan, LocalJobsGiveTheOneProcessColumns) {
    const fs::path work = planDir("local");
    const fs::path scene = sceneCopy(work);
    const fs::path one = oneProcessSweep(scene, work);
    const fs::path out = work / "j2";
    const auto r = runCdlab(
        "sweep " + scene.string() + kVary + " -j 2 --no-report-timing --out " + out.string(), work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(deterministicColumns(out / "results.csv"), deterministicColumns(one / "results.csv"));
    EXPECT_EQ(slurp(out / "report.md"), slurp(one / "report.md"));
    // With timings, the report names the clocks; every run recorded its CPU time.
    const auto timed =
        runCdlab("sweep " + scene.string() + kVary + " -j 2 --out " + out.string(), work);
    ASSERT_EQ(timed.exit_code, 0) << timed.err;
    const std::string report = slurp(out / "report.md");
    EXPECT_NE(report.find("CLOCK_THREAD_CPUTIME_ID"), std::string::npos);
    EXPECT_NE(report.find("each run a job in a process of its own"), std::string::npos);
    EXPECT_NE(slurp(out / "results.csv").find(",thread_cputime,"), std::string::npos);
    // The reading ranks by CPU time exactly when two jobs' timed intervals overlapped.
    std::vector<std::pair<double, double>> spans;
    for (int k = 0; k < 5; ++k) {
        const nlohmann::json j =
            nlohmann::json::parse(slurp(out / "plan/results" / (std::to_string(k) + ".json")));
        spans.emplace_back(j.at("started").get<double>(), j.at("finished").get<double>());
    }
    bool overlapped = false;
    for (const auto& a : spans) {
        for (const auto& b : spans) {
            overlapped = overlapped || (&a != &b && a.first < b.second && b.first < a.second);
        }
    }
    EXPECT_EQ(report.find("the reading ranks them by CPU time") != std::string::npos, overlapped);
    fs::remove_all(work);
}

// runSweep called as a library with -j must be told which cdlab to run: its own executable is
// not one (here it is this test binary, which would run every test again for each job).
TEST(SweepPlan, ParallelRunsFromTheLibraryNeedTheCdlabBinary) {
    const fs::path work = planDir("library");
    app::SweepOptions o;
    o.scene = fs::path(CDLAB_SOURCE_DIR) / "tests/data/tunnel_small.yaml";
    o.vary = {"broadphase=sap,hgrid"};
    o.repeat = 1;
    o.jobs = 2;
    o.out_dir = work / "out";
    std::ostringstream out, err;
    EXPECT_EQ(app::runSweep(o, out, err), 2);
    EXPECT_NE(err.str().find("no cdlab executable to run the jobs"), std::string::npos)
        << err.str();
    o.cdlab_binary = CDLAB_BINARY;
    err.str("");
    EXPECT_EQ(app::runSweep(o, out, err), 0) << err.str();
    const std::string csv = slurp(o.out_dir / "results.csv");
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3) << csv;  // header and two runs
    fs::remove_all(work);
}

// The Slurm array script, run by bash with the task id Slurm would give each task.
TEST(SweepPlan, SlurmArrayScriptMapsEachTaskToItsJob) {
    const fs::path work = planDir("slurm");
    const fs::path scene = sceneCopy(work);
    const fs::path one = oneProcessSweep(scene, work);
    const fs::path dir = plan(scene, work, " --slurm");
    const std::string script = slurp(dir / "sweep.sbatch");
    EXPECT_NE(script.find("#SBATCH --array=0-4\n"), std::string::npos) << script;
    EXPECT_NE(script.find("sweep --collect"), std::string::npos) << script;
    // Task 2 runs job 2 and only job 2.
    ASSERT_EQ(shell("SLURM_ARRAY_TASK_ID=2 bash " + (dir / "sweep.sbatch").string() +
                    " > /dev/null 2>&1"),
              0);
    EXPECT_TRUE(fs::exists(dir / "results/2.json"));
    EXPECT_FALSE(fs::exists(dir / "results/1.json"));
    for (int k : {0, 1, 3, 4}) {
        ASSERT_EQ(shell("SLURM_ARRAY_TASK_ID=" + std::to_string(k) + " bash " +
                        (dir / "sweep.sbatch").string() + " > /dev/null 2>&1"),
                  0)
            << k;
    }
    // A task beyond the array has no line.
    EXPECT_EQ(shell("SLURM_ARRAY_TASK_ID=5 bash " + (dir / "sweep.sbatch").string() +
                    " > /dev/null 2>&1"),
              2);
    expectSameAsOneProcess(dir, one, work);
    fs::remove_all(work);
}

// A job that never ran, and one that failed (its scene changed after planning): both are named
// on stderr and in report.md, the other runs are still written, and collect exits 1.
TEST(SweepPlan, MissingAndFailedJobsAreNamed) {
    const fs::path work = planDir("missing");
    const fs::path scene = sceneCopy(work);
    const fs::path dir = plan(scene, work);
    const std::vector<std::string> jobs = jobLines(dir);
    for (std::size_t k : {0u, 1u, 2u}) ASSERT_EQ(shell(jobs[k] + " > /dev/null 2>&1"), 0);
    // Job 3 was killed while writing its result (a .partial file is no result); job 4 sees
    // another scene than the planned one.
    std::ofstream(dir / "results/3.json.partial") << "{\"format\": \"cdlab-sweep-res";
    std::ofstream(scene, std::ios::app) << "# edited after planning\n";
    EXPECT_EQ(shell(jobs[4] + " > /dev/null 2>&1"), 2);
    const auto r = runCdlab("sweep --collect " + dir.string(), work);
    EXPECT_EQ(r.exit_code, 1) << r.err;
    const std::string run3 = "broadphase=hgrid world.time_step=0.05";
    const std::string run4 = "broadphase=hgrid world.time_step=0.005";
    EXPECT_NE(r.err.find("missing " + run3 + ": job 3 left no result"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("missing " + run4 + ": job 4 failed: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("is not the scene planned"), std::string::npos) << r.err;
    const std::string report = slurp(dir / "report.md");
    EXPECT_NE(report.find("## Missing or failed runs"), std::string::npos);
    EXPECT_NE(report.find("- **" + run3 + "**: job 3 left no result"), std::string::npos);
    EXPECT_NE(report.find("- **" + run4 + "**: job 4 failed"), std::string::npos);
    // The two runs that did run are in the table.
    const std::string csv = slurp(dir / "results.csv");
    EXPECT_NE(csv.find("broadphase=sap world.time_step=0.05,"), std::string::npos);
    EXPECT_EQ(csv.find(run3 + ","), std::string::npos);
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3);
    // The page carries the failures too: the banner, and a row marked failed for each.
    const std::string page = slurp(dir / "report.html");
    EXPECT_NE(page.find("id=\"failures\""), std::string::npos);
    EXPECT_NE(page.find("<tr class=\"failed\" data-failed=\"1\"><td>" + run3 + "</td>"),
              std::string::npos);
    EXPECT_NE(page.find("<tr class=\"failed\" data-failed=\"1\"><td>" + run4 + "</td>"),
              std::string::npos);

    // Without the reference nothing can be compared: report.md says so, no table.
    fs::remove(dir / "results/0.json");
    const auto no_ref = runCdlab("sweep --collect " + dir.string(), work);
    EXPECT_EQ(no_ref.exit_code, 1);
    EXPECT_NE(no_ref.err.find("missing reference: job 0 left no result"), std::string::npos)
        << no_ref.err;
    EXPECT_FALSE(fs::exists(dir / "results.csv"));
    EXPECT_FALSE(fs::exists(dir / "report.html"));
    EXPECT_NE(slurp(dir / "report.md").find("The reference run left no result"), std::string::npos);
    fs::remove_all(work);
}

TEST(SweepPlan, BadInputIsExitTwoWithAClearMessage) {
    const fs::path work = planDir("bad");
    const fs::path scene = sceneCopy(work);
    const fs::path dir = plan(scene, work);
    const std::vector<std::string> jobs = jobLines(dir);
    ASSERT_EQ(shell(jobs[0] + " > /dev/null 2>&1"), 0);
    ASSERT_EQ(shell(jobs[1] + " > /dev/null 2>&1"), 0);

    auto r = runCdlab("sweep --collect " + (work / "nowhere").string(), work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("nowhere: no such plan"), std::string::npos) << r.err;
    r = runCdlab("sweep --job " + (work / "nowhere").string() + " --run 0", work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("no such plan"), std::string::npos) << r.err;
    r = runCdlab("sweep --job " + dir.string() + " --run 5", work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--run 5: the plan"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("has jobs 0 to 4"), std::string::npos) << r.err;
    r = runCdlab("sweep --job " + dir.string(), work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--run K is required"), std::string::npos) << r.err;
    for (const char* j : {"0", "-3"}) {
        r = runCdlab(
            "sweep " + scene.string() + kVary + " -j " + j + " --out " + (work / "j").string(),
            work);
        EXPECT_EQ(r.exit_code, 2) << j;
        EXPECT_NE(r.err.find("must be >= 1"), std::string::npos) << r.err;
    }
    r = runCdlab("sweep " + scene.string() + " --slurm", work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--slurm: only with --plan"), std::string::npos) << r.err;
    r = runCdlab("sweep --collect " + dir.string() + " --job " + dir.string(), work);
    EXPECT_EQ(r.exit_code, 2);

    // A corrupt result file: named, nothing written.
    std::ofstream(dir / "results/1.json") << "{\"format\": \"cdlab-sweep-result 1\", \"plan_";
    r = runCdlab("sweep --collect " + dir.string(), work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("results/1.json: malformed result"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "report.md"));

    // A result of another plan of the same sweep (re-planned into another directory).
    const fs::path other = work / "other";
    ASSERT_EQ(
        runCdlab("sweep " + scene.string() + kVary + " --plan " + other.string(), work).exit_code,
        0);
    ASSERT_EQ(shell(jobLines(other)[1] + " > /dev/null 2>&1"), 0);
    fs::copy_file(other / "results/1.json", dir / "results/1.json",
                  fs::copy_options::overwrite_existing);
    r = runCdlab("sweep --collect " + dir.string(), work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("a result of another sweep"), std::string::npos) << r.err;

    // A truncated plan.
    const std::string plan_text = slurp(dir / "plan.json");
    std::ofstream(work / "truncated.json") << plan_text.substr(0, plan_text.size() / 2);
    r = runCdlab("sweep --job " + (work / "truncated.json").string() + " --run 0", work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("truncated.json: malformed plan"), std::string::npos) << r.err;

    // An edited plan is refused by the jobs and by collect.
    std::string text = slurp(dir / "plan.json");
    text.replace(text.find("\"repeat\": 2"), 11, "\"repeat\": 3");
    std::ofstream(dir / "plan.json") << text;
    r = runCdlab("sweep --job " + (dir / "plan.json").string() + " --run 0", work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("does not match its id"), std::string::npos) << r.err;
    r = runCdlab("sweep --collect " + dir.string(), work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("does not match its id"), std::string::npos) << r.err;
    fs::remove_all(work);
}

// Jobs that shared cores: their wall-clock ranges overlap (the wait for a core is charged to
// whichever job waited), their CPU-time ranges do not. The reading ranks by CPU time then, by
// the same rule (a winner only beyond the spread), and says why; otherwise by wall clock.
TEST(SweepPlan, ConcurrentRunsAreRankedByCpuTime) {
    auto run = [](const std::string& label, app::Timed wall, app::Timed cpu) {
        app::SweepRun r;
        r.label = label;
        r.time_step = 0.01;
        r.steps = 10;
        r.repeats = 3;
        r.ms_per_simulated_s = wall;
        r.cpu_ms_per_simulated_s = cpu;
        return r;
    };
    app::SweepOptions o;
    o.scene = fs::path(CDLAB_SOURCE_DIR) / "tests/data/tunnel_small.yaml";
    o.planned = true;
    app::SweepRun reference = run("", {10, 9, 11}, {10, 9, 11});
    reference.time_step = 0.001;
    engine::Scene base;
    base.world.time_step = 0.01;
    const std::vector<app::SweepRun> runs = {
        run("broadphase=sap", {1.4, 1.0, 3.0}, {1.2, 1.1, 1.3}),
        run("broadphase=tree", {2.0, 1.5, 2.5}, {1.9, 1.8, 2.0})};
    std::string md = app::sweep::markdownReport(o, base, 0.1, runs, reference, {});
    EXPECT_NE(md.find("none named, the lowest costs are within measurement spread of each other "
                      "(ms per simulated second"),
              std::string::npos)
        << md;
    EXPECT_EQ(md.find("ranks them by CPU time"), std::string::npos) << md;
    o.timed_concurrently = true;
    md = app::sweep::markdownReport(o, base, 0.1, runs, reference, {});
    EXPECT_NE(md.find("**broadphase=sap** (1.2 (1.1..1.3) CPU ms per simulated second, median "
                      "(min..max of 3 repeats)); its slowest repeat beat every other run's "
                      "fastest"),
              std::string::npos)
        << md;
    EXPECT_NE(md.find("the reading ranks them by CPU time"), std::string::npos) << md;
    // CPU ranges that overlap name no winner either.
    std::vector<app::SweepRun> close = runs;
    close[1].cpu_ms_per_simulated_s = {1.25, 1.2, 1.4};
    md = app::sweep::markdownReport(o, base, 0.1, close, reference, {});
    EXPECT_NE(md.find("within measurement spread of each other (CPU ms per simulated second"),
              std::string::npos)
        << md;
}

// Doubles cross the result file bit for bit (shortest round-trip text; non-finite as strings).
TEST(SweepPlan, ResultFilesKeepEveryBitOfTheirNumbers) {
    app::sweep::SweepPlan plan;
    plan.id = "0123456789abcdef";
    plan.runs.resize(2);
    app::sweep::JobResult result;
    result.run = 1;
    result.measured.time_step = 0.1 + 0.2;
    result.measured.max_energy_drift = std::nextafter(1e-300, 1.0);
    result.measured.max_angular_momentum_drift = 4.9406564584124654e-324;  // denormal
    result.measured.max_penetration = std::numeric_limits<double>::infinity();
    result.measured.flagged = std::nan("");
    result.measured.ms_step = {1.0 / 3, 2.0 / 3, 0.7};
    result.measured.state_hash = 0xfedcba9876543210ull;
    result.contacts[{3, 7}] = 0.07000000000000001;
    const app::sweep::JobResult back =
        app::sweep::parseResult(app::sweep::resultJson(plan, result), plan, 1);
    EXPECT_EQ(back.measured.time_step, 0.1 + 0.2);
    EXPECT_EQ(back.measured.max_energy_drift, std::nextafter(1e-300, 1.0));
    EXPECT_EQ(back.measured.max_angular_momentum_drift, 4.9406564584124654e-324);
    EXPECT_EQ(back.measured.max_penetration, std::numeric_limits<double>::infinity());
    EXPECT_TRUE(std::isnan(back.measured.flagged));
    EXPECT_EQ(back.measured.ms_step.median, 1.0 / 3);
    EXPECT_EQ(back.measured.ms_step.min, 2.0 / 3);
    EXPECT_EQ(back.measured.state_hash, 0xfedcba9876543210ull);
    EXPECT_EQ(back.contacts.at({3, 7}), 0.07000000000000001);
    // Another job's file, another plan's file.
    EXPECT_THROW(app::sweep::parseResult(app::sweep::resultJson(plan, result), plan, 0),
                 std::runtime_error);
    app::sweep::SweepPlan other = plan;
    other.id = "fedcba9876543210";
    EXPECT_THROW(app::sweep::parseResult(app::sweep::resultJson(plan, result), other, 1),
                 std::runtime_error);
}

}  // namespace
