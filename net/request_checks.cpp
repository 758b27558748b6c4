#include "net/request_checks.h"

#include "net/request_error.h"

#include <boost/asio/ip/address.hpp>
#include <cctype>

namespace skinlab::net {

namespace {
std::string lowerCase(std::string s) {
    for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}
} // namespace

bool constantTimeEqual(const std::string& a, const std::string& b) {
    if (a.size() != b.size()) return false;
    unsigned char diff = 0;
    for (std::size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
    return diff == 0;
}

bool HostRule::allows(const std::string& hostHeader) const {
    std::string name = lowerCase(hostHeader), portText;
    if (!name.empty() && name.front() == '[') {
        const std::size_t close = name.find(']');
        if (close == std::string::npos) return false;
        if (close + 1 < name.size() && name[close + 1] != ':') return false;
        portText = close + 1 < name.size() ? name.substr(close + 2) : "";
        name = name.substr(1, close - 1);
    } else if (const std::size_t colon = name.rfind(':'); colon != std::string::npos) {
        portText = name.substr(colon + 1);
        name = name.substr(0, colon);
    }
    if (name.empty()) return false;
    if (!publicHost.empty() && name == lowerCase(publicHost)) return true; // any port (a proxy)
    if (portText != std::to_string(port)) return false;
    boost::system::error_code ec;
    const auto bound = boost::asio::ip::make_address(boundHost, ec);
    if (ec) return false;
    if (name == "localhost") return bound.is_loopback() || bound.is_unspecified();
    const auto address = boost::asio::ip::make_address(name, ec);
    if (ec) return false; // any other name
    return bound.is_unspecified() || address == bound;
}

void checkSameOrigin(const HttpRequest& request, int port) {
    // A browser says where a request comes from: Sec-Fetch-Site (every current browser) and Origin (every POST, and
    // cross-origin GETs). Either, when present, must name this page; a client that sends neither is not a browser.
    if (request.headerCount("Sec-Fetch-Site") > 1 || request.headerCount("Origin") > 1)
        throw RequestError(400, "Origin, Sec-Fetch-Site: at most one of each");
    const std::string site = lowerCase(request.header("Sec-Fetch-Site"));
    if (!site.empty() && site != "same-origin" && site != "none")
        throw RequestError(403, "Sec-Fetch-Site: \"" + site.substr(0, 32) + "\": only this page's own requests");
    if (request.headerCount("Origin") == 0) return;
    const std::string origin = lowerCase(request.header("Origin"));
    const std::string own = "http://" + lowerCase(request.header("Host"));
    const bool defaultPort = port == 80 && own.ends_with(":80") && origin == own.substr(0, own.size() - 3);
    if (origin != own && !defaultPort)
        throw RequestError(403, "Origin: \"" + origin.substr(0, 64) + "\" is not this page's origin (" + own + ")");
}

std::optional<std::string> bearerToken(const HttpRequest& request) {
    const std::string authorization = request.header("Authorization");
    if (authorization.rfind("Bearer ", 0) != 0) return std::nullopt;
    return authorization.substr(7);
}

} // namespace skinlab::net
