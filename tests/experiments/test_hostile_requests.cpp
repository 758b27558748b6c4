// Hostile requests against the study server, sent byte for byte over raw sockets (no HTTP library in between
// to tidy them up): path traversal in every encoding, malformed, oversized and deeply nested JSON, numbers no
// double holds, slow headers, chunked floods, bad and foreign tokens, replays, out-of-order, concurrent and late
// answers, non-UTF-8 headers, foreign Host names, join floods and connection floods, platform ids without the
// participant's secret (in any letter case), session floods, IPv6 and address-spraying join floods, tokens in URLs,
// framing, transfer codings the server cannot decode and formula cells. Each gets a 4xx (or the page it should), and
// the study file afterwards holds exactly what it held before (every row of every table), or the one row that
// records the attempt.
#include "common/error.h"
#include "common/files.h"
#include "net/join_limiter.h"
#include "experiments/recruitment.h"
#include "experiments/sqlite_database.h"
#include "experiments/study_backup.h"
#include "experiments/study_export.h"
#include "study_server_fixture.h"
#include "store_answer.h"

#include <arpa/inet.h>
#include <atomic>
#include <fstream>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>
#include <sstream>
#include <sys/socket.h>
#include <sys/stat.h>
#include <thread>
#include <unistd.h>
#include <utility>

using namespace skinlab::experiments;
using namespace skinlab::experiments::test_support;
using nlohmann::json;
using namespace std::chrono_literals;
namespace fs = std::filesystem;

namespace {

const char* kDesign = R"(
title = "Hostile test"
seed = 9
repetitions = 1
[practice]
trials = 1
[catch]
blank = 1
)";

// One raw TCP connection to the server.
class RawSocket {
public:
    explicit RawSocket(int port, const char* source = nullptr) {
        fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
        if (source) {
            sockaddr_in local{};
            local.sin_family = AF_INET;
            ::inet_pton(AF_INET, source, &local.sin_addr);
            ::bind(fd_, reinterpret_cast<sockaddr*>(&local), sizeof local);
        }
        sockaddr_in address{};
        address.sin_family = AF_INET;
        address.sin_port = htons(static_cast<std::uint16_t>(port));
        ::inet_pton(AF_INET, "127.0.0.1", &address.sin_addr);
        connected_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0;
    }
    ~RawSocket() { ::close(fd_); }
    bool connected() const { return connected_; }
    // Sends everything; false when the server closed or reset the connection.
    bool send(std::string_view bytes) {
        while (!bytes.empty()) {
            const ssize_t n = ::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL);
            if (n <= 0) return false;
            bytes.remove_prefix(static_cast<std::size_t>(n));
        }
        return true;
    }
    // Reads one response (status line, headers, Content-Length body); "" when the connection closes first.
    std::string readResponse(std::chrono::milliseconds timeout = 10s) {
        const auto deadline = std::chrono::steady_clock::now() + timeout;
        while (true) {
            const std::size_t end = buffer_.find("\r\n\r\n");
            if (end != std::string::npos) {
                std::size_t length = 0;
                const std::string head = buffer_.substr(0, end);
                std::string lower = head;
                for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
                if (const std::size_t at = lower.find("content-length:"); at != std::string::npos)
                    length = std::stoul(head.substr(at + 15));
                if (buffer_.size() >= end + 4 + length) {
                    std::string response = buffer_.substr(0, end + 4 + length);
                    buffer_.erase(0, end + 4 + length);
                    return response;
                }
            }
            const auto left =
                std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
            if (left.count() <= 0) return "";
            pollfd p{fd_, POLLIN, 0};
            if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) return "";
            char chunk[65536];
            const ssize_t n = ::recv(fd_, chunk, sizeof chunk, 0);
            if (n <= 0) return "";
            buffer_.append(chunk, static_cast<std::size_t>(n));
        }
    }
    // Reads up to the end of a response's header (the bytes after it stay buffered); "" when none arrives in time.
    std::string readHead(std::chrono::milliseconds timeout = 10s) {
        const auto deadline = std::chrono::steady_clock::now() + timeout;
        for (std::size_t end; (end = buffer_.find("\r\n\r\n")) == std::string::npos;)
            if (!receive(deadline)) return "";
        const std::size_t end = buffer_.find("\r\n\r\n") + 4;
        std::string head = buffer_.substr(0, end);
        buffer_.erase(0, end);
        return head;
    }
    // A chunked body after readHead(): the size of each chunk in order, the body decoded; false when it does not
    // arrive whole in time.
    bool readChunks(std::vector<std::size_t>& sizes, std::string& body, std::chrono::milliseconds timeout = 20s) {
        const auto deadline = std::chrono::steady_clock::now() + timeout;
        while (true) {
            std::size_t line;
            while ((line = buffer_.find("\r\n")) == std::string::npos)
                if (!receive(deadline)) return false;
            const std::size_t size = std::stoul(buffer_.substr(0, line), nullptr, 16);
            while (buffer_.size() < line + 2 + size + 2)
                if (!receive(deadline)) return false;
            if (size == 0) {
                buffer_.erase(0, line + 4);
                return true;
            }
            sizes.push_back(size);
            body += buffer_.substr(line + 2, size);
            buffer_.erase(0, line + 2 + size + 2);
        }
    }
    // Everything until the server closes the connection (an HTTP/1.0 body without a length).
    std::string readUntilClosed(std::chrono::milliseconds timeout = 20s) {
        const auto deadline = std::chrono::steady_clock::now() + timeout;
        while (receive(deadline)) {
        }
        return std::exchange(buffer_, std::string());
    }
    // True when the server closed the connection (EOF or reset) within the timeout.
    bool closedByServer(std::chrono::milliseconds timeout) {
        pollfd p{fd_, POLLIN, 0};
        if (::poll(&p, 1, static_cast<int>(timeout.count())) <= 0) return false;
        char chunk[4096];
        return ::recv(fd_, chunk, sizeof chunk, 0) <= 0;
    }

private:
    bool receive(std::chrono::steady_clock::time_point deadline) {
        const auto left =
            std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
        pollfd p{fd_, POLLIN, 0};
        if (left.count() <= 0 || ::poll(&p, 1, static_cast<int>(left.count())) <= 0) return false;
        char chunk[65536];
        const ssize_t n = ::recv(fd_, chunk, sizeof chunk, 0);
        if (n <= 0) return false;
        buffer_.append(chunk, static_cast<std::size_t>(n));
        return true;
    }

    int fd_ = -1;
    bool connected_ = false;
    std::string buffer_;
};

int statusOf(const std::string& response) {
    if (response.rfind("HTTP/1.", 0) != 0 || response.size() < 12) return 0;
    return std::stoi(response.substr(9, 3));
}

std::string bodyOf(const std::string& response) {
    const std::size_t end = response.find("\r\n\r\n");
    return end == std::string::npos ? "" : response.substr(end + 4);
}

long residentKiB() {
    std::ifstream status("/proc/self/status");
    std::string line;
    while (std::getline(status, line))
        if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
    return 0;
}

struct Hostile {
    RunningStudy study;
    std::string host;
    explicit Hostile(const std::function<void(ServerOptions&)>& configure = {})
        : study(kDesign, {}, configure), host("127.0.0.1:" + std::to_string(study.port())) {}

    // One request on a fresh connection; the raw response ("" = none).
    std::string exchange(const std::string& bytes, std::chrono::milliseconds timeout = 10s) {
        RawSocket socket(study.port());
        if (!socket.send(bytes)) return "";
        return socket.readResponse(timeout);
    }
    std::string request(const std::string& method, const std::string& target, const std::string& body = "",
                        const std::string& extraHeaders = "", const std::string& type = "application/json") {
        std::string bytes = method + " " + target + " HTTP/1.1\r\nHost: " + host + "\r\n" + extraHeaders;
        if (!body.empty() || method == "POST")
            bytes += "Content-Type: " + type + "\r\nContent-Length: " + std::to_string(body.size()) + "\r\n";
        return exchange(bytes + "Connection: close\r\n\r\n" + body);
    }
    // Expects `status` (a 4xx; 0 = any 4xx), a JSON {"error"} body when the server could answer with one, and no change.
    void expectRejected(const std::string& what, int status, const std::function<std::string()>& send) {
        const std::string before = study.fingerprint();
        const std::string response = send();
        if (status == 0) // any client error
            EXPECT_TRUE(statusOf(response) >= 400 && statusOf(response) < 500)
                << what << ": " << response.substr(0, 300);
        else EXPECT_EQ(statusOf(response), status) << what << ": " << response.substr(0, 300);
        if (statusOf(response) >= 400) {
            json body;
            try {
                body = json::parse(bodyOf(response));
            } catch (const json::exception&) {
            }
            EXPECT_TRUE(body.is_object() && body.contains("error")) << what << ": " << response.substr(0, 300);
        }
        EXPECT_EQ(study.fingerprint(), before) << what << ": the request changed stored data";
    }
};

json screen() { return {{"viewport_width", 1280}, {"viewport_height", 800}, {"device_pixel_ratio", 1.0}}; }

struct Participant {
    std::string token;
    std::int64_t session = 0;
    json state;
};

Participant joinAndStart(HttpClient& client) {
    Participant p;
    JsonAnswer joined = postJson(client, "/api/join", json::object());
    EXPECT_EQ(joined.status, 201) << joined.raw;
    p.token = joined.body.value("token", "");
    json start = screen();
    start["token"] = p.token;
    JsonAnswer session = postJson(client, "/api/session", start);
    EXPECT_EQ(session.status, 200) << session.raw;
    p.session = session.body.value("session", 0);
    p.state = session.body;
    return p;
}

json answerBody(const Participant& p, const json& trial, const std::string& side) {
    json body = screen();
    body["token"] = p.token;
    body["trial"] = trial;
    body["side"] = side;
    body["session"] = p.session;
    body["response_ms"] = 900.0;
    body["client_time"] = "2026-11-23T14:00:00.000Z";
    return body;
}

} // namespace

TEST(HostileRequests, TraversalInEveryEncodingReachesNothingButTheStudy) {
    Hostile h;
    for (const std::string target : {"/../study.db",
                                     "/%2e%2e/study.db",
                                     "/%2E%2E/%2E%2E/etc/passwd",
                                     "/%252e%252e/study.db",
                                     "/..%2fstudy.db",
                                     "/..%5cstudy.db",
                                     "/..\\study.db",
                                     "/%c0%ae%c0%ae/study.db",
                                     "/%e0%80%ae%e0%80%ae/study.db",
                                     "//etc/passwd",
                                     "/stimuli/../manifest.json",
                                     "/stimuli/..%2f..%2fmanifest.json",
                                     "/stimuli/%2e%2e%2fmanifest.json",
                                     "/stimuli/0.png/../../study.db",
                                     "/stimuli/%30.png",
                                     "/stimuli/0.png%00",
                                     "/stimuli/0.png%00.txt",
                                     "/stimuli//0.png",
                                     "/stimuli/0x1.png",
                                     "/stimuli/1e1.png",
                                     "/stimuli/-0.png",
                                     "/stimuli/+1.png",
                                     "/stimuli/0000001.png",
                                     "/stimuli/999999.png",
                                     "/stimuli/../../stimuli/png/0-separable.png",
                                     "/png/0-separable.png",
                                     "/manifest.json",
                                     "/design.toml",
                                     "/study.db",
                                     "/study.db-wal",
                                     "/api/../study.db",
                                     "/api/%2e%2e/study.db",
                                     "/index.html/../study.db",
                                     "/app.js/..",
                                     "/api/study/..",
                                     "/API/study"}) {
        h.expectRejected("GET " + target, 404, [&] { return h.request("GET", target); });
    }
    // Raw non-ASCII bytes in the target: refused as malformed or unknown.
    for (const std::string target : {"/\xff\xfe", "/stimuli/\xc0\xae\xc0\xae/study.db", "/stimuli/0.png\xff"})
        h.expectRejected("GET " + target, 0, [&] { return h.request("GET", target); });
    // Absolute-form and asterisk targets, and garbage request lines, are malformed or unknown, never files.
    h.expectRejected("absolute form", 404, [&] { return h.request("GET", "http://127.0.0.1/../study.db"); });
    h.expectRejected("asterisk", 404, [&] { return h.request("OPTIONS", "*"); });
    h.expectRejected("no target", 400, [&] { return h.exchange("GET HTTP/1.1\r\nHost: " + h.host + "\r\n\r\n"); });
    h.expectRejected("space in target", 400,
                     [&] { return h.exchange("GET /a b HTTP/1.1\r\nHost: " + h.host + "\r\n\r\n"); });
    h.expectRejected("not HTTP", 400,
                     [&] { return h.exchange("\x16\x03\x01\x02\x10\x01\x10\x01\xfc\x03\x03\r\n\r\n"); });
    // The page with hostile query strings is just the page.
    for (const std::string target : {"/?p=../../etc/passwd", "/index.html?p=%00%ff", "/?p=<script>"}) {
        const std::string before = h.study.fingerprint();
        const std::string response = h.request("GET", target);
        EXPECT_EQ(statusOf(response), 200) << target;
        EXPECT_NE(bodyOf(response).find("<script src=\"/app.js\"></script>"), std::string::npos) << target;
        EXPECT_EQ(h.study.fingerprint(), before);
    }
}

TEST(HostileRequests, MalformedOversizedAndOverflowingJsonIs400Or413) {
    Hostile h;
    HttpClient client = h.study.client();
    Participant p = joinAndStart(client);
    const json good = answerBody(p, p.state["trial"]["id"], "left");
    auto post = [&](const std::string& body) {
        return [&h, body] { return h.request("POST", "/api/response", body); };
    };
    auto with = [&](const std::string& key, const std::string& rawValue) {
        json copy = good;
        copy.erase(key);
        std::string text = copy.dump();
        text.insert(1, "\"" + key + "\":" + rawValue + ",");
        return text;
    };
    for (const std::string body :
         {"", "{", "{\"token\":", "}", "null", "[]", "\"text\"", "{}x", "{\"a\":NaN}", "{\"a\":Infinity}", "{\"a\":01}",
          "{'a':1}", "{\"a\":\"\xff\xfe\"}", "{\"a\":\"\\ud800\"}"}) {
        h.expectRejected("body " + body, 400, post(body));
    }
    h.expectRejected("deep nesting", 400, post(std::string(7000, '[') + std::string(7000, ']')));
    h.expectRejected("deep object nesting", 400, [&] {
        std::string body;
        for (int i = 0; i < 1500; ++i) body += "{\"a\":";
        body += "1" + std::string(1500, '}');
        return h.request("POST", "/api/response", body);
    });
    // Numbers no double (or no 64-bit integer) holds, and numbers out of range.
    for (const auto& [key, value] :
         std::vector<std::pair<std::string, std::string>>{{"trial", "1e400"},
                                                          {"trial", "-1e400"},
                                                          {"trial", "1e-400"},
                                                          {"trial", "18446744073709551615"},
                                                          {"trial", "99999999999999999999999"},
                                                          {"trial", "9223372036854775808"},
                                                          {"trial", "1.5"},
                                                          {"trial", "-0"},
                                                          {"session", "1e400"},
                                                          {"response_ms", "1e400"},
                                                          {"response_ms", "1e308"},
                                                          {"response_ms", "-1"},
                                                          {"device_pixel_ratio", "1e-400"},
                                                          {"device_pixel_ratio", "17"},
                                                          {"viewport_width", "1e400"},
                                                          {"viewport_width", "4294967297"},
                                                          {"side", "1e400"}}) {
        h.expectRejected(key + "=" + value, 400, post(with(key, value)));
    }
    h.expectRejected("join with 1e400", 400, [&] { return h.request("POST", "/api/join", "{\"label\":1e400}"); });
    h.expectRejected("session with 1e400", 400, [&] {
        return h.request("POST", "/api/session", "{\"token\":\"" + p.token + "\",\"viewport_width\":1e400}");
    });
    // Oversized: announced, sent, or only claimed.
    h.expectRejected("17 KiB body", 413, post("{\"client_time\":\"" + std::string(17 * 1024, 'x') + "\"}"));
    h.expectRejected("claimed 1 TB", 413, [&] {
        return h.exchange("POST /api/join HTTP/1.1\r\nHost: " + h.host +
                          "\r\nContent-Type: application/json\r\nContent-Length: 1000000000000\r\n\r\n{}");
    });
    h.expectRejected("negative length", 400, [&] {
        return h.exchange("POST /api/join HTTP/1.1\r\nHost: " + h.host +
                          "\r\nContent-Type: application/json\r\nContent-Length: -1\r\n\r\n{}");
    });
    h.expectRejected("two lengths", 400, [&] {
        return h.exchange("POST /api/join HTTP/1.1\r\nHost: " + h.host +
                          "\r\nContent-Type: application/json\r\nContent-Length: 2\r\nContent-Length: 3\r\n\r\n{}");
    });
    h.expectRejected("9 KiB header", 431,
                     [&] { return h.request("GET", "/api/study", "", "X-Pad: " + std::string(9000, 'a') + "\r\n"); });
    h.expectRejected("2,000 small headers", 431, [&] {
        std::string headers;
        for (int i = 0; i < 2000; ++i) headers += "X-" + std::to_string(i) + ": a\r\n";
        return h.request("GET", "/api/study", "", headers);
    });
    h.expectRejected("text/plain", 415,
                     [&] { return h.request("POST", "/api/response", good.dump(), "", "text/plain"); });
    // The good request still works afterwards.
    EXPECT_EQ(statusOf(h.request("POST", "/api/response", good.dump())), 200);
}

TEST(HostileRequests, SlowHeadersAreCutWithout408BlockingAnyoneElse) {
    Hostile h([](ServerOptions& o) { o.requestTimeout = 1500ms; });
    const std::string before = h.study.fingerprint();
    std::vector<std::unique_ptr<RawSocket>> slow;
    for (int i = 0; i < 40; ++i) {
        slow.push_back(std::make_unique<RawSocket>(h.study.port(), ("127.0.1." + std::to_string(i + 1)).c_str()));
        ASSERT_TRUE(slow.back()->send("POST /api/join HTTP/1.1\r\nHost: " + h.host + "\r\n"));
    }
    // Meanwhile a normal request is answered at once.
    const auto start = std::chrono::steady_clock::now();
    EXPECT_EQ(statusOf(h.request("GET", "/api/study")), 200);
    EXPECT_LT(std::chrono::steady_clock::now() - start, 1000ms);
    // One more header line every 500 ms does not extend the deadline: 408, then the connection is closed.
    for (int i = 0; i < 2; ++i) {
        std::this_thread::sleep_for(500ms);
        for (auto& s : slow) s->send("X-Slow-" + std::to_string(i) + ": 1\r\n");
    }
    for (auto& s : slow) {
        const std::string response = s->readResponse(5s);
        EXPECT_EQ(statusOf(response), 408) << response;
        EXPECT_TRUE(s->closedByServer(3s));
    }
    EXPECT_EQ(h.study.fingerprint(), before);
}

TEST(HostileRequests, ChunkedFloodsAreRefusedEarlyWithoutBuffering) {
    Hostile h;
    const std::string before = h.study.fingerprint();
    const long rssBefore = residentKiB();
    // Three floods at once, each offering 500 MiB in 64 KiB chunks: the server stops reading after 16 KiB of body
    // (413), discards at most a few MiB more and closes.
    std::atomic<std::size_t> maxSent{0};
    std::vector<std::thread> floods;
    std::vector<std::string> answers(3);
    for (int f = 0; f < 3; ++f) {
        floods.emplace_back([&, f] {
            RawSocket socket(h.study.port());
            socket.send("POST /api/join HTTP/1.1\r\nHost: " + h.host +
                        "\r\nContent-Type: application/json\r\nTransfer-Encoding: chunked\r\n\r\n");
            char size[32];
            std::snprintf(size, sizeof size, "%x\r\n", 65536);
            const std::string chunk = std::string(size) + std::string(65536, ' ') + "\r\n";
            std::size_t sent = 0;
            while (sent < (500u << 20) && socket.send(chunk)) sent += 65536;
            std::size_t seen = maxSent.load();
            while (sent > seen && !maxSent.compare_exchange_weak(seen, sent)) {
            }
            answers[static_cast<std::size_t>(f)] = socket.readResponse(3s);
        });
    }
    for (std::thread& t : floods) t.join();
    EXPECT_LT(maxSent.load(), 64u << 20) << "the server kept reading a flood";
    for (const std::string& a : answers)
        if (!a.empty()) {
            EXPECT_EQ(statusOf(a), 413) << a.substr(0, 200);
        }
    EXPECT_LT(residentKiB() - rssBefore, 64 * 1024) << "RSS grew while refusing floods";
    // Chunk sizes that overflow, or a single chunk over the limit.
    h.expectRejected("chunk size overflow", 0, [&] {
        return h.exchange("POST /api/join HTTP/1.1\r\nHost: " + h.host +
                          "\r\nContent-Type: application/json\r\nTransfer-Encoding: "
                          "chunked\r\n\r\nfffffffffffffffffffff\r\n{}\r\n0\r\n\r\n");
    });
    h.expectRejected("one huge chunk", 413, [&] {
        return h.exchange("POST /api/join HTTP/1.1\r\nHost: " + h.host +
                          "\r\nContent-Type: application/json\r\nTransfer-Encoding: chunked\r\n\r\n40000000\r\n{}");
    });
    EXPECT_EQ(h.study.fingerprint(), before);
    // A small chunked body is fine.
    const std::string joined =
        h.exchange("POST /api/join HTTP/1.1\r\nHost: " + h.host +
                   "\r\nContent-Type: application/json\r\nTransfer-Encoding: chunked\r\n\r\n2\r\n{}\r\n0\r\n\r\n");
    EXPECT_EQ(statusOf(joined), 201) << joined;
}

TEST(HostileRequests, TokensReplaysOrderConcurrencyAndLateAnswers) {
    Hostile h;
    HttpClient client = h.study.client();
    Participant alice = joinAndStart(client);
    Participant bob = joinAndStart(client);
    const json first = alice.state["trial"]["id"];
    auto post = [&](const json& body) {
        return [&h, body] { return h.request("POST", "/api/response", body.dump()); };
    };
    auto with = [](json body, const std::string& key, const json& value) {
        if (value.is_null()) body.erase(key);
        else body[key] = value;
        return body;
    };
    const json good = answerBody(alice, first, "left");
    h.expectRejected("missing token", 400, post(with(good, "token", nullptr)));
    h.expectRejected("empty token", 404, post(with(good, "token", "")));
    h.expectRejected("wrong token", 404, post(with(good, "token", std::string(32, '0'))));
    h.expectRejected("token too long", 400, post(with(good, "token", std::string(65, 'a'))));
    h.expectRejected("token as object", 400, post(with(good, "token", json{{"$ne", ""}})));
    h.expectRejected("SQL in token", 404, post(with(good, "token", "' OR 1=1 --")));
    h.expectRejected("bob's token on alice's trial", 404, post(with(good, "token", bob.token)));
    h.expectRejected("bob's session", 404, post(with(good, "session", bob.session)));
    h.expectRejected("bob's trial", 404, post(with(good, "trial", bob.state["trial"]["id"])));
    h.expectRejected("state with bob's token changed", 404, [&] {
        // The last hex digit changed (to one it is not: a random token ends in '0' one time in 16).
        return h.request("GET", "/api/state", "",
                         "X-Skinlab-Token: " + bob.token.substr(0, 31) + (bob.token.back() == '0' ? "1" : "0") +
                             "\r\n");
    });
    h.expectRejected("session for nobody", 404,
                     [&] { return h.request("POST", "/api/session", with(screen(), "token", "nobody").dump()); });
    h.expectRejected("researcher status without token", 401,
                     [&] { return h.request("GET", "/api/researcher/status"); });
    h.expectRejected("researcher token in the URL", 401,
                     [&] { return h.request("GET", std::string("/api/researcher/status?token=") + kResearcherToken); });
    h.expectRejected("participant token as researcher token", 403, [&] {
        return h.request("GET", "/api/researcher/export", "", "Authorization: Bearer " + alice.token + "\r\n");
    });

    // Out of order: alice's third trial before her first.
    const auto trials = h.study.store().trials(h.study.store().participant(alice.token).id);
    h.expectRejected("out of order", 409, post(with(good, "trial", trialReference(alice.token, trials[2].id))));

    // Concurrent answers to the same trial: one stored, the same answer again is a duplicate, a different one 409.
    std::vector<std::thread> threads;
    std::vector<int> statuses(16);
    for (int i = 0; i < 16; ++i)
        threads.emplace_back([&, i] {
            const std::string response =
                h.request("POST", "/api/response", answerBody(alice, first, i % 2 ? "left" : "right").dump());
            statuses[static_cast<std::size_t>(i)] = statusOf(response);
        });
    for (std::thread& t : threads) t.join();
    EXPECT_EQ(h.study.store().responseCount(), 1);
    int ok = 0, conflict = 0;
    for (int s : statuses) (s == 200 ? ok : conflict) += 1;
    EXPECT_EQ(ok + conflict, 16);
    EXPECT_EQ(ok, 8) << "every request with the stored side is acknowledged (stored or duplicate)";
    const bool storedLeft = h.study.store().responses()[0].aSelected == h.study.store().responses()[0].aOnLeft;
    // Replays: the stored answer again is harmless, another one is refused.
    {
        const std::string before = h.study.fingerprint();
        const std::string replay =
            h.request("POST", "/api/response", answerBody(alice, first, storedLeft ? "left" : "right").dump());
        EXPECT_EQ(statusOf(replay), 200);
        EXPECT_TRUE(json::parse(bodyOf(replay))["duplicate"].get<bool>());
        EXPECT_EQ(h.study.fingerprint(), before);
    }
    h.expectRejected("replay, other side", 409, post(answerBody(alice, first, storedLeft ? "right" : "left")));

    // Finish alice, then answer after completion.
    json state = json::parse(bodyOf(h.request("GET", "/api/state", "", "X-Skinlab-Token: " + alice.token + "\r\n")));
    json last;
    while (!state["completed"].get<bool>()) {
        last = state["trial"]["id"];
        state = json::parse(bodyOf(h.request("POST", "/api/response", answerBody(alice, last, "left").dump())));
    }
    {
        const std::string before = h.study.fingerprint();
        const std::string again = h.request("POST", "/api/response", answerBody(alice, last, "left").dump());
        EXPECT_EQ(statusOf(again), 200);
        EXPECT_TRUE(json::parse(bodyOf(again))["completed"].get<bool>());
        EXPECT_EQ(h.study.fingerprint(), before);
    }
    h.expectRejected("after completion, changed answer", 409, post(answerBody(alice, last, "right")));
    h.expectRejected("after completion, next id", 404, post(answerBody(alice, last.get<std::int64_t>() + 1, "left")));
}

TEST(HostileRequests, HostHeadersNonUtf8HeadersAndFloodsOfJoinsOrConnections) {
    Hostile h([](ServerOptions& o) {
        o.joinBurst = 5;
        o.joinsPerMinute = 1;
        o.connectionsPerClient = 6;
    });
    auto withHost = [&](const std::string& host) {
        return h.exchange("GET /api/study HTTP/1.1\r\nHost: " + host + "\r\nConnection: close\r\n\r\n");
    };
    const std::string port = std::to_string(h.study.port());
    for (const std::string& host : std::vector<std::string>{
             "evil.example", "evil.example:" + port, "localhost.evil.example", "127.0.0.1", "127.0.0.1:1",
             "127.0.0.2:" + port, "[::1]", "\xff\xfe", "", "127.0.0.1:" + port + "@evil"}) {
        h.expectRejected("Host " + host, 421, [&] { return withHost(host); });
    }
    h.expectRejected("no Host (HTTP/1.0)", 400, [&] { return h.exchange("GET /api/study HTTP/1.0\r\n\r\n"); });
    h.expectRejected("two Hosts", 400, [&] {
        return h.exchange("GET /api/study HTTP/1.1\r\nHost: " + h.host + "\r\nHost: evil.example\r\n\r\n");
    });
    EXPECT_EQ(statusOf(withHost("localhost:" + std::to_string(h.study.port()))), 200);
    EXPECT_EQ(statusOf(withHost(h.host)), 200);

    // Non-UTF-8 and control bytes in headers: a request with them works, and only well-formed UTF-8 is stored.
    HttpClient client = h.study.client();
    Participant p = joinAndStart(client);
    json start = screen();
    start["token"] = p.token;
    const std::string body = start.dump();
    const std::string response = h.exchange("POST /api/session HTTP/1.1\r\nHost: " + h.host +
                                            "\r\nUser-Agent: Mozilla\xff\xfe\xc3\r\n"
                                            "Content-Type: application/json\r\nContent-Length: " +
                                            std::to_string(body.size()) + "\r\nConnection: close\r\n\r\n" + body);
    EXPECT_EQ(statusOf(response), 200) << response;
    {
        SqliteDatabase db(h.study.databasePath().string(), false);
        SqliteStatement s = db.prepare("SELECT user_agent FROM sessions ORDER BY id DESC LIMIT 1");
        ASSERT_TRUE(s.step());
        EXPECT_EQ(s.text(0), "Mozilla\xEF\xBF\xBD\xEF\xBF\xBD\xEF\xBF\xBD");
    }
    EXPECT_NO_THROW({
        const json exported = json::parse(exportResponses(h.study.store(), "json"));
        EXPECT_TRUE(exported.is_object());
    });
    h.expectRejected("bad header name", 400, [&] {
        return h.exchange("GET /api/study HTTP/1.1\r\nHost: " + h.host + "\r\nBad\xff Name: 1\r\n\r\n");
    });
    h.expectRejected("NUL in a header", 400, [&] {
        return h.exchange(std::string("GET /api/study HTTP/1.1\r\nHost: ") + h.host + "\r\nX: a" +
                          std::string(1, '\0') + "b\r\n\r\n");
    });

    // Joins: a burst of 5 per address (one already used above), then 429 with Retry-After; nothing stored by those.
    for (int i = 0; i < 4; ++i) EXPECT_EQ(statusOf(h.request("POST", "/api/join", "{}")), 201);
    for (int i = 0; i < 5; ++i) {
        h.expectRejected("join flood", 429, [&] { return h.request("POST", "/api/join", "{}"); });
    }
    EXPECT_NE(h.request("POST", "/api/join", "{}").find("Retry-After:"), std::string::npos);
    // Another address has its own allowance.
    {
        RawSocket other(h.study.port(), "127.0.0.9");
        other.send("POST /api/join HTTP/1.1\r\nHost: " + h.host +
                   "\r\nContent-Type: application/json\r\nContent-Length: 2\r\n\r\n{}");
        EXPECT_EQ(statusOf(other.readResponse()), 201);
    }

    // Connections: 6 open at once from one address; the 7th is refused (429) and closed, the others still work.
    std::vector<std::unique_ptr<RawSocket>> open;
    for (int i = 0; i < 6; ++i) open.push_back(std::make_unique<RawSocket>(h.study.port(), "127.0.0.3"));
    std::this_thread::sleep_for(200ms);
    {
        RawSocket extra(h.study.port(), "127.0.0.3");
        EXPECT_EQ(statusOf(extra.readResponse(3s)), 429);
    }
    ASSERT_TRUE(open[0]->send("GET /api/study HTTP/1.1\r\nHost: " + h.host + "\r\n\r\n"));
    EXPECT_EQ(statusOf(open[0]->readResponse()), 200);
    RawSocket elsewhere(h.study.port(), "127.0.0.4");
    ASSERT_TRUE(elsewhere.send("GET /api/study HTTP/1.1\r\nHost: " + h.host + "\r\n\r\n"));
    EXPECT_EQ(statusOf(elsewhere.readResponse()), 200);
}

TEST(HostileRequests, PublicHostNameIsAcceptedWhenGiven) {
    Hostile h([](ServerOptions& o) { o.publicHost = "study.example.org"; });
    for (const std::string host : {"study.example.org", "Study.Example.org:443", "study.example.org:8080"})
        EXPECT_EQ(statusOf(h.exchange("GET /api/study HTTP/1.1\r\nHost: " + host + "\r\nConnection: close\r\n\r\n")),
                  200)
            << host;
    EXPECT_EQ(statusOf(h.exchange("GET /api/study HTTP/1.1\r\nHost: evil.example.org\r\nConnection: close\r\n\r\n")),
              421);
}

TEST(HostileRequests, StimuliArePinnedCachedAndNeverFollowLinksOutOfTheSet) {
    Hostile h;
    const fs::path png = h.study.folder() / "stimuli" / "png";
    fs::path first;
    for (const auto& entry : fs::directory_iterator(png))
        if (first.empty() || entry.path() < first) first = entry.path();
    // Which number serves which file: find the stimulus whose bytes are `first`.
    const std::string original = skinlab::readFile(first);
    int number = -1;
    std::string etag;
    for (int i = 0; i < 64 && number < 0; ++i) {
        const std::string response = h.request("GET", "/stimuli/" + std::to_string(i) + ".png");
        if (bodyOf(response) == original) {
            number = i;
            const std::size_t at = response.find("ETag: ");
            ASSERT_NE(at, std::string::npos);
            etag = response.substr(at + 6, response.find("\r\n", at) - at - 6);
            EXPECT_NE(response.find("Cache-Control: private, max-age=31536000, immutable"), std::string::npos);
        }
    }
    ASSERT_GE(number, 0);
    const std::string target = "/stimuli/" + std::to_string(number) + ".png";
    // Revalidation: 304 without a body.
    const std::string revalidated = h.request("GET", target, "", "If-None-Match: " + etag + "\r\n");
    EXPECT_EQ(statusOf(revalidated), 304);
    EXPECT_TRUE(bodyOf(revalidated).empty());
    EXPECT_EQ(statusOf(h.request("GET", target, "", "If-None-Match: \"other\"\r\n")), 200);
    // The file changed on disk, then replaced by a link out of the set: the verified bytes are still served.
    skinlab::writeFileAtomic(first, "changed");
    EXPECT_EQ(bodyOf(h.request("GET", target)), original);
    fs::remove(first);
    fs::create_symlink("/etc/hostname", first);
    EXPECT_EQ(bodyOf(h.request("GET", target)), original);
    // A server started on a set whose image links out of the folder refuses to start.
    fs::remove(first);
    const fs::path outside = h.study.folder() / "outside.png";
    skinlab::writeFileAtomic(outside, original); // same bytes, same sha256: only the location is wrong
    fs::create_symlink(outside, first);
    StudyStore store(h.study.databasePath());
    ServerOptions options;
    options.port = 0;
    try {
        StudyServer server(store, options);
        ADD_FAILURE() << "a stimulus linking out of the set was accepted";
    } catch (const skinlab::InputError& e) {
        EXPECT_NE(std::string(e.what()).find("outside the stimulus folder"), std::string::npos) << e.what();
    }
}

namespace {

// A study recruiting through `platform` (extra design lines after it), with the join allowance of `configure`.
std::string recruitingDesign(const std::string& recruitment) { return std::string(kDesign) + recruitment; }

struct Visit {
    std::string outcome, address, source;
};
std::vector<Visit> visits(const RunningStudy& study) {
    SqliteDatabase db(study.databasePath().string(), false);
    SqliteStatement s = db.prepare("SELECT outcome, client_address, source FROM participant_visits WHERE outcome <>"
                                   " 'session' ORDER BY id");
    std::vector<Visit> out;
    while (s.step()) out.push_back({s.text(0), s.text(1), s.text(2)});
    return out;
}

JsonAnswer joinWith(HttpClient& client, const json& recruitment, const std::string& joinKey = "") {
    json body{{"recruitment", recruitment}};
    if (!joinKey.empty()) body["join_key"] = joinKey;
    return postJson(client, "/api/join", body);
}

} // namespace

// A platform id is public knowledge (it shows in the platform's messages, screenshots, a participant's other
// studies): alone, it must never hand out a participation. Resuming needs the join key of the first join (the same
// browser) or the platform's per-attempt session id of the first join (the same platform link).
TEST(HostileRequests, PlatformIdAloneNeverTakesOverAParticipation) {
    RunningStudy study(recruitingDesign("[recruitment]\nplatform = \"mturk\"\n"));
    HttpClient client = study.client();
    const json worker{{"workerId", "A1B2C3D4E5F6"},
                      {"assignmentId", "3ASSIGNMENTAAAAAAAAAAAAAAAAA"},
                      {"hitId", "3HITAAAAAAAAAAAAAAAAAAAAAAAA"}};
    const JsonAnswer first = joinWith(client, worker, "browser-secret-of-the-worker-0001");
    ASSERT_EQ(first.status, 201) << first.raw;
    const std::string token = first.body["token"];

    // The attack: the worker id alone, then with a wrong key, another assignment, or in lower case.
    json otherAssignment = worker;
    otherAssignment["assignmentId"] = "3ASSIGNMENTBBBBBBBBBBBBBBBBB";
    json lower = otherAssignment;
    lower["workerId"] = "a1b2c3d4e5f6";
    const std::vector<std::pair<std::string, JsonAnswer>> attempts{
        {"the worker id alone", joinWith(client, {{"workerId", "A1B2C3D4E5F6"}})},
        {"a wrong join key", joinWith(client, {{"workerId", "A1B2C3D4E5F6"}}, "guessed-key")},
        {"another assignment", joinWith(client, otherAssignment)},
        {"lower case, another assignment", joinWith(client, lower, "guessed-key")}};
    for (const auto& [what, answer] : attempts) {
        EXPECT_EQ(answer.status, 409) << what << ": " << answer.raw;
        EXPECT_FALSE(answer.body.contains("token")) << what << ": " << answer.raw;
        EXPECT_EQ(answer.raw.find(token), std::string::npos) << what << ": the token was handed out";
        EXPECT_NE(answer.body.value("error", "").find("workerId: this mturk id has already started this study"),
                  std::string::npos)
            << answer.raw;
    }
    EXPECT_EQ(study.store().status().size(), 1u) << "a refused attempt created a participant";

    // The worker's own browser (its join key) and the worker's own assignment (another browser) resume.
    const JsonAnswer sameBrowser = joinWith(client, otherAssignment, "browser-secret-of-the-worker-0001");
    EXPECT_EQ(sameBrowser.status, 200) << sameBrowser.raw;
    EXPECT_EQ(sameBrowser.body.value("token", ""), token);
    const JsonAnswer sameAssignment = joinWith(client, worker);
    EXPECT_EQ(sameAssignment.status, 200) << sameAssignment.raw;
    EXPECT_EQ(sameAssignment.body.value("token", ""), token);

    // The researcher sees them on the dashboard.
    const JsonAnswer board =
        get(client, "/api/researcher/dashboard", {{"Authorization", std::string("Bearer ") + kResearcherToken}});
    ASSERT_EQ(board.status, 200) << board.raw;
    EXPECT_EQ(board.body["participants"][0]["refused_attempts"], 4);
    EXPECT_EQ(board.body["participants"][0]["resumes"], 2);
    // Every refused attempt and every resume is recorded with its address.
    const std::vector<Visit> recorded = visits(study);
    ASSERT_EQ(recorded.size(), 6u);
    for (std::size_t i = 0; i < recorded.size(); ++i) {
        EXPECT_EQ(recorded[i].outcome, i < 4 ? "refused" : "resumed") << i;
        EXPECT_EQ(recorded[i].address, "127.0.0.1");
        EXPECT_EQ(recorded[i].source, "peer");
    }
}

// Others knowing a participant's platform id cannot use up the participant's resumes: 110 refused joins with the id
// from three addresses, then the participant resumes from their own browser (join key) and their own platform link
// (session id). The researcher sees the refused attempts (the dashboard's refused platform ids).
TEST(HostileRequests, RefusedJoinsByOthersNeverLockTheParticipantOut) {
    RunningStudy study(recruitingDesign("[recruitment]\nplatform = \"prolific\"\ncompletion_code = \"C1ABCDEF\"\n"));
    const std::string pid = "5f8a1b2c3d4e5f6a7b8c9d0e";
    const json own{{"PROLIFIC_PID", pid}, {"SESSION_ID", "60bb1b2c3d4e5f6a7b8c9d22"}};
    HttpClient owner = study.client();
    const JsonAnswer first = joinWith(owner, own, "browser-secret-of-the-owner-0001");
    ASSERT_EQ(first.status, 201) << first.raw;

    int refused = 0;
    for (int i = 0; i < 110; ++i) {
        HttpClient other = study.client();
        other.setSourceAddress("127.0.0." + std::to_string(2 + i % 3));
        const JsonAnswer attempt = joinWith(other, {{"PROLIFIC_PID", pid}});
        EXPECT_EQ(attempt.status, 409) << i << ": " << attempt.raw;
        refused += attempt.status == 409;
    }
    EXPECT_EQ(refused, 110);

    // The owner's own browser and the owner's own platform link (a new browser) both resume.
    const JsonAnswer sameBrowser = joinWith(owner, own, "browser-secret-of-the-owner-0001");
    EXPECT_EQ(sameBrowser.status, 200) << sameBrowser.raw;
    EXPECT_EQ(sameBrowser.body.value("token", ""), first.body["token"]);
    HttpClient newBrowser = study.client();
    const JsonAnswer sameLink = joinWith(newBrowser, own, "another-browser-of-the-owner-0002");
    EXPECT_EQ(sameLink.status, 200) << sameLink.raw;
    EXPECT_EQ(sameLink.body.value("token", ""), first.body["token"]);

    // The researcher sees the refused attempts: how many (rows kept up to the cap), from how many addresses.
    const JsonAnswer board =
        get(owner, "/api/researcher/dashboard", {{"Authorization", std::string("Bearer ") + kResearcherToken}});
    ASSERT_EQ(board.status, 200) << board.raw;
    EXPECT_EQ(board.body["participants"][0]["resumes"], 2);
    EXPECT_EQ(board.body["participants"][0]["refused_attempts"], kMaxVisitsPerParticipant);
    ASSERT_EQ(board.body["refused_platform_ids"].size(), 1u) << board.raw;
    const json& row = board.body["refused_platform_ids"][0];
    EXPECT_EQ(row["observer"], first.body["observer"]);
    EXPECT_EQ(row["platform"], "prolific");
    EXPECT_EQ(row["external_id"], pid);
    EXPECT_EQ(row["attempts"], kMaxVisitsPerParticipant);
    EXPECT_EQ(row["attempts_capped"], true);
    EXPECT_EQ(row["addresses"], 3);
}

// Guessing the researcher token: every wrong token is logged with the client's address (never the token); after a
// burst of 10 the client's network gets 429 with Retry-After and its tokens are not compared, not even the right
// one; another network is not affected.
TEST(HostileRequests, WrongResearcherTokensAreThrottledAndLogged) {
    std::ostringstream log; // the server's log (added before it starts, removed after it stopped)
    const auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(log);
    spdlog::default_logger()->sinks().push_back(sink);
    struct RemoveSink {
        std::shared_ptr<spdlog::sinks::sink> sink;
        ~RemoveSink() { std::erase(spdlog::default_logger()->sinks(), sink); }
    } removeSink{sink};
    RunningStudy study(kDesign);

    HttpClient guesser = study.client();
    guesser.setSourceAddress("127.0.0.7");
    auto status = [&](HttpClient& client, const std::string& token) {
        return client.get("/api/researcher/status", {{"Authorization", "Bearer " + token}});
    };
    for (int i = 0; i < 10; ++i) {
        const HttpAnswer wrong = status(guesser, "guessed-token-" + std::to_string(1000 + i));
        EXPECT_EQ(wrong.status, 403) << i << ": " << wrong.body;
    }
    const HttpAnswer throttled = status(guesser, "guessed-token-2000");
    EXPECT_EQ(throttled.status, 429) << throttled.body;
    EXPECT_GE(std::atoi(throttled.header("Retry-After").c_str()), 1) << throttled.header("Retry-After");
    EXPECT_EQ(status(guesser, kResearcherToken).status, 429) << "a throttled network's token was compared";

    HttpClient researcher = study.client();
    EXPECT_EQ(status(researcher, kResearcherToken).status, 200);

    spdlog::default_logger()->flush();
    const std::string text = log.str();
    std::size_t warnings = 0;
    for (std::size_t at = 0; (at = text.find("researcher token: wrong token from 127.0.0.7", at)) != std::string::npos;
         ++at)
        ++warnings;
    EXPECT_EQ(warnings, 10u) << text;
    EXPECT_EQ(text.find("guessed-token"), std::string::npos) << "a token was logged: " << text;
    EXPECT_EQ(text.find(kResearcherToken), std::string::npos) << "the token was logged: " << text;
}

// One person, one platform id, whatever the letter case (or, on generic systems, trailing dots and blanks).
TEST(HostileRequests, PlatformIdsAreOneParticipantWhateverTheirSpelling) {
    {
        RunningStudy study(
            recruitingDesign("[recruitment]\nplatform = \"prolific\"\ncompletion_code = \"C1ABCDEF\"\n"));
        HttpClient client = study.client();
        const std::string pid = "5f8a1b2c3d4e5f6a7b8c9d0e";
        std::string upper = pid, mixed = pid;
        for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
        for (std::size_t i = 0; i < mixed.size(); i += 2)
            mixed[i] = static_cast<char>(std::toupper(static_cast<unsigned char>(mixed[i])));
        EXPECT_EQ(joinWith(client, {{"PROLIFIC_PID", pid}}, "key-one-0001").status, 201);
        EXPECT_EQ(joinWith(client, {{"PROLIFIC_PID", upper}}, "key-two-0002").status, 409);
        EXPECT_EQ(joinWith(client, {{"PROLIFIC_PID", mixed}}, "key-three-0003").status, 409);
        const JsonAnswer resumed = joinWith(client, {{"PROLIFIC_PID", upper}}, "key-one-0001");
        EXPECT_EQ(resumed.status, 200) << resumed.raw;
        const std::vector<ParticipantStatus> status = study.store().status();
        ASSERT_EQ(status.size(), 1u);
        EXPECT_EQ(status[0].external->id, pid);
    }
    {
        RunningStudy study(recruitingDesign("[recruitment]\nplatform = \"mturk\"\n"));
        HttpClient client = study.client();
        EXPECT_EQ(joinWith(client, {{"workerId", "a1b2c3d4e5f6"}}, "key-one-0001").status, 201);
        EXPECT_EQ(joinWith(client, {{"workerId", "A1B2C3D4E5F6"}}, "key-two-0002").status, 409);
        ASSERT_EQ(study.store().status().size(), 1u);
        EXPECT_EQ(study.store().status()[0].external->id, "A1B2C3D4E5F6");
    }
    {
        RunningStudy study(recruitingDesign("[recruitment]\nplatform = \"generic\"\nid_parameter = \"code\"\n"));
        HttpClient client = study.client();
        EXPECT_EQ(joinWith(client, {{"code", "Abc.Def"}}, "key-one-0001").status, 201);
        EXPECT_EQ(joinWith(client, {{"code", "abc.def."}}, "key-two-0002").status, 409);
        EXPECT_EQ(joinWith(client, {{"code", " ABC.DEF.. "}}, "key-three-0003").status, 409);
        EXPECT_EQ(joinWith(client, {{"code", "abc.deg"}}, "key-four-0004").status, 201);
        ASSERT_EQ(study.store().status().size(), 2u);
        EXPECT_EQ(study.store().status()[0].external->id, "abc.def");
    }
    EXPECT_EQ(normalisedExternalId("prolific", "5F8A1B2C3D4E5F6A7B8C9D0E"), "5f8a1b2c3d4e5f6a7b8c9d0e");
    EXPECT_EQ(normalisedExternalId("mturk", "a1b2c3"), "A1B2C3");
    EXPECT_EQ(normalisedExternalId("sona", "\t48213. "), "48213");
}

// Every page load starts a session; one token cannot start thousands (the database, the dashboard's JSON and the
// exports would grow without bound).
TEST(HostileRequests, SessionsPerParticipantAreBounded) {
    for (const int limit : {4, kDefaultSessionsPerParticipant}) {
        Hostile h([limit](ServerOptions& o) {
            if (limit != kDefaultSessionsPerParticipant) o.sessionsPerParticipant = limit;
        });
        HttpClient client = h.study.client();
        Participant p = joinAndStart(client);
        json start = screen();
        start["token"] = p.token;
        for (int i = 1; i < limit; ++i) ASSERT_EQ(postJson(client, "/api/session", start).status, 200) << i;
        for (int i = 0; i < 3; ++i)
            h.expectRejected("session beyond the limit", 429,
                             [&] { return h.request("POST", "/api/session", start.dump()); });
        SqliteDatabase db(h.study.databasePath().string(), false);
        SqliteStatement s = db.prepare("SELECT COUNT(*) FROM sessions");
        ASSERT_TRUE(s.step());
        EXPECT_EQ(s.integer(0), limit);
        // Every page load of the participation is recorded with its address.
        SqliteStatement v = db.prepare("SELECT COUNT(*) FROM participant_visits WHERE outcome = 'session' AND"
                                       " client_address = '127.0.0.1' AND source = 'peer'");
        ASSERT_TRUE(v.step());
        EXPECT_EQ(v.integer(0), limit);
        // Answers still go on in the sessions it has.
        EXPECT_EQ(postJson(client, "/api/response", answerBody(p, p.state["trial"]["id"], "left")).status, 200);
    }
}

// The join allowance is per client network: an IPv6 /64 is one client (a subscriber holds all of it), and the
// table of allowances never forgets a client that is being refused because others flood it with new addresses.
TEST(HostileRequests, JoinLimitCountsIpv6NetworksAndSurvivesAddressSprays) {
    Hostile h([](ServerOptions& o) {
        o.joinBurst = 5;
        o.joinsPerMinute = 1;
        o.trustedProxies = {"127.0.0.1"}; // the test's requests come "through a proxy" from chosen addresses
    });
    auto joinFrom = [&](const std::string& address, const std::string& body = "{}") {
        return statusOf(h.request("POST", "/api/join", body, "X-Forwarded-For: " + address + "\r\n"));
    };
    for (int i = 1; i <= 5; ++i) EXPECT_EQ(joinFrom("2001:db8:1:2::" + std::to_string(i)), 201) << i;
    // Another address of the same /64, and a label probe from it, are refused; nothing is stored.
    h.expectRejected("the same /64, another address", 429, [&] {
        return h.request("POST", "/api/join", "{}", "X-Forwarded-For: 2001:db8:1:2:ffff:1:2:3\r\n");
    });
    h.expectRejected("a label probe from the same /64", 429, [&] {
        return h.request("POST", "/api/join", R"({"label":"P001"})", "X-Forwarded-For: 2001:db8:1:2:aaaa::9\r\n");
    });
    EXPECT_EQ(joinFrom("2001:db8:1:3::1"), 201) << "the next /64 is another client";
    // Taken labels cost the allowance too: at most the burst of probes per network.
    int answered = 0;
    for (int i = 0; i < 10; ++i)
        answered += joinFrom("2001:db8:9:9::" + std::to_string(i),
                             R"({"label":"P00)" + std::to_string(i % 3 + 1) + "\"}") != 429;
    EXPECT_EQ(answered, 5);

    // The table: a spray of new addresses evicts the fullest buckets, not the one of a client being refused.
    JoinLimiter limiter(1, 5, 1000);
    const auto now = JoinLimiter::Clock::now();
    double retry = 0;
    for (int i = 0; i < 5; ++i) EXPECT_TRUE(limiter.allow("203.0.113.7", retry, now));
    EXPECT_FALSE(limiter.allow("203.0.113.7", retry, now));
    for (int i = 0; i <= 100000; ++i) {
        const std::string address =
            "10." + std::to_string(i >> 16) + "." + std::to_string((i >> 8) & 255) + "." + std::to_string(i & 255);
        limiter.allow(address, retry, now + std::chrono::milliseconds(i / 100));
    }
    EXPECT_LE(limiter.size(), 1000u);
    EXPECT_FALSE(limiter.allow("203.0.113.7", retry, now + std::chrono::seconds(2)))
        << "the spray reset the refused client's allowance";
    EXPECT_TRUE(limiter.allow("203.0.113.7", retry, now + std::chrono::seconds(62))) << "it refills as configured";
    EXPECT_EQ(clientNetwork("2001:db8:1:2:3:4:5:6"), "2001:db8:1:2::/64");
    EXPECT_EQ(clientNetwork("2001:DB8:1:2::"), "2001:db8:1:2::/64");
    EXPECT_EQ(clientNetwork("2001:db8::1", 48), "2001:db8::/48");
    EXPECT_EQ(clientNetwork("::ffff:192.0.2.1"), "192.0.2.1");
    EXPECT_EQ(clientNetwork("192.0.2.1"), "192.0.2.1");
}

// Participant tokens stay out of URLs (and so out of proxies' logs and the browser's history); study files and
// their backups are readable by their owner only.
TEST(HostileRequests, TokensStayOutOfUrlsAndStudyFilesArePrivate) {
    Hostile h;
    HttpClient client = h.study.client();
    Participant p = joinAndStart(client);
    h.expectRejected("token in the URL", 400, [&] { return h.request("GET", "/api/state?token=" + p.token); });
    h.expectRejected("no token", 400, [&] { return h.request("GET", "/api/state"); });
    EXPECT_EQ(statusOf(h.request("GET", "/api/state", "", "X-Skinlab-Token: " + p.token + "\r\n")), 200);

    auto mode = [](const fs::path& file) {
        struct stat st {};
        EXPECT_EQ(::stat(file.c_str(), &st), 0) << file;
        return st.st_mode & 0777;
    };
    const mode_t previous = ::umask(022); // the usual umask, which leaves files readable by everyone
    EXPECT_EQ(mode(h.study.databasePath()), 0600u);
    EXPECT_EQ(mode(h.study.databasePath().string() + "-wal"), 0600u);
    EXPECT_EQ(mode(h.study.databasePath().string() + "-shm"), 0600u);
    const fs::path copy = h.study.folder() / "backup.db";
    backupStudy(h.study.databasePath(), copy, false);
    EXPECT_EQ(mode(copy), 0600u);
    ::umask(previous);
}

// Smaller defects: framing, transfer codings the server cannot decode, a slow body, spreadsheet formulas in exports.
TEST(HostileRequests, FramingTransferCodingsSlowBodiesAndFormulaCells) {
    Hostile h([](ServerOptions& o) { o.requestTimeout = 1500ms; });
    for (const std::string target : {"/", "/researcher", "/api/study"}) {
        const std::string response = h.request("GET", target);
        EXPECT_NE(response.find("X-Frame-Options: DENY"), std::string::npos) << target;
        EXPECT_NE(response.find("frame-ancestors 'none'"), std::string::npos) << target;
    }
    // A body in a coding the server does not decode: 501 and closed, and the bytes after the header (here a whole
    // second request) are never taken as the next request.
    const std::string smuggled = "POST /api/join HTTP/1.1\r\nHost: " + h.host +
                                 "\r\nContent-Type: application/json\r\nContent-Length: 2\r\n\r\n{}";
    for (const std::string coding : {"identity", "gzip", "chunked, identity", "gzip, chunked, identity"}) {
        const std::string before = h.study.fingerprint();
        RawSocket socket(h.study.port());
        ASSERT_TRUE(socket.send("POST /api/join HTTP/1.1\r\nHost: " + h.host +
                                "\r\nContent-Type: application/json\r\nTransfer-Encoding: " + coding + "\r\n\r\n" +
                                smuggled));
        const std::string response = socket.readResponse(5s);
        EXPECT_EQ(statusOf(response), 501) << coding << ": " << response;
        EXPECT_EQ(socket.readResponse(1s), "") << coding << ": the body was read as a second request";
        EXPECT_TRUE(socket.closedByServer(3s)) << coding;
        EXPECT_EQ(h.study.fingerprint(), before) << coding;
    }
    // A body sent a byte at a time: cut at the request deadline, however steadily it trickles.
    {
        const std::string before = h.study.fingerprint();
        RawSocket socket(h.study.port());
        ASSERT_TRUE(socket.send("POST /api/join HTTP/1.1\r\nHost: " + h.host +
                                "\r\nContent-Type: application/json\r\nContent-Length: 100\r\n\r\n"));
        const auto start = std::chrono::steady_clock::now();
        std::string response;
        for (int i = 0; i < 40 && response.empty(); ++i) {
            socket.send(" ");
            response = socket.readResponse(200ms);
        }
        EXPECT_EQ(statusOf(response), 408) << response;
        EXPECT_LT(std::chrono::steady_clock::now() - start, 4s);
        EXPECT_EQ(h.study.fingerprint(), before);
    }
    // Client-chosen text that a spreadsheet would run as a formula is exported as text.
    HttpClient client = h.study.client();
    ASSERT_EQ(postJson(client, "/api/join", {{"label", "-2-3"}}).status, 201);
    const std::string token = h.study.store().status().back().participant.token;
    json start = screen();
    start["token"] = token;
    const JsonAnswer session = postJson(client, "/api/session", start);
    Participant p{token, session.body["session"].get<std::int64_t>(), session.body};
    ASSERT_EQ(postJson(client, "/api/response", answerBody(p, p.state["trial"]["id"], "left")).status, 200);
    const std::string csv = exportResponses(h.study.store(), "csv");
    EXPECT_NE(csv.find("\n'-2-3,"), std::string::npos) << csv.substr(0, 400);
    EXPECT_EQ(csv.find("\n-2-3,"), std::string::npos);
    EXPECT_EQ(csvTextField("=HYPERLINK(\"x\")"), "\"'=HYPERLINK(\"\"x\"\")\"");
    EXPECT_EQ(csvTextField("@SUM(1)"), "'@SUM(1)");
    EXPECT_EQ(csvTextField("+1"), "'+1");
    EXPECT_EQ(csvTextField("P001"), "P001");
}

// The researcher's export is streamed from a snapshot: chunks of bounded size, produced as the client reads them,
// from a read transaction of its own, so answers go on while it is read (none of them in it), and memory holds one
// piece whatever the study's size.
TEST(HostileRequests, ExportsStreamInBoundedChunksFromASnapshotWhileAnswersGoOn) {
    Hostile h;
    StudyStore& store = h.study.store();
    // Enough answers for several pieces of JSON.
    for (int i = 0; i < 14; ++i) {
        const ParticipantRecord p = store.join("", "bulk-" + std::to_string(i));
        const std::int64_t session = store.startSession(p.id, "test", 1280, 800, 1.0);
        while (const auto trial = store.nextTrial(p.id)) store.recordResponse(storeAnswer(p, session, *trial, "left"));
    }
    HttpClient client = h.study.client();
    Participant late = joinAndStart(client);
    const std::int64_t before = store.responseCount();
    const std::string authorization = "Authorization: Bearer " + std::string(kResearcherToken) + "\r\n";
    for (const std::string format : {"json", "csv"}) {
        RawSocket reader(h.study.port());
        ASSERT_TRUE(reader.send("GET /api/researcher/export?format=" + format + " HTTP/1.1\r\nHost: " + h.host +
                                "\r\n" + authorization + "\r\n"));
        const std::string head = reader.readHead();
        ASSERT_EQ(statusOf(head), 200) << head;
        EXPECT_NE(head.find("Transfer-Encoding: chunked"), std::string::npos) << head;
        EXPECT_EQ(head.find("Content-Length"), std::string::npos) << head;
        // The export has begun (its snapshot is taken): an answer now is acknowledged and stored, and not in it.
        const JsonAnswer answered =
            postJson(client, "/api/response", answerBody(late, late.state["trial"]["id"], "left"));
        ASSERT_EQ(answered.status, 200) << answered.raw;
        late.state = answered.body;
        std::vector<std::size_t> sizes;
        std::string body;
        ASSERT_TRUE(reader.readChunks(sizes, body)) << format;
        EXPECT_GE(sizes.size(), format == "json" ? 3u : 1u) << format << ": " << body.size() << " bytes in one piece";
        for (const std::size_t size : sizes) EXPECT_LE(size, ResponseExport::kPieceBytes + 8192) << format;
        const std::int64_t inSnapshot = store.responseCount() - 1;
        if (format == "json") {
            const json exported = json::parse(body);
            EXPECT_EQ(static_cast<std::int64_t>(exported["responses"].size()), inSnapshot);
        } else {
            EXPECT_EQ(std::count(body.begin(), body.end(), '\n'), inSnapshot + 1) << "header and one line per answer";
        }
        // The connection stays usable after the last chunk (kept alive).
        ASSERT_TRUE(reader.send("GET /api/study HTTP/1.1\r\nHost: " + h.host + "\r\n\r\n"));
        EXPECT_EQ(statusOf(reader.readResponse()), 200);
    }
    EXPECT_EQ(store.responseCount(), before + 2);
    // The stream as a whole is the export as a library call makes it, in every format.
    for (const std::string format : {"json", "csv", "pwcmp"}) {
        RawSocket reader(h.study.port());
        ASSERT_TRUE(reader.send("GET /api/researcher/export?format=" + format + " HTTP/1.1\r\nHost: " + h.host +
                                "\r\n" + authorization + "\r\n"));
        ASSERT_EQ(statusOf(reader.readHead()), 200);
        std::vector<std::size_t> sizes;
        std::string body;
        ASSERT_TRUE(reader.readChunks(sizes, body));
        EXPECT_EQ(body, exportResponses(store, format)) << format;
    }
    // HTTP/1.0 has no chunks: the body ends with the connection. HEAD: the header alone.
    {
        RawSocket reader(h.study.port());
        ASSERT_TRUE(reader.send("GET /api/researcher/export?format=csv HTTP/1.0\r\nHost: " + h.host + "\r\n" +
                                authorization + "\r\n"));
        const std::string response = reader.readUntilClosed();
        EXPECT_EQ(statusOf(response), 200) << response.substr(0, 300);
        EXPECT_EQ(response.find("chunked"), std::string::npos);
        EXPECT_EQ(bodyOf(response), exportResponses(store, "csv"));
    }
    {
        RawSocket reader(h.study.port());
        ASSERT_TRUE(
            reader.send("HEAD /api/researcher/export HTTP/1.1\r\nHost: " + h.host + "\r\n" + authorization + "\r\n"));
        EXPECT_EQ(statusOf(reader.readHead()), 200);
        ASSERT_TRUE(reader.send("GET /api/study HTTP/1.1\r\nHost: " + h.host + "\r\n\r\n"));
        EXPECT_EQ(statusOf(reader.readResponse()), 200) << "the HEAD answer carried a body";
    }
    h.expectRejected("include_session_ids=yes", 400, [&] {
        return h.request("GET", "/api/researcher/export?include_session_ids=yes", "", authorization);
    });
}

// Idle connections from many addresses, each under its cap, can fill every connection slot: a newcomer is still
// served (a connection idle long, of the network holding the most, makes room), and when every slot is in the middle of a request the newcomer
// waits in the listen backlog until one is free — never a 429 meant for a single flooding network.
TEST(HostileRequests, IdleConnectionsFromManyAddressesNeverKeepANewcomerOut) {
    // A real HttpServer with few slots: 48 in all, 8 per address, the last 8 (or none) kept for newcomers.
    struct SmallServer {
        HttpServer server;
        int port;
        std::thread serving;
        explicit SmallServer(int reserve)
            : server([](const HttpRequest&) { return HttpResponse{200, "text/plain", {}, "ok", nullptr, {}}; },
                     limits(reserve)),
              port(server.bind("127.0.0.1", 0)), serving([this] { server.run(); }) {}
        ~SmallServer() {
            server.stop();
            serving.join();
        }
        static HttpLimits limits(int reserve) {
            HttpLimits l;
            l.maxConnections = 48;
            l.reserveConnections = reserve;
            l.connectionsPerClient = 8;
            l.requestTimeout = 30s;
            return l;
        }
        void waitForOpen(int n) {
            for (int i = 0; i < 500 && server.openConnections() != n; ++i) std::this_thread::sleep_for(10ms);
        }
    };
    const std::string request = "GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n";
    {
        // A participant's kept-alive connection, then six addresses with 8 idle connections each (the last 7):
        // every slot (48) taken, none of them over its cap.
        SmallServer small(8);
        RawSocket participant(small.port, "127.0.5.1");
        ASSERT_TRUE(participant.send(request));
        ASSERT_EQ(statusOf(participant.readResponse(5s)), 200);
        std::vector<std::unique_ptr<RawSocket>> idle;
        for (int address = 1; address <= 6; ++address)
            for (int k = 0; k < (address < 6 ? 8 : 7); ++k) {
                idle.push_back(std::make_unique<RawSocket>(small.port, ("127.0.1." + std::to_string(address)).c_str()));
                ASSERT_TRUE(idle.back()->connected());
                std::this_thread::sleep_for(5ms); // an order of age
            }
        std::this_thread::sleep_for(300ms);
        EXPECT_LE(small.server.openConnections(), 48);
        for (int newcomer = 1; newcomer <= 3; ++newcomer) {
            RawSocket fresh(small.port, ("127.0.2." + std::to_string(newcomer)).c_str());
            ASSERT_TRUE(fresh.send(request));
            EXPECT_EQ(statusOf(fresh.readResponse(5s)), 200) << "newcomer " << newcomer;
        }
        // The flooding networks' connections idle longest made room; the youngest are still open and served, and
        // so is the participant's, although it waited longer than any: its network holds one connection.
        EXPECT_TRUE(idle.front()->closedByServer(2s));
        ASSERT_TRUE(idle.back()->send(request));
        EXPECT_EQ(statusOf(idle.back()->readResponse(5s)), 200);
        ASSERT_TRUE(participant.send(request));
        EXPECT_EQ(statusOf(participant.readResponse(5s)), 200);
    }
    {
        // Every slot in the middle of a request (headers begun, not finished): nothing idle to close. A newcomer's
        // connection waits in the listen backlog, unanswered, and is served as soon as a slot is free.
        SmallServer small(0);
        std::vector<std::unique_ptr<RawSocket>> busy;
        for (int address = 1; address <= 6; ++address)
            for (int k = 0; k < 8; ++k) {
                busy.push_back(std::make_unique<RawSocket>(small.port, ("127.0.3." + std::to_string(address)).c_str()));
                ASSERT_TRUE(busy.back()->send("GET / HTTP/1.1\r\n"));
            }
        small.waitForOpen(48);
        EXPECT_EQ(small.server.openConnections(), 48);
        RawSocket waiting(small.port, "127.0.4.1");
        ASSERT_TRUE(waiting.connected());
        ASSERT_TRUE(waiting.send(request));
        EXPECT_EQ(waiting.readResponse(1s), "") << "answered while every slot was busy";
        ASSERT_TRUE(busy.front()->send("Host: 127.0.0.1\r\n\r\n"));
        EXPECT_EQ(statusOf(busy.front()->readResponse(5s)), 200);
        busy.erase(busy.begin()); // closes it: a slot is free
        EXPECT_EQ(statusOf(waiting.readResponse(5s)), 200);
    }
}
