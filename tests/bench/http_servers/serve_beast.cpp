// tests/bench/http_servers/serve_beast.cpp -- the Boost.Beast backend (Boost 1.74, header-only):
// asynchronous sessions on an io_context run by the thread budget, after Beast's
// http_server_async example. A long-poll holds no thread: it is a timer that the publisher
// cancels (through the session's strand) when a newer frame is out.
#include <boost/asio/dispatch.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <optional>
#include <thread>
#include <vector>

#include "bench_server.h"

namespace httpbench {

namespace {

namespace beast = boost::beast;
namespace http = beast::http;
namespace net = boost::asio;
using tcp = net::ip::tcp;

class Session : public std::enable_shared_from_this<Session> {
public:
    Session(tcp::socket&& socket, FrameHub& hub, const ServeLimits& limits)
        : stream_(std::move(socket)), timer_(stream_.get_executor()), hub_(hub), limits_(limits) {}

    void run() {
        net::dispatch(stream_.get_executor(),
                      beast::bind_front_handler(&Session::read, shared_from_this()));
    }

private:
    void read() {
        parser_.emplace();
        parser_->body_limit(limits_.max_body);
        // A deadline for the whole request, headers and body: a client that trickles its
        // headers is dropped after io_timeout however often it sends a byte.
        stream_.expires_after(limits_.io_timeout);
        http::async_read(stream_, buffer_, *parser_,
                         beast::bind_front_handler(&Session::onRead, shared_from_this()));
    }

    void onRead(beast::error_code ec, std::size_t) {
        if (ec) {
            if (ec == http::error::body_limit) return answer(413, "text/plain", "too large", {});
            stream_.socket().shutdown(tcp::socket::shutdown_both, ec);
            return;
        }
        stream_.expires_never();
        const auto& req = parser_->get();
        const beast::string_view target = req.target();
        const std::size_t q = target.find('?');
        const beast::string_view path = target.substr(0, q);
        if (path == "/frame.png" && req.method() == http::verb::get) {
            const beast::string_view query =
                q == beast::string_view::npos ? beast::string_view() : target.substr(q + 1);
            waitThen(afterParam(std::string_view(query.data(), query.size())), true);
        } else if (path == "/command" && req.method() == http::verb::post) {
            waitThen(hub_.newest()->version, false);
        } else {
            answer(404, "text/plain", "no such page", {});
        }
    }

    // Answers once a frame newer than `after` is out or the long-poll ends; no thread waits.
    void waitThen(std::uint64_t after, bool frame) {
        const std::uint64_t wait = ++wait_id_;
        std::weak_ptr<Session> weak = shared_from_this();
        const bool waiting = hub_.wakeWhenNewer(after, [weak, wait] {
            if (auto self = weak.lock()) {
                net::post(self->stream_.get_executor(), [self, wait] {
                    if (self->wait_id_ == wait) self->timer_.cancel();
                });
            }
        });
        if (!waiting) return reply(frame);
        timer_.expires_after(limits_.long_poll);
        timer_.async_wait(
            [self = shared_from_this(), frame](beast::error_code) { self->reply(frame); });
    }

    void reply(bool frame) {
        ++wait_id_;  // a wake still queued for this wait no longer cancels anything
        const auto f = hub_.newest();
        if (frame) return answer(200, "image/png", f->bytes, f);
        answer(200, "application/json", commandAnswer(*f), {});
    }

    void answer(unsigned status, const char* type, std::string body,
                const std::shared_ptr<const Frame>& f) {
        const auto& req = parser_->get();
        res_.emplace(http::status(status), req.version());
        res_->set(http::field::content_type, type);
        if (f) {
            res_->set("X-Version", std::to_string(f->version));
            res_->set("X-Published-Ns", std::to_string(f->published_ns));
        }
        res_->keep_alive(req.keep_alive() && status < 400);
        res_->body() = std::move(body);
        res_->prepare_payload();
        stream_.expires_after(limits_.io_timeout);
        http::async_write(stream_, *res_,
                          beast::bind_front_handler(&Session::onWrite, shared_from_this()));
    }

    void onWrite(beast::error_code ec, std::size_t) {
        const bool again = !ec && res_->keep_alive();
        res_.reset();
        if (again) return read();
        stream_.socket().shutdown(tcp::socket::shutdown_both, ec);
    }

    beast::tcp_stream stream_;
    net::steady_timer timer_;
    beast::flat_buffer buffer_;
    std::optional<http::request_parser<http::string_body>> parser_;
    std::optional<http::response<http::string_body>> res_;
    std::uint64_t wait_id_ = 0;
    FrameHub& hub_;
    const ServeLimits& limits_;
};

class BeastServer final : public BenchServer {
public:
    BeastServer(FrameHub& hub, const ServeLimits& limits)
        : hub_(hub), limits_(limits), acceptor_(net::make_strand(ioc_)) {
        const tcp::endpoint endpoint(net::ip::make_address("127.0.0.1"), 0);
        acceptor_.open(endpoint.protocol());
        acceptor_.set_option(net::socket_base::reuse_address(true));
        acceptor_.bind(endpoint);
        acceptor_.listen(net::socket_base::max_listen_connections);
        port_ = acceptor_.local_endpoint().port();
        accept();
        for (int i = 0; i < limits.threads; ++i) threads_.emplace_back([this] { ioc_.run(); });
    }

    int port() const override { return port_; }

    void stop() override {
        ioc_.stop();
        for (std::thread& t : threads_) t.join();
    }

private:
    void accept() {
        acceptor_.async_accept(
            net::make_strand(ioc_), [this](beast::error_code ec, tcp::socket socket) {
                if (!ec) {
                    if (limits_.tcp_nodelay) socket.set_option(tcp::no_delay(true), ec);
                    std::make_shared<Session>(std::move(socket), hub_, limits_)->run();
                }
                accept();
            });
    }

    FrameHub& hub_;
    ServeLimits limits_;
    net::io_context ioc_{};
    tcp::acceptor acceptor_;
    int port_ = 0;
    std::vector<std::thread> threads_;
};

}  // namespace

std::unique_ptr<BenchServer> startBeast(FrameHub& hub, const ServeLimits& limits) {
    return std::make_unique<BeastServer>(hub, limits);
}

}  // namespace httpbench
