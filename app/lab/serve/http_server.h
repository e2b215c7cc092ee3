// app/lab/serve/http_server.h -- the HTTP layer of `cdlab serve` (serve_http.h lists the
// endpoints): the page and the API over one LiveSession, on Boost.Beast's asynchronous sessions.
// No thread is held by a connection, idle or waiting: a client holding many connections open
// slows no one else, and each is dropped at its 5 s deadline.
#pragma once

#include <memory>
#include <string>

namespace app {

class LiveSession;

class HttpServer {
public:
    /// Serves `page` at / and the API over `session`, which must outlive this object.
    HttpServer(LiveSession& session, std::string page);
    /// Joins every thread; commands still waiting on the session are awaited (stop the session
    /// first so that they are refused at once).
    ~HttpServer();
    HttpServer(const HttpServer&) = delete;
    HttpServer& operator=(const HttpServer&) = delete;

    /// Listens on `host` (an address or a name, the first of its addresses that binds) and
    /// `port` (0: any free port). Returns the port, or 0 when it cannot listen.
    int listen(const std::string& host, int port);

    /// Serves on this thread and the pool's others until stop(); returns once they are out.
    void run();

    /// Makes run() return; from any thread (a signal's waiter), before or during run().
    void stop();

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace app
