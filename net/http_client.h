#pragma once
// A small blocking HTTP/1.1 client (Boost.Beast) for the simulated observers, the tests and the benchmarks: one
// kept-alive connection, reopened when the server closed it, with a timeout on every request.
#include <chrono>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace skinlab::net {

using HttpHeaders = std::vector<std::pair<std::string, std::string>>;

struct HttpAnswer {
    int status = 0; // 0 = no answer (refused, reset, timed out)
    std::string body;
    HttpHeaders headers; // names in lower case
    std::string error;   // why there is no answer
    std::string header(std::string_view name) const;
};

class HttpClient {
public:
    HttpClient(std::string host, int port);
    ~HttpClient();
    HttpClient(HttpClient&&) noexcept;
    HttpClient(const HttpClient&) = delete;
    HttpClient& operator=(const HttpClient&) = delete;

    // Sends one request on the kept-alive connection (opening it when needed). A request that fails on a reused
    // connection the server had closed meanwhile is sent once more on a fresh one; otherwise status 0.
    HttpAnswer send(const std::string& method, const std::string& target, const std::string& body = "",
                    const HttpHeaders& headers = {}, const std::string& contentType = "application/json");
    HttpAnswer get(const std::string& target, const HttpHeaders& headers = {}) {
        return send("GET", target, "", headers);
    }
    HttpAnswer post(const std::string& target, const std::string& body,
                    const std::string& contentType = "application/json") {
        return send("POST", target, body, {}, contentType);
    }

    void setTimeout(std::chrono::milliseconds timeout) { timeout_ = timeout; }
    void setKeepAlive(bool keepAlive) { keepAlive_ = keepAlive; }
    void setUserAgent(std::string userAgent) { userAgent_ = std::move(userAgent); }
    // Connects from this local address (e.g. 127.0.0.5: loopback clients that look like different machines).
    void setSourceAddress(std::string address) { sourceAddress_ = std::move(address); }
    void disconnect();

private:
    struct Connection;
    HttpAnswer attempt(const std::string& method, const std::string& target, const std::string& body,
                       const HttpHeaders& headers, const std::string& contentType, bool& reused);
    std::string host_;
    int port_;
    std::chrono::milliseconds timeout_{30000};
    bool keepAlive_ = true;
    std::string userAgent_ = "skinlab-client";
    std::string sourceAddress_;
    Connection* connection_ = nullptr;
};

} // namespace skinlab::net
