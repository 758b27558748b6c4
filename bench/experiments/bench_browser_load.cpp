// Benchmark: the study server under browser-like load (docs/benchmarks.md, "Study server under browser-like load").
//
// The server is the real `skinlab study serve` in its own process (so its RSS can be read and it can be killed).
// Each simulated participant behaves like the participant page in a browser: one kept-alive connection, the
// page's request sequence (/, app.js, style.css, /api/study, /api/join, /api/session, then per trial the images it
// has not fetched yet — a browser caches them: they are immutable — and /api/response), a think time drawn from
// [MIN, MAX] ms before each answer, participants starting over a ramp. Participants come from 127.0.x.y source
// addresses, 8 per address (like a lab behind one NAT), so the per-address connection cap is exercised as deployed.
// Every request's latency is recorded; a request that gets no answer (server killed) is re-sent on a new
// connection, as the page does. At the end every acknowledged answer is checked against study.db: stored once, as
// acknowledged. --export-every-s S: a researcher downloads the JSON export (GET /api/researcher/export) every S
// seconds meanwhile, on its own connection; its requests are reported apart from the participants'. --prefill N: N
// participants who already answered every trial are written into the study before it is served (the export then
// starts at N × 24 answers). --idle-connections N: N connections that never send a request, 60 per source address
// (127.2.x.y), each reopened 100 ms after the server closes it; the participants start 10 s after them.
//
// Usage: bench_experiments_browser_load [--participants N] [--think-ms MIN:MAX] [--ramp-s S] [--slow-headers N]
//          [--chunked-floods N] [--kill-at F1,F2] [--image-kib K] [--export-every-s S] [--prefill N]
//          [--idle-connections N]
//          [--folder DIR] [--server PATH]
// Prints a summary (Markdown rows for docs/benchmarks.md).
#include "bench/bench_stats.h"
#include "common/files.h"
#include "bench_stimulus_set.h"
#include "experiments/sqlite_database.h"
#include "experiments/study_creation.h"
#include "experiments/study_store.h"

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstring>
#include <fcntl.h>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <sys/resource.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>
#include <vector>

namespace fs = std::filesystem;
namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
using tcp = asio::ip::tcp;
using json = nlohmann::json;
using Clock = std::chrono::steady_clock;
using namespace skinlab::experiments;

namespace {

struct Options {
    int participants = 1000;
    double thinkMin = 1500, thinkMax = 3000;
    double rampSeconds = 30;
    int slowHeaders = 0;
    int chunkedFloods = 0;
    std::vector<double> killAt; // fractions of all answers
    int imageKiB = 1024;
    double exportEverySeconds = 0; // 0 = no researcher export
    int prefill = 0;
    int idleConnections = 0;
    fs::path folder = fs::temp_directory_path() / "skinlab-bench-browser-load";
    std::string server = SKINLAB_CLI;
};

// Five conditions in one block: 10 pairs × 2 repetitions + 2 catch = 22 answers per participant; images are random
// bytes of the given size (the server does not decode them; the dimensions declared are the demo's 896×504, which a 1920×1080 window shows side by side).
void writeSet(const fs::path& folder, int imageKiB) {
    std::mt19937 random(1);
    skinlab::bench::writeBenchStimulusSet(folder, 5, 896, 504, [&](const std::string&) {
        std::string bytes(static_cast<std::size_t>(imageKiB) * 1024, '\0');
        for (char& c : bytes) c = static_cast<char>(random());
        return bytes;
    });
}

constexpr const char* kToken = "0123456789abcdef0123456789abcdef"; // the researcher's

// The server process.
struct Server {
    pid_t pid = -1;
    int port = 0;
    void start(const Options& o, const fs::path& db, int wantedPort) {
        int pipeFds[2];
        if (::pipe(pipeFds) != 0) throw std::runtime_error("pipe");
        pid = ::fork();
        if (pid == 0) {
            ::dup2(pipeFds[1], 1);
            ::close(pipeFds[0]);
            const int devNull = ::open("/dev/null", O_WRONLY);
            ::dup2(devNull, 2); // its log (one line per join) is not part of the measurement
            const std::string portText = std::to_string(wantedPort);
            ::execl(o.server.c_str(), o.server.c_str(), "study", "serve", db.c_str(), "--port", portText.c_str(),
                    "--token", kToken, static_cast<char*>(nullptr));
            ::_exit(127);
        }
        ::close(pipeFds[1]);
        FILE* out = ::fdopen(pipeFds[0], "r");
        char line[512];
        port = -1;
        while (std::fgets(line, sizeof line, out)) {
            int p = 0;
            if (std::sscanf(line, "serving %*s on http://127.0.0.1:%d/", &p) == 1) {
                port = p;
                break;
            }
        }
        // Keep reading (and dropping) its output in the background so it never blocks on a full pipe.
        std::thread([out] {
            char buffer[512];
            while (std::fgets(buffer, sizeof buffer, out)) {
            }
            std::fclose(out);
        }).detach();
        if (port <= 0) throw std::runtime_error("the server did not start");
    }
    long rssKiB(const char* key) const {
        std::ifstream status("/proc/" + std::to_string(pid) + "/status");
        std::string line;
        while (std::getline(status, line))
            if (line.rfind(key, 0) == 0) return std::stol(line.substr(std::strlen(key)));
        return 0;
    }
    void kill(int signal) {
        ::kill(pid, signal);
        int status = 0;
        ::waitpid(pid, &status, 0);
    }
};

struct Stats {
    std::vector<double> all, answers, slowSideNormal, images;
    int errors = 0;         // HTTP answers other than 2xx/304
    int retries = 0;        // requests re-sent after no answer
    int connectRetries = 0; // of which: no connection made (refused or timed out)
    std::map<int, int> statuses;
};

double percentile(const std::vector<double>& v, double p) { return skinlab::bench::nearestRankPercentile(v, p); }

class Participant : public std::enable_shared_from_this<Participant> {
public:
    Participant(asio::io_context& io, const Options& o, int index, int& port, Stats& stats, std::atomic<long>& answered)
        : io_(io), o_(o), index_(index), port_(port), stats_(stats), answered_(answered), timer_(io),
          random_(static_cast<unsigned>(index * 7919 + 1)) {
        source_ = "127.0." + std::to_string(1 + index / 8 / 250) + "." + std::to_string(1 + (index / 8) % 250);
        // Beast reads at most the buffer's free capacity per call (at least 512 bytes): an empty buffer reads a 1 MiB
        // image in thousands of small recvmsg calls, and one client thread serving 1,000 participants then
        // saturates its core and queues requests for seconds (measured: image p99 10.8 s while curl fetched the
        // same image in ≤ 9 ms). 64 KiB reads, as a browser's network stack does.
        buffer_.reserve(64 * 1024);
    }
    void start(double delaySeconds) {
        timer_.expires_after(std::chrono::milliseconds(static_cast<long>(delaySeconds * 1000)));
        timer_.async_wait([self = shared_from_this()](beast::error_code) { self->step(); });
    }
    std::atomic<bool> completed{false};
    std::string token;
    std::vector<std::pair<std::int64_t, std::string>> acknowledged; // (trial reference, side)

private:
    // The page's sequence, one request at a time.
    void step() {
        switch (stage_) {
        case 0:
            return send("GET", "/", "", [this](const std::string&) {
                stage_ = 1;
                step();
            });
        case 1:
            return send("GET", "/app.js", "", [this](const std::string&) {
                stage_ = 2;
                step();
            });
        case 2:
            return send("GET", "/style.css", "", [this](const std::string&) {
                stage_ = 3;
                step();
            });
        case 3:
            return send("GET", "/api/study", "", [this](const std::string&) {
                stage_ = 4;
                step();
            });
        case 4:
            return send("POST", "/api/join", json{{"join_key", "bench-" + std::to_string(index_)}}.dump(),
                        [this](const std::string& body) {
                            token = json::parse(body)["token"];
                            stage_ = 5;
                            step();
                        });
        case 5:
            return send(
                "POST", "/api/session",
                json{{"token", token}, {"viewport_width", 1920}, {"viewport_height", 1080}, {"device_pixel_ratio", 1.0}}
                    .dump(),
                [this](const std::string& body) {
                    state_ = json::parse(body);
                    session_ = state_["session"];
                    stage_ = 6;
                    step();
                });
        default: return trial();
        }
    }

    void trial() {
        if (state_["completed"].get<bool>()) {
            completed = true;
            close();
            return;
        }
        for (const char* side : {"left", "right", "reference"}) {
            const json& shown = state_["trial"][side];
            if (shown.is_object() && shown.contains("url") && fetched_.insert(shown["url"].get<std::string>()).second)
                return send("GET", shown["url"].get<std::string>(), "", [this](const std::string&) { trial(); });
        }
        std::uniform_real_distribution<double> think(o_.thinkMin, o_.thinkMax);
        timer_.expires_after(std::chrono::microseconds(static_cast<long>(think(random_) * 1000)));
        timer_.async_wait([self = shared_from_this()](beast::error_code) { self->answer(); });
    }

    void answer() {
        const std::int64_t trial = state_["trial"]["id"];
        const std::string side = random_() % 2 ? "left" : "right";
        json body{{"token", token},         {"trial", trial},          {"side", side},
                  {"session", session_},    {"response_ms", 900.0},    {"client_time", "2026-12-01T00:00:00.000Z"},
                  {"viewport_width", 1920}, {"viewport_height", 1080}, {"device_pixel_ratio", 1.0}};
        send(
            "POST", "/api/response", body.dump(),
            [this, trial, side](const std::string& reply) {
                acknowledged.emplace_back(trial, side);
                ++answered_;
                state_ = json::parse(reply);
                this->trial();
            },
            true);
    }

    void send(const std::string& method, const std::string& target, const std::string& body,
              std::function<void(const std::string&)> then, bool isAnswer = false) {
        request_ = {http::string_to_verb(method), target, 11};
        request_.set(http::field::host, "127.0.0.1:" + std::to_string(port_));
        request_.set(http::field::user_agent, "Mozilla/5.0 (bench) skinlab-browser-load");
        if (method == "POST") {
            request_.set(http::field::content_type, "application/json");
            request_.body() = body;
        }
        request_.prepare_payload();
        then_ = std::move(then);
        isAnswer_ = isAnswer;
        started_ = Clock::now();
        if (!stream_) return connect();
        write();
    }

    void connect() {
        stream_ = std::make_unique<beast::tcp_stream>(io_);
        beast::error_code ec;
        stream_->socket().open(tcp::v4(), ec);
        stream_->socket().bind(tcp::endpoint(asio::ip::make_address(source_), 0), ec);
        stream_->expires_after(std::chrono::seconds(10));
        stream_->async_connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port_)),
                               [self = shared_from_this()](beast::error_code e) {
                                   if (e) {
                                       ++self->stats_.connectRetries;
                                       return self->retry();
                                   }
                                   self->write();
                               });
    }

    void write() {
        stream_->expires_after(std::chrono::seconds(30));
        http::async_write(*stream_, request_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
            if (ec) return self->retry();
            self->response_ = {};
            self->parser_.emplace();
            self->parser_->body_limit(64u << 20);
            http::async_read(*self->stream_, self->buffer_, *self->parser_, [self](beast::error_code e, std::size_t) {
                if (e) return self->retry();
                self->done();
            });
        });
    }

    void done() {
        const double ms = std::chrono::duration<double, std::milli>(Clock::now() - started_).count();
        const auto res = parser_->release();
        const int status = res.result_int();
        ++stats_.statuses[status];
        stats_.all.push_back(ms);
        if (isAnswer_) stats_.answers.push_back(ms);
        if (std::string(request_.target()).rfind("/stimuli/", 0) == 0) stats_.images.push_back(ms);
        if (!res.keep_alive()) stream_.reset();
        if (status == 429 || status >= 500) { // the page retries these
            ++stats_.errors;
            timer_.expires_after(std::chrono::milliseconds(500));
            timer_.async_wait([self = shared_from_this()](beast::error_code) { self->resend(); });
            return;
        }
        if (status >= 400) {
            ++stats_.errors;
            std::fprintf(stderr, "participant %d: %s -> %d %s\n", index_, std::string(request_.target()).c_str(),
                         status, res.body().substr(0, 200).c_str());
            close();
            return;
        }
        auto then = std::move(then_);
        then(res.body());
    }

    void retry() {
        // No answer (the server was killed or closed the kept-alive connection): a new connection, as the page does.
        ++stats_.retries;
        stream_.reset();
        buffer_.clear();
        timer_.expires_after(std::chrono::milliseconds(200));
        timer_.async_wait([self = shared_from_this()](beast::error_code) { self->resend(); });
    }
    void resend() {
        started_ = Clock::now();
        if (!stream_) return connect();
        write();
    }
    void close() {
        if (stream_) {
            beast::error_code ignored;
            stream_->socket().shutdown(tcp::socket::shutdown_both, ignored);
        }
        stream_.reset();
    }

    asio::io_context& io_;
    const Options& o_;
    int index_;
    int& port_;
    Stats& stats_;
    std::atomic<long>& answered_;
    asio::steady_timer timer_;
    std::mt19937 random_;
    std::string source_;
    std::unique_ptr<beast::tcp_stream> stream_;
    beast::flat_buffer buffer_;
    http::request<http::string_body> request_;
    std::optional<http::response_parser<http::string_body>> parser_;
    http::response<http::string_body> response_;
    std::function<void(const std::string&)> then_;
    bool isAnswer_ = false;
    Clock::time_point started_;
    int stage_ = 0;
    json state_;
    std::int64_t session_ = 0;
    std::set<std::string> fetched_;
};

// A client that sends its header one line every 4 s, and reconnects when the server cuts it (408).
class SlowHeader : public std::enable_shared_from_this<SlowHeader> {
public:
    SlowHeader(asio::io_context& io, int index, int& port, std::atomic<bool>& stop)
        : io_(io), index_(index), port_(port), stop_(stop), timer_(io) {}
    std::atomic<int>* cut = nullptr;
    void start() {
        if (stop_) return;
        socket_ = std::make_unique<tcp::socket>(io_);
        beast::error_code ec;
        socket_->open(tcp::v4(), ec);
        const std::string source = "127.1." + std::to_string(1 + index_ / 50) + "." + std::to_string(1 + index_ % 50);
        socket_->bind(tcp::endpoint(asio::ip::make_address(source), 0), ec);
        lines_ = 0;
        socket_->async_connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port_)),
                               [self = shared_from_this()](beast::error_code e) {
                                   if (e) return self->later();
                                   self->line();
                                   self->watch();
                               });
    }

private:
    void line() {
        const std::string text =
            lines_ == 0 ? "GET /api/study HTTP/1.1\r\n" : "X-Slow-" + std::to_string(lines_) + ": 1\r\n";
        ++lines_;
        auto bytes = std::make_shared<std::string>(text);
        asio::async_write(*socket_, asio::buffer(*bytes), [bytes](beast::error_code, std::size_t) {});
        timer_.expires_after(std::chrono::seconds(4));
        timer_.async_wait([self = shared_from_this()](beast::error_code ec) {
            if (!ec && self->socket_ && self->socket_->is_open() && !self->stop_) self->line();
        });
    }
    void watch() {
        // Whatever arrives (the 408) or the close ends this round; a new connection starts.
        socket_->async_read_some(asio::buffer(sink_), [self = shared_from_this()](beast::error_code ec, std::size_t) {
            if (!ec) return self->watch();
            if (self->cut) ++*self->cut;
            self->timer_.cancel();
            self->later();
        });
    }
    void later() {
        auto retry = std::make_shared<asio::steady_timer>(io_, std::chrono::milliseconds(100));
        retry->async_wait([self = shared_from_this(), retry](beast::error_code) { self->start(); });
    }
    asio::io_context& io_;
    int index_;
    int& port_;
    std::atomic<bool>& stop_;
    asio::steady_timer timer_;
    std::unique_ptr<tcp::socket> socket_;
    int lines_ = 0;
    char sink_[1024];
};

// A connection that never sends a request (an idle-connection flood), reopened 100 ms after the server closes it.
class IdleHolder : public std::enable_shared_from_this<IdleHolder> {
public:
    IdleHolder(asio::io_context& io, int index, int& port, std::atomic<bool>& stop, std::atomic<long>& closed)
        : io_(io), index_(index), port_(port), stop_(stop), closed_(closed) {}
    void start(double delaySeconds) {
        auto timer =
            std::make_shared<asio::steady_timer>(io_, std::chrono::microseconds(static_cast<long>(delaySeconds * 1e6)));
        timer->async_wait([self = shared_from_this(), timer](beast::error_code) { self->open(); });
    }

private:
    void open() {
        if (stop_) return;
        socket_ = std::make_unique<tcp::socket>(io_);
        beast::error_code ec;
        socket_->open(tcp::v4(), ec);
        const int address = index_ / 60;
        const std::string source =
            "127.2." + std::to_string(1 + address / 250) + "." + std::to_string(1 + address % 250);
        socket_->bind(tcp::endpoint(asio::ip::make_address(source), 0), ec);
        socket_->async_connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port_)),
                               [self = shared_from_this()](beast::error_code e) {
                                   if (e) return self->later();
                                   self->watch();
                               });
    }
    void watch() {
        socket_->async_read_some(asio::buffer(sink_), [self = shared_from_this()](beast::error_code ec, std::size_t) {
            if (!ec) return self->watch();
            ++self->closed_;
            self->later();
        });
    }
    void later() {
        socket_.reset();
        auto retry = std::make_shared<asio::steady_timer>(io_, std::chrono::milliseconds(100));
        retry->async_wait([self = shared_from_this(), retry](beast::error_code) { self->open(); });
    }
    asio::io_context& io_;
    int index_;
    int& port_;
    std::atomic<bool>& stop_;
    std::atomic<long>& closed_;
    std::unique_ptr<tcp::socket> socket_;
    char sink_[512];
};

// A client that sends a 500 MiB chunked body, again and again (blocking, in its own thread).
void chunkedFlood(int& port, std::atomic<bool>& stop, std::atomic<long>& refused) {
    const std::string chunk = "10000\r\n" + std::string(65536, ' ') + "\r\n";
    while (!stop) {
        asio::io_context io;
        tcp::socket socket(io);
        beast::error_code ec;
        socket.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)), ec);
        if (ec) {
            std::this_thread::sleep_for(std::chrono::milliseconds(200));
            continue;
        }
        const std::string head = "POST /api/join HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) +
                                 "\r\nContent-Type: application/json\r\nTransfer-Encoding: chunked\r\n\r\n";
        asio::write(socket, asio::buffer(head), ec);
        for (std::size_t sent = 0; !ec && !stop && sent < (500u << 20); sent += 65536)
            asio::write(socket, asio::buffer(chunk), ec);
        ++refused;
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
}

// The researcher: GET /api/researcher/export?format=json every `every` seconds (blocking, in its own thread), the
// whole body read and dropped; each download's time and size are recorded.
struct Exports {
    std::vector<double> ms;
    std::vector<double> megabytes;
    int failed = 0;
};

void exportLoop(int& port, double every, std::atomic<bool>& stop, Exports& out) {
    auto next = Clock::now();
    while (!stop) {
        next += std::chrono::microseconds(static_cast<long>(every * 1e6));
        while (!stop && Clock::now() < next) std::this_thread::sleep_for(std::chrono::milliseconds(50));
        if (stop) break;
        const auto start = Clock::now();
        try {
            asio::io_context io;
            beast::tcp_stream stream(io);
            stream.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
            http::request<http::empty_body> request{http::verb::get, "/api/researcher/export?format=json", 11};
            request.set(http::field::host, "127.0.0.1:" + std::to_string(port));
            request.set(http::field::authorization, std::string("Bearer ") + kToken);
            http::write(stream, request);
            beast::flat_buffer buffer;
            http::response_parser<http::string_body> parser;
            parser.body_limit(boost::none);
            http::read(stream, buffer, parser);
            if (parser.get().result_int() != 200)
                throw std::runtime_error("status " + std::to_string(parser.get().result_int()));
            out.ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
            out.megabytes.push_back(static_cast<double>(parser.get().body().size()) / 1e6);
        } catch (const std::exception&) {
            ++out.failed; // the server was killed meanwhile (--kill-at)
        }
    }
}

// N participants who answered every trial, written through the store (joins) and one transaction (sessions and
// answers) before the server starts.
void prefill(const fs::path& db, int participants) {
    {
        StudyStore store(db);
        for (int i = 0; i < participants; ++i) store.join("", "prefill-" + std::to_string(i));
    }
    SqliteDatabase sql(db.string(), false);
    SqliteTransaction tx(sql);
    sql.execute("INSERT INTO sessions (participant_id, started_at, user_agent, viewport_width, viewport_height,"
                " device_pixel_ratio) SELECT id, created_at, 'Mozilla/5.0 (bench) prefill', 1920, 1080, 1.0"
                " FROM participants");
    sql.execute("INSERT INTO responses (trial_id, participant_id, session_id, chosen, side, response_ms, client_time,"
                " server_time, viewport_width, viewport_height, device_pixel_ratio, user_agent)"
                " SELECT t.id, t.participant_id, s.id, CASE WHEN t.id % 2 = 0 THEN 'A' ELSE 'B' END,"
                " CASE WHEN t.a_on_left = (t.id % 2 = 0) THEN 'left' ELSE 'right' END, 900.0,"
                " '2026-12-01T00:00:00.000Z', '2026-12-01T00:00:00.000Z', 1920, 1080, 1.0,"
                " 'Mozilla/5.0 (bench) prefill' FROM trials t JOIN sessions s ON s.participant_id = t.participant_id");
    tx.commit();
}

} // namespace

int main(int argc, char** argv) {
    Options o;
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string key = argv[i], value = argv[i + 1];
        if (key == "--participants") o.participants = std::stoi(value);
        else if (key == "--think-ms") {
            o.thinkMin = std::stod(value);
            o.thinkMax =
                value.find(':') != std::string::npos ? std::stod(value.substr(value.find(':') + 1)) : o.thinkMin;
        } else if (key == "--ramp-s") o.rampSeconds = std::stod(value);
        else if (key == "--slow-headers") o.slowHeaders = std::stoi(value);
        else if (key == "--chunked-floods") o.chunkedFloods = std::stoi(value);
        else if (key == "--kill-at") {
            std::stringstream list(value);
            std::string item;
            while (std::getline(list, item, ',')) o.killAt.push_back(std::stod(item));
        } else if (key == "--image-kib") o.imageKiB = std::stoi(value);
        else if (key == "--export-every-s") o.exportEverySeconds = std::stod(value);
        else if (key == "--prefill") o.prefill = std::stoi(value);
        else if (key == "--idle-connections") o.idleConnections = std::stoi(value);
        else if (key == "--folder") o.folder = value;
        else if (key == "--server") o.server = value;
        else {
            std::fprintf(stderr, "unknown option %s\n", key.c_str());
            return 2;
        }
    }
    rlimit files{}; // every connection is a file descriptor here too
    if (::getrlimit(RLIMIT_NOFILE, &files) == 0 && files.rlim_cur < files.rlim_max) {
        files.rlim_cur = files.rlim_max;
        ::setrlimit(RLIMIT_NOFILE, &files);
    }
    fs::remove_all(o.folder);
    writeSet(o.folder / "stimuli", o.imageKiB);
    const fs::path design = o.folder / "design.toml";
    skinlab::writeFileAtomic(design, "title = \"Browser load\"\nseed = 3\nrepetitions = 2\n[catch]\nblank = 2\n");
    const fs::path db = o.folder / "study.db";
    createStudy(o.folder / "stimuli", design, {}, db);
    if (o.prefill > 0) prefill(db, o.prefill);
    const long prefilled = o.prefill > 0 ? StudyStore(db).responseCount() : 0;

    Server server;
    server.start(o, db, 0);
    int port = server.port;
    std::printf("server pid %d on port %d; %d participants, think %.0f–%.0f ms, ramp %.0f s, %d slow-header "
                "connections, %d chunked floods, images %d KiB\n",
                server.pid, port, o.participants, o.thinkMin, o.thinkMax, o.rampSeconds, o.slowHeaders, o.chunkedFloods,
                o.imageKiB);
    std::fflush(stdout);

    asio::io_context io;
    Stats stats;
    std::atomic<long> answered{0};
    std::atomic<bool> stop{false};
    std::atomic<int> slowCut{0};
    std::vector<std::shared_ptr<Participant>> participants;
    // An idle-connection flood first (over 5 s), the participants 10 s later.
    std::atomic<long> idleClosed{0};
    std::vector<std::shared_ptr<IdleHolder>> idle;
    for (int i = 0; i < o.idleConnections; ++i) {
        idle.push_back(std::make_shared<IdleHolder>(io, i, port, stop, idleClosed));
        idle.back()->start(5.0 * i / o.idleConnections);
    }
    const double lead = o.idleConnections > 0 ? 10 : 0;
    for (int i = 0; i < o.participants; ++i) {
        participants.push_back(std::make_shared<Participant>(io, o, i, port, stats, answered));
        participants.back()->start(lead + o.rampSeconds * i / std::max(1, o.participants));
    }
    std::vector<std::shared_ptr<SlowHeader>> slow;
    for (int i = 0; i < o.slowHeaders; ++i) {
        slow.push_back(std::make_shared<SlowHeader>(io, i, port, stop));
        slow.back()->cut = &slowCut;
        slow.back()->start();
    }
    std::atomic<long> floodsRefused{0};
    std::vector<std::thread> floods;
    for (int i = 0; i < o.chunkedFloods; ++i) floods.emplace_back([&] { chunkedFlood(port, stop, floodsRefused); });
    Exports exports;
    std::thread researcher;
    if (o.exportEverySeconds > 0)
        researcher = std::thread([&] { exportLoop(port, o.exportEverySeconds, stop, exports); });

    // Kill -9 and restart at the given fractions of all answers; sample the server's RSS meanwhile.
    const long total = 22L * o.participants;
    long peakRss = 0;
    int kills = 0;
    std::thread supervisor([&] {
        std::size_t next = 0;
        while (!stop) {
            std::this_thread::sleep_for(std::chrono::milliseconds(100));
            peakRss = std::max(peakRss, server.rssKiB("VmRSS:"));
            if (next < o.killAt.size() && answered >= static_cast<long>(o.killAt[next] * static_cast<double>(total))) {
                peakRss = std::max(peakRss, server.rssKiB("VmHWM:"));
                server.kill(SIGKILL);
                ++kills;
                std::this_thread::sleep_for(std::chrono::milliseconds(300));
                server.start(o, db, port);
                ++next;
            }
        }
    });
    const auto start = Clock::now();
    std::thread ioThread([&] {
        // Runs until every participant is done; the slow-header clients then stop reconnecting.
        io.run();
    });
    while (true) {
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
        int done = 0;
        for (auto& p : participants) done += p->completed ? 1 : 0;
        if (done == o.participants || Clock::now() - start > std::chrono::minutes(10)) break;
    }
    const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
    peakRss = std::max(peakRss, server.rssKiB("VmHWM:"));
    stop = true;
    io.stop();
    ioThread.join();
    supervisor.join();
    for (auto& t : floods) t.join();
    if (researcher.joinable()) researcher.join();
    server.kill(SIGTERM);

    // Every acknowledged answer stored exactly once, as acknowledged.
    StudyStore store(db);
    std::map<std::int64_t, bool> storedLeft; // by trial row id
    for (const ResponseRow& r : store.responses()) storedLeft[r.trialId] = r.aSelected == r.aOnLeft;
    long acknowledged = 0, lost = 0, mismatched = 0, completed = 0;
    for (auto& p : participants) {
        completed += p->completed ? 1 : 0;
        for (const auto& [reference, side] : p->acknowledged) {
            ++acknowledged;
            const auto it = storedLeft.find(reference & 0xFFFFFFFFll);
            if (it == storedLeft.end()) ++lost;
            else if (it->second != (side == "left")) ++mismatched;
        }
    }
    const long stored = store.responseCount() - prefilled;
    std::printf(
        "%.1f s: %ld/%d participants completed; %ld answers acknowledged, %ld stored (%ld lost, %ld stored "
        "differently, %ld stored without acknowledgement); %d kills; %d HTTP errors, %d re-sent after no answer (%d "
        "of them: no connection)\n",
        seconds, completed, o.participants, acknowledged, stored, lost, mismatched, stored - acknowledged + lost, kills,
        stats.errors, stats.retries, stats.connectRetries);
    std::printf("statuses:");
    for (const auto& [status, n] : stats.statuses) std::printf(" %d×%d", status, n);
    std::printf("\nslow-header connections cut by the server: %d; chunked floods refused: %ld\n", slowCut.load(),
                floodsRefused.load());
    if (o.idleConnections > 0)
        std::printf("idle connections: %d held open (reopened when closed), closed by the server %ld times; the "
                    "participants started %.0f s after them\n",
                    o.idleConnections, idleClosed.load(), lead);
    std::printf("| %d | %.0f–%.0f | %d | %d | %zu | %.1f | %.1f | %.1f | %.1f | %.1f | %.0f | %ld |\n", o.participants,
                o.thinkMin, o.thinkMax, o.slowHeaders, o.chunkedFloods, stats.all.size(), percentile(stats.all, 50),
                percentile(stats.all, 99), percentile(stats.answers, 50), percentile(stats.answers, 99),
                percentile(stats.all, 100), static_cast<double>(stats.answers.size()) / seconds, peakRss / 1024);
    std::printf("image requests: %zu, ms p50 %.1f p90 %.1f p99 %.1f max %.1f\n", stats.images.size(),
                percentile(stats.images, 50), percentile(stats.images, 90), percentile(stats.images, 99),
                percentile(stats.images, 100));
    if (o.exportEverySeconds > 0)
        std::printf("researcher exports (JSON, every %.1f s, %ld answers prefilled): %zu downloaded, %d failed; ms p50 "
                    "%.0f max %.0f; MB first %.1f last %.1f\n",
                    o.exportEverySeconds, prefilled, exports.ms.size(), exports.failed, percentile(exports.ms, 50),
                    percentile(exports.ms, 100), exports.megabytes.empty() ? 0.0 : exports.megabytes.front(),
                    exports.megabytes.empty() ? 0.0 : exports.megabytes.back());
    std::printf(
        "(participants | think ms | slow headers | floods | requests | p50 all ms | p99 all ms | p50 answer ms | "
        "p99 answer ms | max ms | answers/s | server peak RSS MiB)\n");
    return lost == 0 && mismatched == 0 && completed == o.participants ? 0 : 1;
}
