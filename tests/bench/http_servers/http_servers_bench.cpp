// tests/bench/http_servers/http_servers_bench.cpp -- cpp-httplib, civetweb and Boost.Beast
// serving `cdlab serve`'s workload, measured alike (a bench run by hand, never by ctest).
//
//   http_servers_bench [--rounds R] [--seconds S] [--commands N] [--frame-bytes B]
//                      [--backends httplib,httplib-nodelay,httplib-tuned,civetweb,...]
//
// Each round starts each backend in a child process of its own (this program with --serve),
// drives it from this process over loopback, reads the child's RSS and threads from /proc, and
// stops it; backends alternate within a round so a slow spell of a shared machine falls on all.
// Prints a Markdown table: the median over rounds with [min-max], and the ratio to cpp-httplib.
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_server.h"
#include "frame_hub.h"
#include "measure.h"

extern char** environ;

namespace httpbench {

namespace {

constexpr double kFps = 30.0;
constexpr int kHostileConnections = 50;
constexpr double kAttackSeconds = 8.0;  // beyond the 5 s timeouts, to see whether they free

using StartServer = std::unique_ptr<BenchServer> (*)(FrameHub&, const ServeLimits&);

struct Backend {
    StartServer start;
    bool tcp_nodelay;
    int keep_alive_requests;
};

// "httplib" is configured as `cdlab serve` configures it; "-nodelay" adds TCP_NODELAY;
// "httplib-tuned" also lets a kept-alive connection carry any number of requests.
const std::map<std::string, Backend>& backends() {
    static const std::map<std::string, Backend> table = {
        {"httplib", {&startHttplib, false, 0}},
        {"httplib-nodelay", {&startHttplib, true, 0}},
        {"httplib-tuned", {&startHttplib, true, 1 << 30}},
        {"civetweb", {&startCivetweb, false, 0}},
        {"civetweb-nodelay", {&startCivetweb, true, 0}},
        {"beast", {&startBeast, false, 0}},
    };
    return table;
}

// The child: serves until SIGTERM. Signals are blocked before any thread starts, so only the
// main thread's sigwait sees them.
int serve(const std::string& backend, std::size_t frame_bytes) {
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGTERM);
    sigaddset(&set, SIGINT);
    pthread_sigmask(SIG_BLOCK, &set, nullptr);
    const auto start = backends().find(backend);
    if (start == backends().end()) {
        std::cerr << "--serve: unknown backend '" << backend << "'\n";
        return 2;
    }
    FrameHub hub(frame_bytes, kFps);
    ServeLimits limits;
    limits.tcp_nodelay = start->second.tcp_nodelay;
    limits.keep_alive_requests = start->second.keep_alive_requests;
    std::unique_ptr<BenchServer> server = start->second.start(hub, limits);
    std::cout << "listening " << server->port() << std::endl;
    int sig = 0;
    sigwait(&set, &sig);
    hub.stop();  // releases the request threads blocked in a long-poll
    server->stop();
    return 0;
}

struct Child {
    pid_t pid = -1;
    int port = 0;
};

Child spawnServer(const std::string& self, const std::string& backend, std::size_t frame_bytes) {
    int out[2];
    if (pipe(out) != 0) throw std::runtime_error("pipe failed");
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, out[1], 1);
    posix_spawn_file_actions_addclose(&actions, out[0]);
    const std::string bytes = std::to_string(frame_bytes);
    std::vector<std::string> args = {self, "--serve", backend, "--frame-bytes", bytes};
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    Child c;
    const int rc = posix_spawn(&c.pid, self.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    close(out[1]);
    if (rc != 0) throw std::runtime_error("cannot start " + self);
    std::string line;
    char ch;
    while (read(out[0], &ch, 1) == 1 && ch != '\n') line += ch;
    close(out[0]);
    if (std::sscanf(line.c_str(), "listening %d", &c.port) != 1) {
        throw std::runtime_error(backend + ": the server did not start (" + line + ")");
    }
    return c;
}

// VmRSS, VmHWM (kB) and Threads of a process.
std::map<std::string, double> procStatus(pid_t pid) {
    std::ifstream in("/proc/" + std::to_string(pid) + "/status");
    std::map<std::string, double> out;
    std::string key;
    double value = 0;
    while (in >> key) {
        if (key == "VmRSS:" || key == "VmHWM:" || key == "Threads:") {
            in >> value;
            out[key.substr(0, key.size() - 1)] = value;
        }
        in.ignore(1 << 20, '\n');
    }
    return out;
}

// The rows, in measureOnce's order; each round adds one value per (row, backend).
const std::vector<std::string>& metrics() {
    static const std::vector<std::string> rows = {
        "(a) frames/s, 1 watcher",
        "(a) frames/s per watcher, 4 watchers (mean)",
        "(a) frames/s, slowest of 4 watchers",
        "(a) frame published -> in hand, 4 watchers, median ms",
        "(a) frame published -> in hand, 4 watchers, p95 ms",
        "(b) command round trip, median ms",
        "(b) command round trip, p95 ms",
        "(b) frame published -> command answer in hand, median ms",
        "(b) frame published -> command answer in hand, p95 ms",
        "(c) server RSS after the run, MB",
        "(c) server peak RSS, MB",
        "(c) server threads",
        "(d) idle x50: watcher frames/s during the attack",
        "(d) idle x50: watcher's longest wait for a frame, ms",
        "(d) idle x50: watcher frames/s in the second after",
        "(d) idle x50: hostile connections the server dropped",
        "(d) idle x50: a new client 2 s into the attack, ms to its first frame",
        "(d) slow headers x50: watcher frames/s during the attack",
        "(d) slow headers x50: watcher's longest wait for a frame, ms",
        "(d) slow headers x50: watcher frames/s in the second after",
        "(d) slow headers x50: hostile connections the server dropped",
        "(d) slow headers x50: a new client 2 s into the attack, ms to its first frame",
        "failed requests (all parts)",
    };
    return rows;
}

std::vector<double> measureOnce(int port, pid_t pid, double seconds, int command_count,
                                std::size_t frame_bytes) {
    const WatchResult one = watch(port, 1, seconds, frame_bytes);
    const WatchResult four = watch(port, 4, seconds, frame_bytes);
    const CommandResult cmd = commands(port, command_count, kFps, frame_bytes);
    const HostileResult idle =
        hostile(port, Hostility::Idle, kHostileConnections, kAttackSeconds, frame_bytes);
    const HostileResult slow =
        hostile(port, Hostility::SlowHeaders, kHostileConnections, kAttackSeconds, frame_bytes);
    std::map<std::string, double> status = procStatus(pid);
    return {one.fps_mean,
            four.fps_mean,
            four.fps_min,
            four.delivery_ms_median,
            four.delivery_ms_p95,
            cmd.round_trip_ms_median,
            cmd.round_trip_ms_p95,
            cmd.after_publish_ms_median,
            cmd.after_publish_ms_p95,
            status["VmRSS"] / 1024.0,
            status["VmHWM"] / 1024.0,
            status["Threads"],
            idle.fps,
            idle.longest_gap_ms,
            idle.fps_after,
            double(idle.dropped_by_server),
            idle.new_client_ms,
            slow.fps,
            slow.longest_gap_ms,
            slow.fps_after,
            double(slow.dropped_by_server),
            slow.new_client_ms,
            double(one.failed_requests + four.failed_requests + cmd.failed)};
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n == 0 ? 0 : n % 2 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2;
}

std::string fixed(double v) {
    char text[32];
    std::snprintf(text, sizeof text, std::abs(v) >= 100 ? "%.0f" : "%.1f", v);
    return text;
}

std::vector<std::string> splitCommas(const std::string& text) {
    std::vector<std::string> out;
    std::stringstream in(text);
    for (std::string item; std::getline(in, item, ',');) out.push_back(item);
    return out;
}

int run(int argc, char** argv) {
    int rounds = 3;
    double seconds = 5;
    int command_count = 200;
    std::size_t frame_bytes = 200 * 1024;
    std::vector<std::string> names = {"httplib",  "httplib-nodelay",  "httplib-tuned",
                                      "civetweb", "civetweb-nodelay", "beast"};
    std::string serve_backend;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        const auto value = [&]() -> std::string {
            if (i + 1 >= argc) throw std::invalid_argument(arg + ": expected a value");
            return argv[++i];
        };
        if (arg == "--serve")
            serve_backend = value();
        else if (arg == "--rounds")
            rounds = std::stoi(value());
        else if (arg == "--seconds")
            seconds = std::stod(value());
        else if (arg == "--commands")
            command_count = std::stoi(value());
        else if (arg == "--frame-bytes")
            frame_bytes = std::stoul(value());
        else if (arg == "--backends")
            names = splitCommas(value());
        else
            throw std::invalid_argument("unknown flag " + arg);
    }
    if (!serve_backend.empty()) return serve(serve_backend, frame_bytes);
    for (const std::string& n : names) {
        if (!backends().count(n)) throw std::invalid_argument("--backends: unknown '" + n + "'");
    }
    if (rounds < 1 || seconds <= 0 || command_count < 1 || frame_bytes < 8) {
        throw std::invalid_argument("--rounds, --seconds, --commands, --frame-bytes: must be > 0");
    }
    const std::string self = "/proc/self/exe";
    std::map<std::string, std::vector<std::vector<double>>> values;  // backend -> row -> rounds
    for (int round = 0; round < rounds; ++round) {
        // Rotate the order each round, so no backend always runs first or last.
        std::vector<std::string> order = names;
        std::rotate(order.begin(), order.begin() + round % order.size(), order.end());
        for (const std::string& name : order) {
            std::cerr << "round " << round + 1 << "/" << rounds << ": " << name << " ..."
                      << std::flush;
            const Child c = spawnServer(self, name, frame_bytes);
            const std::vector<double> row =
                measureOnce(c.port, c.pid, seconds, command_count, frame_bytes);
            kill(c.pid, SIGTERM);
            int status = 0;
            waitpid(c.pid, &status, 0);
            auto& rows = values[name];
            rows.resize(row.size());
            for (std::size_t m = 0; m < row.size(); ++m) rows[m].push_back(row[m]);
            std::cerr << " 1 watcher " << fixed(row[0]) << " fps, command median " << fixed(row[5])
                      << " ms, slow-headers attack " << fixed(row[17]) << " fps"
                      << (WIFEXITED(status) && WEXITSTATUS(status) == 0
                              ? ""
                              : " (the server did not exit cleanly)")
                      << "\n";
        }
    }
    std::cout << "| " << rounds << " rounds: median [min-max] (ratio to httplib) |";
    for (const std::string& n : names) std::cout << " " << n << " |";
    std::cout << "\n|---|";
    for (std::size_t i = 0; i < names.size(); ++i) std::cout << "---|";
    std::cout << "\n";
    for (std::size_t m = 0; m < metrics().size(); ++m) {
        std::cout << "| " << metrics()[m] << " |";
        const double base = values.count("httplib") ? median(values["httplib"][m]) : 0;
        for (const std::string& n : names) {
            const std::vector<double>& v = values[n][m];
            const double med = median(v);
            std::cout << " " << fixed(med);
            if (v.size() > 1) {
                std::cout << " [" << fixed(*std::min_element(v.begin(), v.end())) << "-"
                          << fixed(*std::max_element(v.begin(), v.end())) << "]";
            }
            if (n != "httplib" && base > 0) {
                char ratio[32];
                std::snprintf(ratio, sizeof ratio, " (x%.2f)", med / base);
                std::cout << ratio;
            }
            std::cout << " |";
        }
        std::cout << "\n";
    }
    return 0;
}

}  // namespace

}  // namespace httpbench

int main(int argc, char** argv) {
    try {
        return httpbench::run(argc, argv);
    } catch (const std::exception& e) {
        std::cerr << "http_servers_bench: " << e.what() << "\n";
        return 2;
    }
}
