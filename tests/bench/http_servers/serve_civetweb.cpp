// tests/bench/http_servers/serve_civetweb.cpp -- the civetweb backend (Debian's libcivetweb,
// C API): a fixed set of worker threads, each owning one connection at a time and blocking in a
// long-poll, as cpp-httplib's pool does.
#include <civetweb.h>

#include <stdexcept>
#include <string>

#include "bench_server.h"

namespace httpbench {

namespace {

class CivetwebServer final : public BenchServer {
public:
    CivetwebServer(FrameHub& hub, const ServeLimits& limits) : hub_(hub), limits_(limits) {
        mg_init_library(0);
        const std::string threads = std::to_string(limits.threads);
        const std::string timeout_ms =
            std::to_string(std::chrono::milliseconds(limits.io_timeout).count());
        // Name, value pairs.
        // clang-format off
        const char* options[] = {"listening_ports", "127.0.0.1:0",
                                 "num_threads", threads.c_str(),
                                 "request_timeout_ms", timeout_ms.c_str(),
                                 "enable_keep_alive", "yes",
                                 "keep_alive_timeout_ms", timeout_ms.c_str(),
                                 "tcp_nodelay", limits.tcp_nodelay ? "1" : "0",
                                 nullptr};
        // clang-format on
        mg_callbacks callbacks{};
        context_ = mg_start(&callbacks, nullptr, options);
        if (context_ == nullptr) throw std::runtime_error("civetweb: cannot listen on 127.0.0.1");
        mg_server_port ports[1]{};
        if (mg_get_server_ports(context_, 1, ports) < 1) {
            mg_stop(context_);
            throw std::runtime_error("civetweb: no listening port");
        }
        port_ = ports[0].port;
        mg_set_request_handler(context_, "/frame.png", &CivetwebServer::frame, this);
        mg_set_request_handler(context_, "/command", &CivetwebServer::command, this);
    }

    int port() const override { return port_; }

    void stop() override {
        mg_stop(context_);
        mg_exit_library();
    }

private:
    static int frame(mg_connection* conn, void* self_ptr) {
        auto& self = *static_cast<CivetwebServer*>(self_ptr);
        const mg_request_info* info = mg_get_request_info(conn);
        const std::uint64_t after = info->query_string ? afterParam(info->query_string) : 0;
        const auto f = self.hub_.waitNewer(after, self.limits_.long_poll);
        const std::string version = std::to_string(f->version);
        const std::string published = std::to_string(f->published_ns);
        const std::string length = std::to_string(f->bytes.size());
        mg_response_header_start(conn, 200);
        mg_response_header_add(conn, "Content-Type", "image/png", -1);
        mg_response_header_add(conn, "Content-Length", length.c_str(), -1);
        mg_response_header_add(conn, "X-Version", version.c_str(), -1);
        mg_response_header_add(conn, "X-Published-Ns", published.c_str(), -1);
        mg_response_header_send(conn);
        mg_write(conn, f->bytes.data(), f->bytes.size());
        return 200;
    }

    static int command(mg_connection* conn, void* self_ptr) {
        auto& self = *static_cast<CivetwebServer*>(self_ptr);
        const mg_request_info* info = mg_get_request_info(conn);
        if (std::string_view(info->request_method) != "POST") {
            mg_send_http_error(conn, 405, "POST only");
            return 405;
        }
        if (info->content_length < 0 || std::size_t(info->content_length) > self.limits_.max_body) {
            mg_send_http_error(conn, 413, "request body over the limit");
            return 413;
        }
        std::string body(std::size_t(info->content_length), '\0');
        std::size_t got = 0;
        while (got < body.size()) {
            const int n = mg_read(conn, body.data() + got, body.size() - got);
            if (n <= 0) return 400;  // the client went away; nothing to answer
            got += std::size_t(n);
        }
        const auto f = self.hub_.waitNewer(self.hub_.newest()->version, self.limits_.long_poll);
        const std::string answer = commandAnswer(*f);
        mg_send_http_ok(conn, "application/json", static_cast<long long>(answer.size()));
        mg_write(conn, answer.data(), answer.size());
        return 200;
    }

    FrameHub& hub_;
    ServeLimits limits_;
    mg_context* context_ = nullptr;
    int port_ = 0;
};

}  // namespace

std::unique_ptr<BenchServer> startCivetweb(FrameHub& hub, const ServeLimits& limits) {
    return std::make_unique<CivetwebServer>(hub, limits);
}

}  // namespace httpbench
