// app/lab/serve/http_server.cpp -- see http_server.h. Boost.Beast (Boost 1.74, header-only).
//
// Threads and waits: an io_context run by kIoThreads threads owns every connection, each an
// asynchronous session on a strand of its own; an io thread never blocks on the LiveSession
// beyond its short locks (frameAt, logYaml, timelineJson, pairHistoryJson, the newest frame).
// The two calls that wait are taken off the io threads:
//   - a long-poll (?after=V) is a timer of 2 s on the connection's strand; FrameWaiters' one
//     thread waits on the session for every new picture and cancels (through the strand) the
//     timers of those waiting past an older version, so any number of long-polls hold no thread;
//   - a command (LiveSession::command waits for the next frame boundary) runs on a pool of
//     kCommandThreads threads, which start writing the answer (the connection idle meanwhile,
//     so the strand is not needed to start it; the write completes on the strand); at most
//     kMaxCommandsWaiting are handed to the pool at once, more are "busy" (429).
// Deadlines: reading a request (its wait, header and body) has 5 s from its start, however often
// bytes trickle in; writing an answer has 5 s. A connection past either is closed.
#include "serve/http_server.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <boost/asio/dispatch.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/asio/thread_pool.hpp>
#include <boost/asio/write.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <charconv>
#include <chrono>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <thread>
#include <vector>

#include "serve/frame_waiters.h"
#include "serve/live_session.h"

namespace app {

// Named, not anonymous: HttpServer::Impl holds a Shared. Nothing outside this file uses it.
namespace http_detail {

namespace beast = boost::beast;
namespace http = beast::http;
namespace net = boost::asio;
using tcp = net::ip::tcp;

constexpr std::size_t kMaxRequestBytes = 64 * 1024;
constexpr auto kIoTimeout = std::chrono::seconds(5);
constexpr auto kLongPoll = std::chrono::seconds(2);
constexpr int kIoThreads = 2;
constexpr int kCommandThreads = 8;
constexpr int kMaxCommandsWaiting = 64;

using Response = http::response<http::string_body>;

// What every connection shares.
struct Shared {
    LiveSession& session;
    const std::string page;
    FrameWaiters waiters;
    net::thread_pool commands{kCommandThreads};
    std::atomic<int> commands_waiting{0};

    Shared(LiveSession& s, std::string p) : session(s), page(std::move(p)), waiters(s) {}
};

// %XX decoded, and '+' as a space in a query (what browsers and urllib encode).
std::string decodeUrl(std::string_view text, bool plus_is_space) {
    std::string out;
    out.reserve(text.size());
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        unsigned v = 0;
        if (c == '%' && i + 2 < text.size() &&
            std::from_chars(text.data() + i + 1, text.data() + i + 3, v, 16).ptr ==
                text.data() + i + 3) {
            out += char(v);
            i += 2;
        } else if (c == '+' && plus_is_space) {
            out += ' ';
        } else {
            out += c;
        }
    }
    return out;
}

// The query's parameters, each decoded; a repeated name keeps its first value.
std::multimap<std::string, std::string> parseQuery(std::string_view query) {
    std::multimap<std::string, std::string> params;
    while (!query.empty()) {
        const std::size_t amp = query.find('&');
        const std::string_view item = query.substr(0, amp);
        query = amp == std::string_view::npos ? std::string_view() : query.substr(amp + 1);
        if (item.empty()) continue;
        const std::size_t eq = item.find('=');
        params.emplace(
            decodeUrl(item.substr(0, eq), true),
            eq == std::string_view::npos ? std::string() : decodeUrl(item.substr(eq + 1), true));
    }
    return params;
}

void setBody(Response& res, http::status status, const char* type, std::string body) {
    res.result(status);
    res.set(http::field::cache_control, "no-store");
    res.set(http::field::content_type, type);
    res.body() = std::move(body);
}

void jsonAnswer(Response& res, http::status status, const nlohmann::ordered_json& body) {
    setBody(res, status, "application/json", body.dump());
}

void errorAnswer(Response& res, http::status status, const std::string& what) {
    jsonAnswer(res, status, {{"ok", false}, {"error", what}});
}

// One connection: requests read, answered and written in turn on its strand; kept alive while
// the client wants it and the request was read whole.
class Connection : public std::enable_shared_from_this<Connection> {
public:
    Connection(tcp::socket&& socket, Shared& shared)
        : stream_(std::move(socket)), timer_(stream_.get_executor()), shared_(shared) {}

    void start() {
        net::dispatch(stream_.get_executor(),
                      beast::bind_front_handler(&Connection::readRequest, shared_from_this()));
    }

private:
    void readRequest() {
        parser_.emplace();
        parser_->body_limit(kMaxRequestBytes);
        res_.emplace();
        // One deadline for the whole request from the moment the connection waits for it: a
        // client trickling a byte now and then is dropped at it all the same.
        deadline_ = std::chrono::steady_clock::now() + kIoTimeout;
        stream_.expires_at(deadline_);
        http::async_read_header(
            stream_, buffer_, *parser_,
            beast::bind_front_handler(&Connection::onHeader, shared_from_this()));
    }

    void onHeader(beast::error_code ec, std::size_t) {
        if (ec) return readFailed(ec);
        if (parser_->is_done()) return answer();
        // curl asks before sending a body; cpp-httplib said yes, so does this.
        if (beast::iequals(parser_->get()[http::field::expect], "100-continue")) {
            static constexpr std::string_view kContinue = "HTTP/1.1 100 Continue\r\n\r\n";
            stream_.expires_at(deadline_);
            net::async_write(stream_, net::buffer(kContinue.data(), kContinue.size()),
                             [self = shared_from_this()](beast::error_code e, std::size_t) {
                                 if (e) return self->close();
                                 self->readBody();
                             });
            return;
        }
        readBody();
    }

    void readBody() {
        stream_.expires_at(deadline_);
        http::async_read(stream_, buffer_, *parser_,
                         [self = shared_from_this()](beast::error_code ec, std::size_t) {
                             if (ec) return self->readFailed(ec);
                             self->answer();
                         });
    }

    void readFailed(beast::error_code ec) {
        if (ec == http::error::body_limit) {
            errorAnswer(*res_, http::status::payload_too_large, "request larger than 64 KiB");
            return send(false);
        }
        // Gone, silent or too slow (the stream closed the socket at the deadline): nothing to say.
        if (ec == http::error::end_of_stream || ec == beast::error::timeout ||
            ec == net::error::eof || ec == net::error::operation_aborted ||
            ec == net::error::connection_reset || !parser_->got_some()) {
            return close();
        }
        errorAnswer(*res_, http::status::bad_request, "bad request: " + ec.message());
        send(false);
    }

    // Routes the request read; either writes the answer or starts what will.
    void answer() {
        stream_.expires_never();
        try {
            route();
        } catch (const std::exception& e) {
            res_.emplace();
            errorAnswer(*res_, http::status::internal_server_error,
                        std::string("internal error: ") + e.what());
            send();
        }
    }

    void route() {
        auto& req = parser_->get();
        const beast::string_view target = req.target();
        const std::size_t q = target.find('?');
        const std::string path =
            decodeUrl(std::string_view(target.data(), std::min(q, target.size())), false);
        params_ = q == beast::string_view::npos
                      ? std::multimap<std::string, std::string>()
                      : parseQuery(std::string_view(target.data() + q + 1, target.size() - q - 1));
        const bool get = req.method() == http::verb::get || req.method() == http::verb::head;
        LiveSession& s = shared_.session;
        if (get && path == "/") {
            setBody(*res_, http::status::ok, "text/html; charset=utf-8", shared_.page);
        } else if (get && path == "/favicon.ico") {
            // Browsers ask for an icon; there is none, and no error is logged for it.
            res_->result(http::status::no_content);
        } else if (req.method() == http::verb::post && path == "/api/command") {
            return command();
        } else if (get && (path == "/api/frame.png" || path == "/api/state.json")) {
            return pickFrame(path == "/api/frame.png");
        } else if (get && path == "/api/session.yaml") {
            setBody(*res_, http::status::ok, "text/yaml; charset=utf-8", s.logYaml());
        } else if (get && path == "/api/timeline.json") {
            std::optional<std::uint64_t> from;
            if (unsignedParam("from", from)) {
                setBody(*res_, http::status::ok, "application/json",
                        s.timelineJson(std::size_t(from.value_or(0))));
            }
        } else if (get && path == "/api/pair.json") {
            const std::string* a = param("a");
            const std::string* b = param("b");
            if (a == nullptr || b == nullptr) {
                errorAnswer(*res_, http::status::bad_request,
                            "pair.json: give the two bodies' names, ?a=NAME&b=NAME");
            } else {
                try {
                    setBody(*res_, http::status::ok, "application/json", s.pairHistoryJson(*a, *b));
                } catch (const std::invalid_argument& e) {
                    errorAnswer(*res_, http::status::bad_request,
                                std::string("pair.json: ") + e.what());
                }
            }
        } else {
            errorAnswer(*res_, http::status::not_found,
                        "no such page: " + std::string(req.method_string()) + " " + path);
        }
        send();
    }

    // The first value given to the query parameter `name`, or null.
    const std::string* param(const std::string& name) const {
        const auto it = params_.lower_bound(name);
        return it == params_.end() || it->first != name ? nullptr : &it->second;
    }

    // A query parameter that must be an unsigned integer, or none; false when it is malformed
    // (the answer is then set).
    bool unsignedParam(const char* name, std::optional<std::uint64_t>& value) {
        const std::string* given = param(name);
        if (given == nullptr) return true;
        const std::string& text = *given;
        std::uint64_t v = 0;
        const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
        if (ec != std::errc() || end != text.data() + text.size() || text.empty()) {
            errorAnswer(
                *res_, http::status::bad_request,
                std::string("query parameter '") + name + "': expected a whole number >= 0");
            return false;
        }
        value = v;
        return true;
    }

    void command() {
        if (++shared_.commands_waiting > kMaxCommandsWaiting) {
            --shared_.commands_waiting;
            const auto f = shared_.session.frame();
            jsonAnswer(*res_, http::status::too_many_requests,
                       {{"ok", false},
                        {"error", "busy: " + std::to_string(kMaxCommandsWaiting) +
                                      " commands are waiting for the next frame; send again "
                                      "later"},
                        {"frame", f ? f->frame : 0}});
            return send();
        }
        net::post(shared_.commands,
                  [self = shared_from_this(), body = std::move(parser_->get().body())] {
                      LiveAnswer a = self->shared_.session.command(body);
                      --self->shared_.commands_waiting;
                      // Written from this thread, without a hop back to the strand: the
                      // connection has no other operation in flight while its command waits
                      // (nothing reads, no timer runs), and the write completes on the strand.
                      self->commandAnswered(a);
                  });
    }

    void commandAnswered(const LiveAnswer& a) {
        if (a.ok) {
            jsonAnswer(*res_, http::status::ok,
                       {{"ok", true}, {"at_frame", a.at_frame}, {"frame", a.frame}});
        } else {
            const http::status status = a.error.rfind("busy:", 0) == 0
                                            ? http::status::too_many_requests
                                        : a.error.rfind("the session has stopped", 0) == 0
                                            ? http::status::service_unavailable
                                            : http::status::bad_request;
            jsonAnswer(*res_, status, {{"ok", false}, {"error", a.error}, {"frame", a.frame}});
        }
        send();
    }

    // The picture of ?version while it is held, else the newest, or (?after) the first newer
    // than that version within the long-poll, else the newest at its end.
    void pickFrame(bool png) {
        std::optional<std::uint64_t> after, version;
        if (!unsignedParam("after", after) || !unsignedParam("version", version)) return send();
        if (version) {
            if (auto f = shared_.session.frameAt(*version)) return frameAnswer(f, png);
        }
        if (!after) return frameAnswer(shared_.session.frame(), png);
        const std::uint64_t wait = ++wait_id_;
        std::weak_ptr<Connection> weak = weak_from_this();
        const bool waiting = shared_.waiters.wakeWhenNewer(*after, [weak, wait] {
            if (auto self = weak.lock()) {
                net::post(self->stream_.get_executor(), [self, wait] {
                    if (self->wait_id_ == wait) self->timer_.cancel();
                });
            }
        });
        if (!waiting) return frameAnswer(shared_.session.frame(), png);
        timer_.expires_after(kLongPoll);
        timer_.async_wait([self = shared_from_this(), png](beast::error_code) {
            ++self->wait_id_;  // a wake still queued for this wait no longer cancels anything
            self->frameAnswer(self->shared_.session.frame(), png);
        });
    }

    void frameAnswer(const std::shared_ptr<const LiveFrame>& f, bool png) {
        if (!f) {
            errorAnswer(*res_, http::status::service_unavailable, "no picture yet");
        } else if (png) {
            setBody(*res_, http::status::ok, "image/png", f->png);
            res_->set("X-Cdlab-Frame", std::to_string(f->frame));
            res_->set("X-Cdlab-Version", std::to_string(f->version));
        } else {
            setBody(*res_, http::status::ok, "application/json", f->state);
        }
        send();
    }

    // Writes res_; `keep_alive` false when the request was not read whole (the connection is
    // then closed after the answer).
    void send(bool keep_alive = true) {
        const auto& req = parser_->get();
        res_->version(req.version() == 10 ? 10 : 11);
        res_->keep_alive(keep_alive && req.keep_alive());
        if (req.method() == http::verb::head) {
            const std::size_t size = res_->body().size();
            res_->body().clear();
            res_->content_length(size);
        } else {
            res_->prepare_payload();
        }
        stream_.expires_after(kIoTimeout);
        http::async_write(stream_, *res_,
                          [self = shared_from_this()](beast::error_code ec, std::size_t) {
                              if (ec) return self->close();
                              if (!self->res_->keep_alive()) return self->close();
                              self->readRequest();
                          });
    }

    // Closes after the answer is out: the sending side first, then whatever the client still
    // sends (a body refused unread) is read away until it hangs up or the deadline, so that the
    // close does not reset the connection under an answer the client has yet to read.
    void close() {
        beast::error_code ec;
        stream_.socket().shutdown(tcp::socket::shutdown_send, ec);
        if (ec) return stream_.close();
        stream_.expires_after(kIoTimeout);
        stream_.async_read_some(net::buffer(drain_),
                                [self = shared_from_this()](beast::error_code e, std::size_t) {
                                    if (e) return self->stream_.close();
                                    self->drain();
                                });
    }

    void drain() {
        stream_.async_read_some(net::buffer(drain_),
                                [self = shared_from_this()](beast::error_code e, std::size_t) {
                                    if (e) return self->stream_.close();
                                    self->drain();
                                });
    }

    beast::tcp_stream stream_;
    net::steady_timer timer_;  ///< the long-poll
    Shared& shared_;
    beast::flat_buffer buffer_;
    std::optional<http::request_parser<http::string_body>> parser_;
    std::optional<Response> res_;
    std::multimap<std::string, std::string> params_;
    std::chrono::steady_clock::time_point deadline_;
    std::uint64_t wait_id_ = 0;
    std::array<char, 4096> drain_{};
};

}  // namespace http_detail

using namespace http_detail;

struct HttpServer::Impl {
    net::io_context ioc{kIoThreads};
    Shared shared;
    tcp::acceptor acceptor{net::make_strand(ioc)};
    net::steady_timer accept_pause{acceptor.get_executor()};

    Impl(LiveSession& session, std::string page) : shared(session, std::move(page)) {}

    void accept() {
        acceptor.async_accept(
            net::make_strand(ioc), [this](beast::error_code ec, tcp::socket socket) {
                if (ec == net::error::operation_aborted) return;
                if (ec) {
                    // Out of descriptors, say: try again shortly instead of spinning.
                    accept_pause.expires_after(std::chrono::milliseconds(50));
                    accept_pause.async_wait([this](beast::error_code) { accept(); });
                    return;
                }
                // Small answers go out at once: no Nagle delay behind the client's delayed ACK.
                socket.set_option(tcp::no_delay(true), ec);
                std::make_shared<Connection>(std::move(socket), shared)->start();
                accept();
            });
    }
};

HttpServer::HttpServer(LiveSession& session, std::string page)
    : impl_(std::make_unique<Impl>(session, std::move(page))) {}

HttpServer::~HttpServer() {
    impl_->ioc.stop();
    impl_->shared.waiters.stop();
    impl_->shared.commands.join();
}

int HttpServer::listen(const std::string& host, int port) {
    beast::error_code ec;
    tcp::resolver resolver(impl_->ioc);
    const auto endpoints = resolver.resolve(
        host, std::to_string(port), tcp::resolver::passive | tcp::resolver::numeric_service, ec);
    if (ec) return 0;
    tcp::acceptor& a = impl_->acceptor;
    for (const auto& entry : endpoints) {
        const tcp::endpoint endpoint = entry.endpoint();
        a.open(endpoint.protocol(), ec);
        if (!ec) a.set_option(net::socket_base::reuse_address(true), ec);
        if (!ec) a.bind(endpoint, ec);
        if (!ec) a.listen(net::socket_base::max_listen_connections, ec);
        if (!ec) break;
        beast::error_code ignored;
        a.close(ignored);
    }
    if (!a.is_open()) return 0;
    const int bound = a.local_endpoint(ec).port();
    if (ec) return 0;
    impl_->accept();
    return bound;
}

void HttpServer::run() {
    std::vector<std::thread> others;
    for (int i = 1; i < kIoThreads; ++i) others.emplace_back([this] { impl_->ioc.run(); });
    impl_->ioc.run();
    for (std::thread& t : others) t.join();
}

void HttpServer::stop() { impl_->ioc.stop(); }

}  // namespace app
