#pragma once
// A server's endpoints as one table: method and path → handler. The first route that matches answers; a route may
// be guarded (the server's own check, e.g. a token, runs before its handler); none matches: 404. Used by the study
// server and `skinlab tune`.
#include "net/http_server.h"
#include "net/request_error.h"

#include <initializer_list>
#include <string_view>
#include <vector>

namespace skinlab::net {

// Whether `method` ("*": any) and `path` (a trailing '*' makes it a prefix) match the request.
bool routeMatches(std::string_view method, std::string_view path, const HttpRequest& request);

template <class Server>
class RouteTable {
public:
    struct Route {
        std::string_view method; // "GET", "POST", or "*" for any
        std::string_view path;   // exact, or a prefix ending in '*'
        bool guarded;            // the guard runs before the handler
        HttpResponse (*handle)(Server& server, const HttpRequest& request);
    };

    RouteTable(std::initializer_list<Route> routes) : routes_(routes) {}

    // The answer of the first matching route, after guard(request) when it is guarded; RequestError 404 when none
    // matches.
    template <class Guard>
    HttpResponse answer(Server& server, const HttpRequest& request, Guard&& guard) const {
        for (const Route& r : routes_)
            if (routeMatches(r.method, r.path, request)) {
                if (r.guarded) guard(request);
                return r.handle(server, request);
            }
        throw RequestError(404, "not found");
    }

private:
    std::vector<Route> routes_;
};

} // namespace skinlab::net
