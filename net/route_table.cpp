#include "net/route_table.h"

namespace skinlab::net {

bool routeMatches(std::string_view method, std::string_view path, const HttpRequest& request) {
    if (method != "*" && request.method != method) return false;
    if (path.ends_with('*')) return std::string_view(request.path).starts_with(path.substr(0, path.size() - 1));
    return request.path == path;
}

} // namespace skinlab::net
