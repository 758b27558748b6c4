// The request checks and the route table of net/ (net/request_checks.h, net/route_table.h).
#include "net/request_checks.h"
#include "net/request_error.h"
#include "net/route_table.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <functional>
#include <string>
#include <utility>
#include <vector>

using namespace skinlab::net;

namespace {

HttpRequest request(const std::string& method, const std::string& path,
                    std::vector<std::pair<std::string, std::string>> headers = {}) {
    HttpRequest r;
    r.method = method;
    r.path = path;
    r.target = path;
    r.headers = std::move(headers);
    return r;
}

int statusOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const RequestError& e) {
        return e.status();
    }
    return 0;
}

} // namespace

TEST(HostRule, AcceptsTheBoundAddressAndLoopbackNamesOnly) {
    const HostRule loopback{"127.0.0.1", 8080, ""};
    EXPECT_TRUE(loopback.allows("127.0.0.1:8080"));
    EXPECT_TRUE(loopback.allows("LOCALHOST:8080"));
    EXPECT_FALSE(loopback.allows("127.0.0.1:8081"));        // another port
    EXPECT_FALSE(loopback.allows("127.0.0.1"));             // no port
    EXPECT_FALSE(loopback.allows("attacker.example:8080")); // DNS rebinding
    EXPECT_FALSE(loopback.allows(""));
    const HostRule any{"::", 9000, ""};
    EXPECT_TRUE(any.allows("[::1]:9000"));
    EXPECT_TRUE(any.allows("192.0.2.7:9000"));
    EXPECT_FALSE(any.allows("[::1]x9000"));
    EXPECT_FALSE(any.allows("[::1:9000"));
    const HostRule proxied{"127.0.0.1", 8080, "Study.Example.org"};
    EXPECT_TRUE(proxied.allows("study.example.org")); // any port: the proxy's
    EXPECT_TRUE(proxied.allows("study.example.org:443"));
    EXPECT_FALSE(proxied.allows("other.example.org:8080"));
}

TEST(SameOrigin, RefusesOtherSitesAndRepeatedHeaders) {
    const auto check = [](std::vector<std::pair<std::string, std::string>> headers, int port = 8080) {
        return statusOf([&] { checkSameOrigin(request("POST", "/api/x", std::move(headers)), port); });
    };
    EXPECT_EQ(check({{"host", "127.0.0.1:8080"}}), 0); // not a browser: nothing to compare
    EXPECT_EQ(check({{"host", "127.0.0.1:8080"}, {"origin", "http://127.0.0.1:8080"}}), 0);
    EXPECT_EQ(check({{"host", "127.0.0.1:8080"}, {"sec-fetch-site", "same-origin"}}), 0);
    EXPECT_EQ(check({{"host", "127.0.0.1:8080"}, {"origin", "http://evil.example"}}), 403);
    EXPECT_EQ(check({{"host", "127.0.0.1:8080"}, {"sec-fetch-site", "cross-site"}}), 403);
    EXPECT_EQ(check({{"host", "127.0.0.1:8080"}, {"origin", "a"}, {"origin", "b"}}), 400);
    EXPECT_EQ(check({{"host", "h:80"}, {"origin", "http://h"}}, 80), 0); // the default port left out
}

TEST(Tokens, BearerAndConstantTimeComparison) {
    EXPECT_EQ(bearerToken(request("GET", "/", {{"authorization", "Bearer abc"}})), "abc");
    EXPECT_FALSE(bearerToken(request("GET", "/", {{"authorization", "Basic abc"}})));
    EXPECT_FALSE(bearerToken(request("GET", "/")));
    EXPECT_TRUE(constantTimeEqual("secret", "secret"));
    EXPECT_FALSE(constantTimeEqual("secret", "secreT"));
    EXPECT_FALSE(constantTimeEqual("secret", "secret2"));
}

namespace {
struct Counter {
    int guarded = 0;
};
} // namespace

TEST(RouteTable, FirstMatchAnswersGuardedRoutesRunTheGuardUnknownIs404) {
    using C = Counter;
    using R = const HttpRequest&;
    const RouteTable<Counter> routes{
        {"GET", "/", false, [](C&, R) { return jsonResponse(200, "page"); }},
        {"POST", "/api/do", true, [](C&, R) { return jsonResponse(200, "done"); }},
        {"*", "/api/*", true, [](C&, R) -> HttpResponse { throw RequestError(404, "not found"); }},
    };
    Counter counter;
    const auto guard = [&](R) { ++counter.guarded; };
    EXPECT_EQ(routes.answer(counter, request("GET", "/"), guard).body, "\"page\"");
    EXPECT_EQ(counter.guarded, 0);
    EXPECT_EQ(routes.answer(counter, request("POST", "/api/do"), guard).body, "\"done\"");
    EXPECT_EQ(counter.guarded, 1);
    // An unknown API path is guarded too (any method), so it answers nothing without the check.
    EXPECT_EQ(statusOf([&] { routes.answer(counter, request("PUT", "/api/other"), guard); }), 404);
    EXPECT_EQ(counter.guarded, 2);
    EXPECT_EQ(statusOf([&] { routes.answer(counter, request("GET", "/elsewhere"), guard); }), 404);
    EXPECT_EQ(statusOf([&] { routes.answer(counter, request("POST", "/"), guard); }), 404);
    EXPECT_EQ(counter.guarded, 2);
}
