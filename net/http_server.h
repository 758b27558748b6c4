#pragma once
// An event-driven HTTP/1.1 server (Boost.Beast on Boost.Asio): a few I/O threads hold every connection
// (thousands of kept-alive browsers cost a socket and a few KiB each, not a thread), and a small pool of worker
// threads runs the handlers, which may block on SQLite and its fsync. Limits are enforced while reading, before
// anything is buffered: header size, body size (chunked bodies included, counted as they arrive), the time a
// request may take to arrive, and the number of open connections per client network (an IPv4 address, an IPv6 /64,
// as joins are counted: net/join_limiter.h). Open connections in all are bounded; the last
// `reserveConnections` slots are kept for newcomers: once they are in use, each new connection closes an idle
// connection (a kept-alive one waiting for its next request, or a new one that has sent nothing yet): of the 32 idle
// longest, the one whose client network holds the most connections. When every slot holds a connection in the middle
// of a request, new ones wait in the listen backlog until one closes. Why this design: docs/architecture.md ("Study
// server: threading model").
//
// Requests that break a limit or are not HTTP are answered here (JSON {"error": ...}) and never reach the handler:
// 400 malformed, 408 too slow, 413 body too large, 431 header too large, 429 too many connections from one client
// network, 501 a transfer coding other than chunked (the connection is closed).
#include <chrono>
#include <nlohmann/json_fwd.hpp>
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace skinlab::net {

struct HttpRequest {
    std::string method; // "GET", "POST", ... ("HEAD" is handed over as "GET"; the body is dropped)
    std::string target; // as sent: path and query
    std::string path;   // target up to '?', not decoded
    std::string query;  // after '?', not decoded
    std::vector<std::pair<std::string, std::string>> headers; // names in lower case, values as sent
    std::string body;
    std::string clientAddress; // peer IP address (StudyServer: the forwarded one behind a trusted proxy)
    std::string forwardedBy;   // the trusted proxy's address when clientAddress was forwarded by it, else ""

    // The first header of that name (case-insensitive), or "".
    std::string header(std::string_view name) const;
    std::size_t headerCount(std::string_view name) const;
    // A query parameter, percent-decoded; nullopt when absent.
    std::optional<std::string> queryParameter(std::string_view name) const;
};

struct HttpResponse {
    int status = 200;
    std::string contentType;
    std::vector<std::pair<std::string, std::string>> headers;
    std::string body;
    std::shared_ptr<const std::string> sharedBody; // when set, sent instead of `body` (not copied)
    // When set, the body is produced piece by piece instead (a large export): called on a worker thread, one call at
    // a time, each once the previous piece is written to the socket, so one piece is held at a time; "" ends the
    // body. Sent with chunked transfer coding (to an HTTP/1.0 client: until the connection closes). Should it throw,
    // the connection is closed without the last chunk, so the client sees an incomplete answer, never a short one.
    std::function<std::string()> streamBody;
};

// A JSON answer: `body` serialised (invalid UTF-8 replaced), Content-Type application/json, never cached. Every JSON
// API of skinlab's servers (study, dashboard, tune) answers through it.
HttpResponse jsonResponse(int status, const nlohmann::json& body);

using HttpHandler = std::function<HttpResponse(const HttpRequest&)>;

struct HttpLimits {
    std::size_t headerBytes = 8 * 1024;              // request line + header fields
    std::size_t bodyBytes = 16 * 1024;               // decoded body, chunked or not
    std::chrono::milliseconds requestTimeout{10000}; // from the first byte... to the whole request read
    std::chrono::milliseconds idleTimeout{30000};    // a kept-alive connection with no request
    std::chrono::milliseconds writeTimeout{30000};
    int connectionsPerClient = 64;            // open connections per client network (429 beyond)
    int clientIpv6Prefix = 64;                // an IPv6 client network: this many leading bits
    std::vector<std::string> uncappedClients; // addresses exempt from connectionsPerClient (a trusted proxy)
    int maxConnections = 20000;               // in all (bounded by the open-file limit too)
    int reserveConnections = -1;              // kept for newcomers (see above); -1 = 5 % of maxConnections, >= 8
    int ioThreads = 2;
    int workerThreads = 8; // run the handlers
};

class HttpServer {
public:
    HttpServer(HttpHandler handler, HttpLimits limits);
    ~HttpServer();
    HttpServer(const HttpServer&) = delete;
    HttpServer& operator=(const HttpServer&) = delete;

    // Binds and listens; returns the port (port 0 = any free one). Throws InputError when it cannot.
    int bind(const std::string& host, int port);
    // Serves until stop() (blocking; the calling thread is one of the I/O threads).
    void run();
    void stop();
    bool running() const;
    // Connections open now (for tests and benchmarks).
    int openConnections() const;

public:
    struct State; // internal

private:
    std::unique_ptr<State> state_;
};

// Percent-decoding of a URL component ('+' stays '+'); nullopt when an escape is malformed.
std::optional<std::string> percentDecode(std::string_view text);

} // namespace skinlab::net
