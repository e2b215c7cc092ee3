// app/lab/sweep_local.cpp -- see sweep_local.h.
// Jobs are processes, not threads: each run gets a fresh process (its memory column is its own
// peak), and a crashing job cannot take the sweep down; the collect step names it instead.
#include "sweep_local.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "exit_codes.h"
#include "sweep_collect.h"

extern char** environ;

namespace app::sweep {

namespace fs = std::filesystem;

namespace {

// Starts job `k`, its output to DIR/logs/K.log; -1 when it cannot be started.
pid_t spawnJob(const SweepPlan& plan, std::size_t k) {
    const std::string binary = plan.binary.string();
    const std::string plan_file = (plan.dir / "plan.json").string();
    const std::string run = std::to_string(k);
    const std::string log = (plan.dir / "logs" / (run + ".log")).string();
    std::vector<std::string> args{binary, "sweep", "--job", plan_file, "--run", run};
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(),
                                     O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
    pid_t pid = -1;
    const int rc = posix_spawn(&pid, binary.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    return rc == 0 ? pid : -1;
}

}  // namespace

int runJobsLocally(const SweepPlan& plan, int jobs, std::ostream& out) {
    struct Running {
        pid_t pid;
        std::size_t k;
    };
    std::vector<Running> running;
    std::size_t next = 0, done = 0;
    int failed = 0;
    auto report = [&](std::size_t k, const std::string& how) {
        ++done;
        out << "[" << done << "/" << plan.runs.size() << "] job " << k << " ("
            << (k == 0 ? "reference" : plan.runs[k].label) << "): " << how << "\n";
    };
    while (done < plan.runs.size()) {
        while (next < plan.runs.size() && running.size() < static_cast<std::size_t>(jobs)) {
            const pid_t pid = spawnJob(plan, next);
            if (pid < 0) {
                report(next, std::string("cannot start ") + plan.binary.string() + ": " +
                                 std::strerror(errno));
                ++failed;
            } else {
                running.push_back({pid, next});
            }
            ++next;
        }
        // Polls only our own children (never waitpid(-1): the caller may have others).
        bool reaped = false;
        for (std::size_t i = 0; i < running.size(); ++i) {
            int status = 0;
            if (waitpid(running[i].pid, &status, WNOHANG) != running[i].pid) continue;
            const bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
            if (!ok) ++failed;
            report(
                running[i].k,
                ok ? std::string("done")
                   : (WIFEXITED(status) ? "exit " + std::to_string(WEXITSTATUS(status))
                                        : "killed by signal " + std::to_string(WTERMSIG(status))) +
                         " (log: " +
                         (plan.dir / "logs" / (std::to_string(running[i].k) + ".log")).string() +
                         ")");
            running.erase(running.begin() + static_cast<std::ptrdiff_t>(i));
            reaped = true;
            break;
        }
        if (!reaped && !running.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return failed;
}

int runPlannedLocally(const SweepOptions& options, const SweepSetup& setup, std::ostream& out,
                      std::ostream& err) {
    // No fallback to /proc/self/exe here: a library caller (a test) is not cdlab.
    std::error_code ec;
    const fs::path& binary = options.cdlab_binary;
    if (binary.empty() || !fs::is_regular_file(binary, ec)) {
        err << "-j " << options.jobs << ": no cdlab executable to run the jobs"
            << (binary.empty() ? "" : " (" + binary.string() + " is not a file)") << "\n";
        return kExitBadInput;
    }
    const SweepPlan plan = makePlan(options, setup, binary, setup.out_dir / "plan");
    try {
        writePlan(plan, false);
    } catch (const std::exception& e) {
        err << "error: " << e.what() << "\n";
        return kExitFailure;
    }
    out << "running " << plan.runs.size() << " jobs, " << options.jobs << " at a time ("
        << (plan.dir / "jobs.txt").string() << ")\n";
    runJobsLocally(plan, options.jobs, out);
    CollectOptions collect;
    collect.plan = plan.dir;
    collect.out_dir = setup.out_dir;
    collect.report_timing = options.report_timing;
    return collectSweep(collect, out, err);
}

}  // namespace app::sweep
