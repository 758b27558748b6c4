#pragma once
// The checks every skinlab server makes on a request before routing it (the study server, `skinlab tune`): the
// Host header against the address the server is bound to (DNS rebinding), the page's own origin (cross-site
// requests), and tokens compared in constant time.
#include "net/http_server.h"

#include <optional>
#include <string>

namespace skinlab::net {

// Whether two strings are equal, in a time that depends on their lengths only (a token check must not tell a
// guesser how many leading characters were right).
bool constantTimeEqual(const std::string& a, const std::string& b);

// The hosts a server answers to. Host = name-or-address [":" port]. A browser sends the name it resolved; a
// DNS-rebinding page sends its own name, so only the bound address (with its port), a loopback name for a loopback
// server, or `publicHost` (any port: a reverse proxy in front) are accepted. A bound address of 0.0.0.0 or :: accepts
// any address.
struct HostRule {
    std::string boundHost;  // the address the server is bound to
    int port = 0;           // the port it is bound to
    std::string publicHost; // a name it is reached by ("" = none)
    bool allows(const std::string& hostHeader) const;
};

// The request comes from the server's own page: Sec-Fetch-Site, when sent, is same-origin or none, and Origin, when
// sent, is http:// and the Host header (or the same without ":80" when `port` is 80). RequestError 400 for a repeated
// header, 403 otherwise.
void checkSameOrigin(const HttpRequest& request, int port);

// The token of an Authorization: Bearer TOKEN header; nullopt without one.
std::optional<std::string> bearerToken(const HttpRequest& request);

} // namespace skinlab::net
