// tests/bench/http_servers/http_client.cpp -- see http_client.h.
// The socket is non-blocking and every read, write and connect first polls against the
// caller's deadline: a stalled server shows up as a late or missing answer, never as a hang.
#include "http_client.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <strings.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>

namespace httpbench {

namespace {

// A header's value from a raw header block ("Name: value\r\n"), case-insensitive name.
std::string_view headerValue(std::string_view head, std::string_view name) {
    std::size_t at = head.find("\r\n");
    while (at != std::string_view::npos && at + 2 < head.size()) {
        const std::size_t start = at + 2;
        const std::size_t end = head.find("\r\n", start);
        const std::string_view line = head.substr(start, end - start);
        if (line.size() > name.size() && line[name.size()] == ':' &&
            strncasecmp(line.data(), name.data(), name.size()) == 0) {
            std::string_view value = line.substr(name.size() + 1);
            while (!value.empty() && value.front() == ' ') value.remove_prefix(1);
            return value;
        }
        at = end;
    }
    return {};
}

template <class T>
T number(std::string_view text) {
    T v = 0;
    std::from_chars(text.data(), text.data() + text.size(), v);
    return v;
}

}  // namespace

bool waitFd(int fd, short events, Clock::time_point deadline) {
    for (;;) {
        const auto left =
            std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
        if (left.count() < 0) return false;
        pollfd p{fd, events, 0};
        const int n = ::poll(&p, 1, int(left.count()) + 1);
        if (n > 0) return true;
        if (n < 0 && errno != EINTR) return false;
    }
}

int connectLoopback(int port, Clock::time_point deadline) {
    const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (fd < 0) return -1;
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(std::uint16_t(port));
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) == 0) return fd;
    int err = 0;
    socklen_t len = sizeof err;
    if (errno == EINPROGRESS && waitFd(fd, POLLOUT, deadline) &&
        ::getsockopt(fd, SOL_SOCKET, SO_ERROR, &err, &len) == 0 && err == 0) {
        return fd;
    }
    ::close(fd);
    return -1;
}

HttpConnection::~HttpConnection() { close(); }

void HttpConnection::close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    buffer_.clear();
    server_closes_ = false;
}

bool HttpConnection::open(Clock::time_point deadline) {
    fd_ = connectLoopback(port_, deadline);
    if (fd_ >= 0) ++connects_;
    return fd_ >= 0;
}

bool HttpConnection::request(std::string_view method, std::string_view target,
                             std::string_view body, Clock::time_point deadline, HttpAnswer& out) {
    std::string req;
    req.reserve(128 + body.size());
    req.append(method).append(" ").append(target).append(" HTTP/1.1\r\nHost: 127.0.0.1\r\n");
    if (!body.empty() || method == "POST") {
        req.append("Content-Type: application/json\r\nContent-Length: ")
            .append(std::to_string(body.size()))
            .append("\r\n");
    }
    req.append("\r\n").append(body);
    for (int attempt = 0; attempt < 2; ++attempt) {
        const bool reused = fd_ >= 0;
        if (!reused && !open(deadline)) return false;
        bool nothing_read = false;
        if (once(req, deadline, out, nothing_read)) return true;
        close();
        if (!(reused && nothing_read) || Clock::now() >= deadline) return false;
    }
    return false;
}

bool HttpConnection::once(const std::string& request, Clock::time_point deadline, HttpAnswer& out,
                          bool& nothing_read) {
    nothing_read = true;
    for (std::size_t sent = 0; sent < request.size();) {
        if (!waitFd(fd_, POLLOUT, deadline)) return false;
        const ssize_t n = ::send(fd_, request.data() + sent, request.size() - sent, MSG_NOSIGNAL);
        if (n < 0 && errno != EAGAIN && errno != EINTR) return false;
        if (n > 0) sent += std::size_t(n);
    }
    // Reads until the header block and then Content-Length bytes of body are in buffer_.
    std::size_t head_end = std::string::npos;
    std::size_t total = std::string::npos;
    char chunk[64 * 1024];
    for (;;) {
        if (head_end == std::string::npos) {
            head_end = buffer_.find("\r\n\r\n");
            if (head_end != std::string::npos) {
                const std::string_view head(buffer_.data(), head_end + 2);
                out.status = number<int>(head.substr(9, 3));
                total = head_end + 4 + number<std::size_t>(headerValue(head, "Content-Length"));
                out.version = number<std::uint64_t>(headerValue(head, "X-Version"));
                out.published_ns = number<std::int64_t>(headerValue(head, "X-Published-Ns"));
                const std::string_view connection = headerValue(head, "Connection");
                server_closes_ =
                    connection.size() == 5 && strncasecmp(connection.data(), "close", 5) == 0;
            }
        }
        if (total != std::string::npos && buffer_.size() >= total) break;
        if (!waitFd(fd_, POLLIN, deadline)) return false;
        const ssize_t n = ::recv(fd_, chunk, sizeof chunk, 0);
        if (n == 0) return false;
        if (n < 0) {
            if (errno == EAGAIN || errno == EINTR) continue;
            return false;
        }
        nothing_read = false;
        buffer_.append(chunk, std::size_t(n));
    }
    out.body.assign(buffer_, head_end + 4, total - head_end - 4);
    buffer_.erase(0, total);
    if (server_closes_) close();
    return true;
}

}  // namespace httpbench
