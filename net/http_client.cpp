#include "net/http_client.h"

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <sys/socket.h>
#include <sys/time.h>

namespace skinlab::net {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
using tcp = asio::ip::tcp;

struct HttpClient::Connection {
    asio::io_context io;
    tcp::socket socket{io};
    beast::flat_buffer buffer;
};

std::string HttpAnswer::header(std::string_view name) const {
    for (const auto& [key, value] : headers)
        if (key.size() == name.size() && std::equal(key.begin(), key.end(), name.begin(), [](char a, char b) {
                return a == std::tolower(static_cast<unsigned char>(b));
            }))
            return value;
    return "";
}

HttpClient::HttpClient(std::string host, int port) : host_(std::move(host)), port_(port) {}
HttpClient::~HttpClient() { disconnect(); }
HttpClient::HttpClient(HttpClient&& other) noexcept
    : host_(std::move(other.host_)), port_(other.port_), timeout_(other.timeout_), keepAlive_(other.keepAlive_),
      userAgent_(std::move(other.userAgent_)), sourceAddress_(std::move(other.sourceAddress_)),
      connection_(other.connection_) {
    other.connection_ = nullptr;
}

void HttpClient::disconnect() {
    delete connection_;
    connection_ = nullptr;
}

HttpAnswer HttpClient::send(const std::string& method, const std::string& target, const std::string& body,
                            const HttpHeaders& headers, const std::string& contentType) {
    bool reused = false;
    HttpAnswer answer = attempt(method, target, body, headers, contentType, reused);
    // A kept-alive connection may have been closed by the server while idle: one more try on a new one.
    if (answer.status == 0 && reused) answer = attempt(method, target, body, headers, contentType, reused);
    return answer;
}

HttpAnswer HttpClient::attempt(const std::string& method, const std::string& target, const std::string& body,
                               const HttpHeaders& headers, const std::string& contentType, bool& reused) {
    HttpAnswer answer;
    beast::error_code ec;
    reused = connection_ != nullptr;
    if (!connection_) {
        auto fresh = std::make_unique<Connection>();
        const auto address = asio::ip::make_address(host_, ec);
        if (ec) {
            answer.error = "bad address " + host_;
            return answer;
        }
        const tcp::endpoint endpoint(address, static_cast<unsigned short>(port_));
        fresh->socket.open(endpoint.protocol(), ec);
        if (!ec && !sourceAddress_.empty())
            fresh->socket.bind(tcp::endpoint(asio::ip::make_address(sourceAddress_, ec), 0), ec);
        // Timeouts on the blocking socket calls (connect included: SO_SNDTIMEO bounds it on Linux).
        timeval tv{};
        tv.tv_sec = static_cast<long>(timeout_.count() / 1000);
        tv.tv_usec = static_cast<long>((timeout_.count() % 1000) * 1000);
        ::setsockopt(fresh->socket.native_handle(), SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
        ::setsockopt(fresh->socket.native_handle(), SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
        if (!ec) fresh->socket.connect(endpoint, ec);
        if (!ec) fresh->socket.set_option(tcp::no_delay(true), ec);
        if (ec) {
            answer.error = ec.message();
            return answer;
        }
        connection_ = fresh.release();
    }
    http::request<http::string_body> request(http::string_to_verb(method), target, 11);
    request.set(http::field::host,
                (host_.find(':') != std::string::npos ? "[" + host_ + "]" : host_) + ":" + std::to_string(port_));
    request.set(http::field::user_agent, userAgent_);
    for (const auto& [name, value] : headers) request.set(name, value);
    if (!body.empty() || method == "POST") {
        request.set(http::field::content_type, contentType);
        request.body() = body;
    }
    request.keep_alive(keepAlive_);
    request.prepare_payload();
    http::write(connection_->socket, request, ec);
    http::response_parser<http::string_body> parser;
    parser.body_limit(1ull << 30);
    if (!ec) http::read(connection_->socket, connection_->buffer, parser, ec);
    if (ec) {
        answer.error = ec.message();
        disconnect();
        return answer;
    }
    http::response<http::string_body> response = parser.release();
    answer.status = static_cast<int>(response.result_int());
    answer.body = std::move(response.body());
    for (const auto& field : response) {
        std::string name(field.name_string());
        for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        answer.headers.emplace_back(std::move(name), std::string(field.value()));
    }
    if (!keepAlive_ || !response.keep_alive()) disconnect();
    return answer;
}

} // namespace skinlab::net
