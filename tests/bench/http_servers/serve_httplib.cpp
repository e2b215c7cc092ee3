// tests/bench/http_servers/serve_httplib.cpp -- the cpp-httplib backend, configured as
// `cdlab serve` configures it: a pool of request threads, each blocking in a long-poll.
#include <httplib.h>

#include <thread>

#include "bench_server.h"

namespace httpbench {

namespace {

class HttplibServer final : public BenchServer {
public:
    HttplibServer(FrameHub& hub, const ServeLimits& limits) {
        const int threads = limits.threads;
        server_.new_task_queue = [threads] { return new httplib::ThreadPool(threads); };
        server_.set_payload_max_length(limits.max_body);
        const auto timeout = limits.io_timeout.count();
        server_.set_read_timeout(timeout, 0);
        server_.set_write_timeout(timeout, 0);
        server_.set_keep_alive_timeout(timeout);
        server_.set_tcp_nodelay(limits.tcp_nodelay);
        if (limits.keep_alive_requests > 0) {
            server_.set_keep_alive_max_count(std::size_t(limits.keep_alive_requests));
        }
        const auto long_poll = limits.long_poll;
        server_.Get(
            "/frame.png", [&hub, long_poll](const httplib::Request& req, httplib::Response& res) {
                const auto f = hub.waitNewer(parseVersion(req.get_param_value("after")), long_poll);
                res.set_header("X-Version", std::to_string(f->version));
                res.set_header("X-Published-Ns", std::to_string(f->published_ns));
                res.set_content(f->bytes, "image/png");
            });
        server_.Post("/command",
                     [&hub, long_poll](const httplib::Request&, httplib::Response& res) {
                         const auto f = hub.waitNewer(hub.newest()->version, long_poll);
                         res.set_content(commandAnswer(*f), "application/json");
                     });
        port_ = server_.bind_to_any_port("127.0.0.1");
        if (port_ <= 0) throw std::runtime_error("cpp-httplib: cannot bind 127.0.0.1");
        listener_ = std::thread([this] { server_.listen_after_bind(); });
    }

    int port() const override { return port_; }

    void stop() override {
        server_.stop();
        listener_.join();
    }

private:
    httplib::Server server_;
    int port_ = 0;
    std::thread listener_;
};

}  // namespace

std::unique_ptr<BenchServer> startHttplib(FrameHub& hub, const ServeLimits& limits) {
    return std::make_unique<HttplibServer>(hub, limits);
}

}  // namespace httpbench
