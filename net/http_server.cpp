#include "net/http_server.h"

#include "common/error.h"
#include "net/join_limiter.h"

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/asio/thread_pool.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>
#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <list>
#include <mutex>
#include <thread>
#include <unordered_map>

namespace skinlab::net {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
using tcp = asio::ip::tcp;

HttpResponse jsonResponse(int status, const nlohmann::json& body) {
    HttpResponse res;
    res.status = status;
    res.contentType = "application/json";
    res.headers.emplace_back("Cache-Control", "no-store");
    res.body = body.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    return res;
}

namespace {

bool equalsIgnoringCase(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i])))
            return false;
    return true;
}

std::string errorBody(const std::string& message) {
    return nlohmann::json{{"error", message}}.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

} // namespace

std::optional<std::string> percentDecode(std::string_view text) {
    std::string out;
    out.reserve(text.size());
    for (std::size_t i = 0; i < text.size(); ++i) {
        if (text[i] != '%') {
            out += text[i];
            continue;
        }
        if (i + 2 >= text.size() || !std::isxdigit(static_cast<unsigned char>(text[i + 1])) ||
            !std::isxdigit(static_cast<unsigned char>(text[i + 2])))
            return std::nullopt;
        out += static_cast<char>(std::stoi(std::string(text.substr(i + 1, 2)), nullptr, 16));
        i += 2;
    }
    return out;
}

std::string HttpRequest::header(std::string_view name) const {
    for (const auto& [key, value] : headers)
        if (equalsIgnoringCase(key, name)) return value;
    return "";
}

std::size_t HttpRequest::headerCount(std::string_view name) const {
    std::size_t n = 0;
    for (const auto& [key, value] : headers) n += equalsIgnoringCase(key, name) ? 1 : 0;
    return n;
}

std::optional<std::string> HttpRequest::queryParameter(std::string_view name) const {
    std::string_view rest = query;
    while (!rest.empty()) {
        const std::size_t amp = rest.find('&');
        const std::string_view pair = rest.substr(0, amp);
        rest = amp == std::string_view::npos ? std::string_view() : rest.substr(amp + 1);
        const std::size_t eq = pair.find('=');
        const auto key = percentDecode(pair.substr(0, eq));
        if (!key || *key != name) continue;
        if (eq == std::string_view::npos) return std::string();
        auto value = percentDecode(pair.substr(eq + 1));
        return value ? value : std::optional<std::string>(std::string());
    }
    return std::nullopt;
}

namespace {
class Connection;
} // namespace

// Members in this order: destroying `io` destroys the connections still queued on it, which release their
// per-client counts (declared before it); the worker pool is joined first.
struct HttpServer::State {
    HttpHandler handler;
    HttpLimits limits;
    std::mutex perClientMutex;
    std::unordered_map<std::string, int> perClient; // by client network (clientNetwork())
    std::atomic<int> open{0};
    bool acceptPaused = false; // every slot in use: new connections wait in the listen backlog (perClientMutex)
    bool stopped = false;      // stop() was called: accepting never resumes (perClientMutex)
    // Connections waiting for a request (kept-alive ones between requests, new ones before their first byte), the
    // longest waiting first: the ones closed to keep the reserve free for newcomers.
    std::mutex idleMutex;
    std::list<Connection*> idle;
    std::atomic<bool> runningFlag{false};
    asio::io_context io;
    std::optional<asio::executor_work_guard<asio::io_context::executor_type>> work;
    tcp::acceptor acceptor{io};
    asio::thread_pool workers;

    State(HttpHandler h, HttpLimits l)
        : handler(std::move(h)), limits(l), workers(static_cast<std::size_t>(std::max(1, l.workerThreads))) {}

    void accept();
    void onAccept(tcp::socket socket);
    int reserve() const {
        return limits.reserveConnections >= 0 ? limits.reserveConnections : std::max(8, limits.maxConnections / 20);
    }
    // Closes a connection waiting for a request, one of those waiting longest (see there); false when none waits.
    bool closeLongestIdle();
    // Counts a new connection from `address` (its network); false when the client's network has its cap of
    // connections (nothing counted then).
    bool admit(const std::string& address) {
        std::lock_guard lock(perClientMutex);
        if (std::find(limits.uncappedClients.begin(), limits.uncappedClients.end(), address) !=
            limits.uncappedClients.end()) {
            ++open; // a trusted proxy carries many clients; they are counted per forwarded address by the handler
            return true;
        }
        const std::string network = clientNetwork(address, limits.clientIpv6Prefix);
        int& n = perClient[network];
        if (n >= limits.connectionsPerClient) {
            if (n == 0) perClient.erase(network);
            return false;
        }
        ++n;
        ++open;
        return true;
    }
    void release(const std::string& address) {
        bool resume = false;
        {
            std::lock_guard lock(perClientMutex);
            if (std::find(limits.uncappedClients.begin(), limits.uncappedClients.end(), address) ==
                limits.uncappedClients.end()) {
                auto it = perClient.find(clientNetwork(address, limits.clientIpv6Prefix));
                if (it != perClient.end() && --it->second <= 0) perClient.erase(it);
            }
            --open;
            resume = acceptPaused && !stopped && open.load() < limits.maxConnections;
            if (resume) acceptPaused = false;
        }
        if (resume) asio::post(acceptor.get_executor(), [this] { accept(); });
    }
};

namespace {

class Connection : public std::enable_shared_from_this<Connection> {
public:
    Connection(tcp::socket socket, HttpServer::State* state, std::string address)
        : stream_(std::move(socket)), state_(state), address_(std::move(address)),
          network_(clientNetwork(address_, state_->limits.clientIpv6Prefix)),
          buffer_(state_->limits.headerBytes + 4096), timer_(stream_.get_executor()) {}
    ~Connection() {
        leaveIdle();
        state_->release(address_);
    }

    void start() {
        asio::dispatch(stream_.get_executor(), [self = shared_from_this()] { self->readRequest(); });
    }

private:
    void readRequest() {
        parser_.emplace();
        parser_->header_limit(static_cast<std::uint32_t>(state_->limits.headerBytes));
        parser_->body_limit(state_->limits.bodyBytes);
        if (buffer_.size() == 0) {
            // Idle: wait for the first byte of the next request under the (long) keep-alive deadline — or until a
            // newcomer needs the slot (State::closeLongestIdle).
            stream_.expires_after(state_->limits.idleTimeout);
            enterIdle();
            stream_.async_read_some(buffer_.prepare(1024),
                                    [self = shared_from_this()](beast::error_code ec, std::size_t n) {
                                        const bool evicted = !self->leaveIdle();
                                        if (ec || evicted) return self->close();
                                        self->buffer_.commit(n);
                                        self->readRest();
                                    });
            return;
        }
        readRest();
    }

    void readRest() {
        // From the first byte on, the whole request must arrive within requestTimeout (slow headers or bodies
        // cannot hold a connection for long). The timer cancels the read, which is then answered 408.
        stream_.expires_never();
        timedOut_ = false;
        timer_.expires_after(state_->limits.requestTimeout);
        timer_.async_wait([self = shared_from_this()](beast::error_code ec) {
            if (ec) return;
            self->timedOut_ = true;
            beast::error_code ignored;
            self->stream_.socket().cancel(ignored);
        });
        http::async_read(stream_, buffer_, *parser_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
            self->timer_.cancel();
            self->onRead(ec);
        });
    }

    void onRead(beast::error_code ec) {
        if (timedOut_ && ec) return fail(408, "request not received in time");
        if (ec == http::error::body_limit)
            return fail(413, "request body too large (limit " + std::to_string(state_->limits.bodyBytes) + " bytes)");
        if (ec == http::error::header_limit || ec == http::error::buffer_overflow)
            return fail(431,
                        "request header too large (limit " + std::to_string(state_->limits.headerBytes) + " bytes)");
        if (ec == http::error::end_of_stream || ec == asio::error::eof || ec == asio::error::connection_reset ||
            ec == asio::error::operation_aborted || ec == http::error::partial_message)
            return close();
        if (ec) return fail(400, "malformed HTTP request (" + ec.message() + ")");

        http::request<http::string_body> message = parser_->release();
        // Only "chunked" is a transfer coding this server decodes. A request with any other (identity, gzip,
        // "chunked, identity": the body's length is then unknown, RFC 9112 §6.3) is refused and the connection
        // closed, never read as an empty body with the rest taken for the next request (request smuggling).
        if (message.count(http::field::transfer_encoding) > 0) {
            std::string codings;
            for (const auto& field : message)
                if (field.name() == http::field::transfer_encoding)
                    codings += (codings.empty() ? "" : ",") + std::string(field.value());
            std::string bare;
            for (char c : codings)
                if (c != ' ' && c != '\t') bare += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
            if (bare != "chunked") return fail(501, "Transfer-Encoding: only chunked is supported");
        }
        auto request = std::make_shared<HttpRequest>();
        request->method = std::string(message.method_string());
        const bool head = message.method() == http::verb::head;
        if (head) request->method = "GET";
        request->target = std::string(message.target());
        const std::size_t question = request->target.find('?');
        request->path = request->target.substr(0, question);
        if (question != std::string::npos) request->query = request->target.substr(question + 1);
        for (const auto& field : message) {
            std::string name(field.name_string());
            for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
            request->headers.emplace_back(std::move(name), std::string(field.value()));
        }
        request->body = std::move(message.body());
        request->clientAddress = address_;
        const bool keepAlive = message.keep_alive();
        const unsigned version = message.version();
        // The handler may block (SQLite, fsync): it runs on a worker, never on an I/O thread.
        stream_.expires_never();
        asio::post(state_->workers, [self = shared_from_this(), request, keepAlive, version, head] {
            HttpResponse response;
            try {
                response = self->state_->handler(*request);
            } catch (const std::exception& e) {
                spdlog::error("{} {}: {}", request->method, request->path, e.what());
                response = HttpResponse{500, "application/json", {}, errorBody("internal error")};
            }
            asio::post(self->stream_.get_executor(),
                       [self, response = std::move(response), keepAlive, version, head]() mutable {
                           self->write(std::move(response), keepAlive, version, head);
                       });
        });
    }

    void fail(int status, const std::string& message) {
        spdlog::debug("{}: {} {}", address_, status, message);
        failing_ = true;
        write(HttpResponse{status, "application/json", {}, errorBody(message)}, false, 11, false);
    }

    // After an error answer to a request that may still be arriving (a body over the limit): stop sending, then
    // read and discard what the client still sends — up to kDrainBytes for kDrainTime — before closing, so the
    // client reads the answer instead of a reset. Nothing of it is kept.
    static constexpr std::size_t kDrainBytes = 4 << 20;
    static constexpr std::chrono::seconds kDrainTime{2};
    void drain() {
        beast::error_code ignored;
        stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
        drainBuffer_ = std::make_unique<char[]>(16384);
        stream_.expires_after(kDrainTime);
        drainSome();
    }
    void drainSome() {
        stream_.async_read_some(asio::buffer(drainBuffer_.get(), 16384),
                                [self = shared_from_this()](beast::error_code ec, std::size_t n) {
                                    self->drained_ += n;
                                    if (ec || self->drained_ >= kDrainBytes) return self->close();
                                    self->drainSome();
                                });
    }

    void write(HttpResponse response, bool keepAlive, unsigned version, bool head) {
        if (response.streamBody) return writeStreamed(std::move(response), keepAlive, version, head);
        // The body is written from a shared buffer: a stimulus image held in memory is never copied per request.
        std::shared_ptr<const std::string> bytes =
            response.sharedBody ? response.sharedBody : std::make_shared<const std::string>(std::move(response.body));
        auto message = std::make_shared<http::response<http::span_body<const char>>>(
            static_cast<http::status>(response.status), version);
        message->set(http::field::server, "skinlab");
        if (!response.contentType.empty()) message->set(http::field::content_type, response.contentType);
        for (const auto& [name, value] : response.headers) message->insert(name, value);
        const std::size_t length = bytes->size();
        if (!head) message->body() = beast::span<const char>(bytes->data(), bytes->size());
        message->keep_alive(keepAlive);
        message->prepare_payload();
        if (head) message->content_length(length);
        stream_.expires_after(state_->limits.writeTimeout);
        http::async_write(stream_, *message,
                          [self = shared_from_this(), message, bytes, keepAlive](beast::error_code ec, std::size_t) {
                              if (!ec && self->failing_) return self->drain();
                              if (ec || !keepAlive) return self->close();
                              self->readRequest();
                          });
    }

    // A body produced piece by piece (HttpResponse::streamBody): the header, then one piece at a time — produced on
    // a worker (it may read SQLite), written here, and only then the next — so one piece is held at a time.
    using Pieces = std::shared_ptr<std::function<std::string()>>;
    void writeStreamed(HttpResponse response, bool keepAlive, unsigned version, bool head) {
        auto header =
            std::make_shared<http::response<http::empty_body>>(static_cast<http::status>(response.status), version);
        header->set(http::field::server, "skinlab");
        if (!response.contentType.empty()) header->set(http::field::content_type, response.contentType);
        for (const auto& [name, value] : response.headers) header->insert(name, value);
        const bool chunked = version >= 11; // HTTP/1.0 has no chunks: the body ends with the connection
        keepAlive = keepAlive && chunked;
        header->keep_alive(keepAlive);
        if (chunked) header->chunked(true);
        auto serializer = std::make_shared<http::response_serializer<http::empty_body>>(*header);
        auto pieces = std::make_shared<std::function<std::string()>>(std::move(response.streamBody));
        stream_.expires_after(state_->limits.writeTimeout);
        http::async_write_header(stream_, *serializer,
                                 [self = shared_from_this(), header, serializer, pieces, keepAlive, chunked,
                                  head](beast::error_code ec, std::size_t) {
                                     if (ec || (head && !keepAlive)) return self->close();
                                     if (head) return self->readRequest();
                                     self->producePiece(pieces, keepAlive, chunked);
                                 });
    }
    void producePiece(const Pieces& pieces, bool keepAlive, bool chunked) {
        asio::post(state_->workers, [self = shared_from_this(), pieces, keepAlive, chunked] {
            auto piece = std::make_shared<std::string>();
            bool failed = false;
            try {
                *piece = (*pieces)();
            } catch (const std::exception& e) {
                spdlog::error("{}: a streamed answer failed: {}", self->address_, e.what());
                failed = true;
            }
            asio::post(self->stream_.get_executor(), [self, pieces, piece, keepAlive, chunked, failed] {
                self->writePiece(pieces, piece, keepAlive, chunked, failed);
            });
        });
    }
    void writePiece(const Pieces& pieces, const std::shared_ptr<std::string>& piece, bool keepAlive, bool chunked,
                    bool failed) {
        if (failed || (piece->empty() && !chunked)) return close();
        stream_.expires_after(state_->limits.writeTimeout);
        if (piece->empty()) {
            return asio::async_write(stream_, http::make_chunk_last(),
                                     [self = shared_from_this(), keepAlive](beast::error_code ec, std::size_t) {
                                         if (ec || !keepAlive) return self->close();
                                         self->readRequest();
                                     });
        }
        auto next = [self = shared_from_this(), pieces, piece, keepAlive, chunked](beast::error_code ec, std::size_t) {
            if (ec) return self->close();
            self->producePiece(pieces, keepAlive, chunked);
        };
        if (chunked) asio::async_write(stream_, http::make_chunk(asio::buffer(*piece)), std::move(next));
        else asio::async_write(stream_, asio::buffer(*piece), std::move(next));
    }

    void close() {
        beast::error_code ignored;
        stream_.socket().shutdown(tcp::socket::shutdown_both, ignored);
        stream_.socket().close(ignored);
    }

    // The idle list (State::idle): entered while waiting for a request, left when a byte arrives or the wait ends.
    void enterIdle() {
        std::lock_guard lock(state_->idleMutex);
        idleEntry_ = state_->idle.insert(state_->idle.end(), this);
        idle_ = true;
    }
    // False when the connection was chosen to be closed meanwhile.
    bool leaveIdle() {
        std::lock_guard lock(state_->idleMutex);
        if (idle_) state_->idle.erase(idleEntry_);
        idle_ = false;
        return !evicted_;
    }

public:
    // State::closeLongestIdle(), under idleMutex, with this connection taken off the idle list: marks it, and
    // returns it when it is still alive (it may be in its destructor, waiting for the mutex).
    std::shared_ptr<Connection> takeForClosing() {
        idle_ = false;
        evicted_ = true;
        return weak_from_this().lock();
    }
    const std::string& network() const { return network_; }
    void closeSoon() {
        asio::post(stream_.get_executor(), [self = shared_from_this()] { self->close(); });
    }

private:
    beast::tcp_stream stream_;
    HttpServer::State* state_; // outlives every connection (see State)
    std::string address_;
    std::string network_; // clientNetwork(address_)
    beast::flat_buffer buffer_;
    std::optional<http::request_parser<http::string_body>> parser_;
    asio::steady_timer timer_;
    bool timedOut_ = false;
    bool failing_ = false;
    std::unique_ptr<char[]> drainBuffer_;
    std::size_t drained_ = 0;
    std::list<Connection*>::iterator idleEntry_; // in state_->idle while idle_ (idleMutex)
    bool idle_ = false;
    bool evicted_ = false;
};

} // namespace

bool HttpServer::State::closeLongestIdle() {
    // Of the kCandidates connections idle longest, the one whose client network holds the most open connections
    // (the longest idle of those): a network flooding idle connections loses its own first, and a participant's
    // kept-alive connection is closed only when the candidates are all participants'.
    constexpr int kCandidates = 32;
    std::shared_ptr<Connection> chosen;
    {
        std::lock_guard lock(idleMutex);
        while (!idle.empty() && !chosen) {
            auto best = idle.begin();
            {
                std::lock_guard counts(perClientMutex);
                int most = -1, k = 0;
                for (auto it = idle.begin(); it != idle.end() && k < kCandidates; ++it, ++k) {
                    const auto found = perClient.find((*it)->network());
                    const int n = found == perClient.end() ? 0 : found->second;
                    if (n > most) {
                        best = it;
                        most = n;
                    }
                }
            }
            Connection* connection = *best;
            idle.erase(best);
            chosen = connection->takeForClosing();
        }
    }
    if (!chosen) return false;
    chosen->closeSoon();
    return true;
}

void HttpServer::State::accept() {
    acceptor.async_accept(asio::make_strand(io), [self = this](beast::error_code ec, tcp::socket socket) {
        if (ec == asio::error::operation_aborted || !self->acceptor.is_open()) return;
        if (!ec) {
            self->onAccept(std::move(socket));
            std::lock_guard lock(self->perClientMutex);
            // Every slot holds a connection: the next ones wait in the listen backlog until one is released.
            if (self->open.load() >= self->limits.maxConnections && !self->stopped) {
                self->acceptPaused = true;
                return;
            }
        } else if (ec == asio::error::no_descriptors) {
            spdlog::warn("out of file descriptors; connections wait in the backlog");
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
        self->accept();
    });
}

void HttpServer::State::onAccept(tcp::socket socket) {
    beast::error_code ignored;
    const auto endpoint = socket.remote_endpoint(ignored);
    std::string address = ignored ? std::string("?") : endpoint.address().to_string();
    if (!admit(address)) {
        // Over the client network's cap: a short answer, written without waiting, and the connection is closed.
        static const std::string refused =
            "HTTP/1.1 429 Too Many Requests\r\nContent-Type: application/json\r\nConnection: close\r\n"
            "Retry-After: 5\r\nContent-Length: 42\r\n\r\n{\"error\":\"too many connections from here\"}";
        socket.non_blocking(true, ignored);
        socket.write_some(asio::buffer(refused), ignored);
        socket.shutdown(tcp::socket::shutdown_both, ignored);
        socket.close(ignored);
        return;
    }
    // In the reserve: the connection idle longest makes room (its client reconnects when it needs to, as a browser
    // does after a keep-alive timeout), so idle connections cannot keep newcomers out.
    if (open.load() > limits.maxConnections - reserve()) closeLongestIdle();
    socket.set_option(tcp::no_delay(true), ignored);
    std::make_shared<Connection>(std::move(socket), this, std::move(address))->start();
}

HttpServer::HttpServer(HttpHandler handler, HttpLimits limits)
    : state_(std::make_unique<State>(std::move(handler), limits)) {
    // Each connection is a file descriptor: raise the soft limit to the hard one, and keep the cap below it.
    rlimit files{};
    if (::getrlimit(RLIMIT_NOFILE, &files) == 0) {
        if (files.rlim_cur < files.rlim_max) {
            files.rlim_cur = files.rlim_max;
            ::setrlimit(RLIMIT_NOFILE, &files);
            ::getrlimit(RLIMIT_NOFILE, &files);
        }
        if (files.rlim_cur != RLIM_INFINITY)
            state_->limits.maxConnections =
                std::min<int>(state_->limits.maxConnections, std::max<int>(16, static_cast<int>(files.rlim_cur) - 64));
    }
}

HttpServer::~HttpServer() {
    stop();
    state_->workers.join();
}

int HttpServer::bind(const std::string& host, int port) {
    beast::error_code ec;
    const auto address = asio::ip::make_address(host, ec);
    if (ec) throw InputError("--host: \"" + host + "\" is not an IP address");
    const tcp::endpoint endpoint(address, static_cast<unsigned short>(port));
    auto& acceptor = state_->acceptor;
    acceptor.open(endpoint.protocol(), ec);
    if (!ec) acceptor.set_option(asio::socket_base::reuse_address(true), ec);
    if (!ec) acceptor.bind(endpoint, ec);
    if (!ec) acceptor.listen(asio::socket_base::max_listen_connections, ec);
    if (ec)
        throw InputError("--host/--port: cannot listen on " + host + ":" + std::to_string(port) + " (" + ec.message() +
                         ")");
    return acceptor.local_endpoint().port();
}

void HttpServer::run() {
    State& s = *state_;
    s.work.emplace(asio::make_work_guard(s.io));
    s.runningFlag = true;
    s.accept();
    std::vector<std::thread> threads;
    for (int i = 1; i < std::max(1, s.limits.ioThreads); ++i) threads.emplace_back([&s] { s.io.run(); });
    s.io.run();
    for (std::thread& t : threads) t.join();
    s.runningFlag = false;
}

void HttpServer::stop() {
    State& s = *state_;
    {
        std::lock_guard lock(s.perClientMutex);
        s.stopped = true;
        s.acceptPaused = false;
    }
    asio::post(s.io, [state = state_.get()] {
        beast::error_code ignored;
        state->acceptor.close(ignored);
    });
    s.work.reset();
    s.io.stop();
}

bool HttpServer::running() const { return state_->runningFlag; }
int HttpServer::openConnections() const { return state_->open.load(); }

} // namespace skinlab::net
