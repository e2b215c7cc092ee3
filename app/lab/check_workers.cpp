// app/lab/check_workers.cpp -- child processes grading one scene each (check_workers.h).
// Processes rather than threads: a scene that crashes or hangs takes only its own process with
// it, a hung one can be stopped (a thread cannot), and each child has its own OSMesa context and
// heap. Every child writes its report to a file of its own and its output to a log of its own;
// reports are stored by scene index, so finishing order never shows in what the parent prints.
#include "check_workers.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>

#include "checkers_step.h"
#include "output_files.h"
#include "render/image.h"

extern char** environ;

namespace app {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

constexpr const char* kReportMagic = "cdlab-check-report 1";
// How often the parent looks at its children: finishing and timeouts are noticed this late.
constexpr std::chrono::milliseconds kPollInterval{10};

void putString(std::ostringstream& s, const std::string& v) { s << v.size() << ':' << v << '\n'; }

// Reads the fields formatWorkerReport writes; any mismatch makes `ok` false.
class ReportReader {
public:
    explicit ReportReader(const std::string& text) : text_(text) {}
    bool ok = true;

    std::string line() {
        const std::size_t end = text_.find('\n', pos_);
        if (end == std::string::npos) return fail();
        std::string l = text_.substr(pos_, end - pos_);
        pos_ = end + 1;
        return l;
    }
    // "KEY VALUE" with an unsigned VALUE.
    std::size_t count(const std::string& key) {
        const std::string l = line();
        if (l.rfind(key + " ", 0) != 0) return fail(), 0;
        return number(l.substr(key.size() + 1));
    }
    std::string string() {
        const std::size_t colon = text_.find(':', pos_);
        if (colon == std::string::npos) return fail();
        const std::size_t n = number(text_.substr(pos_, colon - pos_));
        if (!ok || n > text_.size() - colon - 1 || colon + 1 + n >= text_.size() ||
            text_[colon + 1 + n] != '\n') {
            return fail();
        }
        pos_ = colon + 2 + n;
        return text_.substr(colon + 1, n);
    }
    bool atEnd() const { return pos_ == text_.size(); }

private:
    std::string fail() {
        ok = false;
        pos_ = text_.size();
        return {};
    }
    std::size_t number(const std::string& s) {
        if (s.empty() || s.size() > 12 || s.find_first_not_of("0123456789") != std::string::npos) {
            fail();
            return 0;
        }
        return std::stoul(s);
    }
    const std::string& text_;
    std::size_t pos_ = 0;
};

struct Child {
    pid_t pid = -1;
    std::size_t index = 0;
    Clock::time_point start;
};

fs::path reportPath(const fs::path& work, std::size_t i) {
    return work / (std::to_string(i) + ".report");
}
fs::path logPath(const fs::path& work, std::size_t i) {
    return work / (std::to_string(i) + ".log");
}

// The child between fork and exec: only async-signal-safe calls. It dies with the parent
// (PR_SET_PDEATHSIG survives exec; set before exec, so no window in which the parent could die
// unnoticed), reads /dev/null, writes stdout and stderr to its log, and reports a failed exec's
// errno through `report_fd`, which exec closes.
[[noreturn]] void execWorker(char* const* argv, const char* log, pid_t parent, int report_fd) {
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(127);
    int err = 0;
    const int in = ::open("/dev/null", O_RDONLY);
    const int out = ::open(log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (in < 0 || out < 0 || ::dup2(in, 0) < 0 || ::dup2(out, 1) < 0 || ::dup2(out, 2) < 0) {
        err = errno;
    } else {
        if (in > 2) ::close(in);
        if (out > 2) ::close(out);
        ::execve(argv[0], argv, environ);
        err = errno;
    }
    [[maybe_unused]] const ssize_t n = ::write(report_fd, &err, sizeof err);
    ::_exit(127);
}

// Starts `cdlab check --worker-result ...` for scene `i`, its stdout and stderr into its log.
// Returns -1 and sets `error` when it cannot be started.
pid_t spawnWorker(const WorkerPlan& plan, std::size_t i, const fs::path& work, std::string& error) {
    std::vector<std::string> args = {
        plan.exe.string(), "check",           "--worker-result", reportPath(work, i).string(),
        "--worker-index",  std::to_string(i), "--out",           plan.dump_root.string()};
    if (plan.frames) {
        args.push_back("--frames");
        args.push_back(std::to_string(*plan.frames));
    }
    if (plan.events) {
        args.push_back("--events");
        args.push_back(plan.events->string());
    }
    args.push_back("--");  // a scene named "-x.yaml" is still a scene
    args.push_back(plan.scenes[i].string());
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    const std::string log = logPath(work, i).string();

    int pipe_fds[2];
    if (::pipe2(pipe_fds, O_CLOEXEC) != 0) {
        error = std::string("cannot start a grader: ") + std::strerror(errno);
        return -1;
    }
    const pid_t parent = ::getpid();
    const pid_t pid = ::fork();
    const int fork_errno = errno;
    if (pid == 0) execWorker(argv.data(), log.c_str(), parent, pipe_fds[1]);
    ::close(pipe_fds[1]);
    int child_errno = 0;
    ssize_t n = 0;
    if (pid > 0) {
        do {
            n = ::read(pipe_fds[0], &child_errno, sizeof child_errno);
        } while (n < 0 && errno == EINTR);
    }
    ::close(pipe_fds[0]);
    if (pid < 0 || n == ssize_t(sizeof child_errno)) {
        if (pid > 0) {
            while (::waitpid(pid, nullptr, 0) < 0 && errno == EINTR) {
            }
        }
        error = "cannot start " + plan.exe.string() + ": " +
                std::strerror(pid < 0 ? fork_errno : child_errno);
        return -1;
    }
    return pid;
}

SceneReport notRun(const std::string& why) {
    SceneReport r;
    r.outcome = SceneOutcome::NotRun;
    r.rows = {{"run", false, "could not run: " + why}};
    return r;
}

// The report of a child that has ended with `status` (or been killed for its timeout).
SceneReport collect(const WorkerPlan& plan, const Child& c, int status, bool timed_out,
                    const fs::path& work) {
    std::optional<SceneReport> report;
    if (timed_out) {
        report = notRun("timed out after " + formatDouble(*plan.timeout) + " s");
    } else if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
        report = parseWorkerReport(fileBytes(reportPath(work, c.index)));
        if (!report) report = notRun("the grader's report is unreadable");
    } else if (WIFSIGNALED(status)) {
        const int sig = WTERMSIG(status);
        const char* name = strsignal(sig);
        report = notRun("the grader was killed by signal " + std::to_string(sig) +
                        (name ? std::string(" (") + name + ")" : std::string()));
    } else {
        report = notRun("the grader exited with code " + std::to_string(WEXITSTATUS(status)));
    }
    if (report->outcome == SceneOutcome::NotRun && report->seconds == 0) {
        report->seconds = std::chrono::duration<double>(Clock::now() - c.start).count();
    }
    report->label = sceneLabel(plan.scenes[c.index], plan.events);
    report->log = fileBytes(logPath(work, c.index));
    return *report;
}

}  // namespace

std::string formatWorkerReport(const SceneReport& report) {
    std::ostringstream s;
    s.precision(17);
    s << kReportMagic << '\n'
      << "outcome " << static_cast<int>(report.outcome) << '\n'
      << "seconds " << report.seconds << '\n'
      << "notes " << report.notes.size() << '\n';
    for (const std::string& n : report.notes) putString(s, n);
    s << "rows " << report.rows.size() << '\n';
    for (const CheckRow& r : report.rows) {
        s << (r.pass ? "pass" : "fail") << '\n';
        putString(s, r.expectation);
        putString(s, r.reason);
    }
    s << "end\n";
    return s.str();
}

std::optional<SceneReport> parseWorkerReport(const std::string& text) {
    ReportReader in(text);
    SceneReport r;
    if (in.line() != kReportMagic) return std::nullopt;
    const std::size_t outcome = in.count("outcome");
    if (outcome > static_cast<std::size_t>(SceneOutcome::NotRun)) return std::nullopt;
    r.outcome = static_cast<SceneOutcome>(outcome);
    const std::string seconds = in.line();
    if (seconds.rfind("seconds ", 0) != 0) return std::nullopt;
    try {
        r.seconds = std::stod(seconds.substr(8));
    } catch (const std::exception&) {
        return std::nullopt;
    }
    const std::size_t notes = in.count("notes");
    for (std::size_t i = 0; in.ok && i < notes; ++i) r.notes.push_back(in.string());
    const std::size_t rows = in.count("rows");
    for (std::size_t i = 0; in.ok && i < rows; ++i) {
        const std::string verdict = in.line();
        if (verdict != "pass" && verdict != "fail") return std::nullopt;
        CheckRow row;
        row.pass = verdict == "pass";
        row.expectation = in.string();
        row.reason = in.string();
        r.rows.push_back(std::move(row));
    }
    if (in.line() != "end" || !in.ok || !in.atEnd()) return std::nullopt;
    return r;
}

int runCheckWorker(const fs::path& scene, std::size_t index, std::optional<int> frames,
                   const fs::path& dump_root, const fs::path& result,
                   const std::optional<fs::path>& events) {
    SceneReport report = gradeSceneFile(scene, index, frames, dump_root, events);
    try {
        writeTextAtomically(result, formatWorkerReport(report));
    } catch (const render::RenderError& e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 1;
    }
    return 0;
}

std::vector<SceneReport> gradeInWorkers(const WorkerPlan& plan) {
    std::vector<SceneReport> reports(plan.scenes.size());
    std::error_code ec;
    const fs::path tmp = fs::temp_directory_path(ec);
    if (ec) throw render::RenderError("no temporary folder for the graders: " + ec.message());
    const fs::path work = tmp / ("cdlab_check_work_" + std::to_string(::getpid()));
    fs::remove_all(work, ec);
    fs::create_directories(work, ec);
    if (ec) throw render::RenderError("cannot create " + work.string() + ": " + ec.message());

    std::vector<Child> running;
    std::size_t next = 0;
    while (next < plan.scenes.size() || !running.empty()) {
        while (running.size() < std::size_t(std::max(plan.jobs, 1)) && next < plan.scenes.size()) {
            std::string error;
            const pid_t pid = spawnWorker(plan, next, work, error);
            if (pid < 0) {
                reports[next] = notRun(error);
                reports[next].label = sceneLabel(plan.scenes[next], plan.events);
            } else {
                running.push_back({pid, next, Clock::now()});
            }
            ++next;
        }
        bool any_ended = false;
        for (std::size_t k = 0; k < running.size();) {
            const Child& c = running[k];
            int status = 0;
            pid_t done = ::waitpid(c.pid, &status, WNOHANG);
            bool timed_out = false;
            if (done == 0 && plan.timeout &&
                std::chrono::duration<double>(Clock::now() - c.start).count() > *plan.timeout) {
                ::kill(c.pid, SIGKILL);
                do {
                    done = ::waitpid(c.pid, &status, 0);
                } while (done < 0 && errno == EINTR);
                timed_out = true;
            }
            if (done == 0 || (done < 0 && errno == EINTR)) {
                ++k;
                continue;
            }
            reports[c.index] = collect(plan, c, status, timed_out, work);
            running.erase(running.begin() + std::ptrdiff_t(k));
            any_ended = true;
        }
        if (!any_ended && !running.empty()) std::this_thread::sleep_for(kPollInterval);
    }
    fs::remove_all(work, ec);
    return reports;
}

}  // namespace app
