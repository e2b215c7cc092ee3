// tests/bench/http_servers/http_client.h -- the bench's client: plain HTTP/1.1 over a POSIX
// socket with keep-alive, every wait bounded by a deadline, so no server under test can hang it
// and no client library favours one server.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>

namespace httpbench {

using Clock = std::chrono::steady_clock;

struct HttpAnswer {
    int status = 0;
    std::string body;
    std::uint64_t version = 0;      ///< X-Version, 0 when absent
    std::int64_t published_ns = 0;  ///< X-Published-Ns, 0 when absent
};

/// A TCP connection to 127.0.0.1:port, opened on first use and again after the server closes it.
class HttpConnection {
public:
    explicit HttpConnection(int port) : port_(port) {}
    ~HttpConnection();
    HttpConnection(const HttpConnection&) = delete;
    HttpConnection& operator=(const HttpConnection&) = delete;

    /// One request and its answer. False on a connection error or when `deadline` passes (the
    /// connection is then closed). A kept-alive connection the server had closed before answering
    /// is reopened and the request sent once more.
    bool request(std::string_view method, std::string_view target, std::string_view body,
                 Clock::time_point deadline, HttpAnswer& out);

    /// Connections opened so far.
    int connects() const { return connects_; }

private:
    bool open(Clock::time_point deadline);
    void close();
    bool once(const std::string& request, Clock::time_point deadline, HttpAnswer& out,
              bool& nothing_read);

    int port_;
    int fd_ = -1;
    bool server_closes_ = false;
    int connects_ = 0;
    std::string buffer_;
};

/// Opens a non-blocking TCP connection to 127.0.0.1:port; -1 when it fails by `deadline`.
int connectLoopback(int port, Clock::time_point deadline);

/// Waits for `events` on fd until `deadline`; false on timeout or error.
bool waitFd(int fd, short events, Clock::time_point deadline);

}  // namespace httpbench
