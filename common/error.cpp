#include "common/error.h"

namespace skinlab {

std::string contextMessage(std::string_view where, std::string_view key, std::string_view message) {
    std::string out;
    if (!where.empty()) {
        out += where;
        out += ": ";
    }
    if (!key.empty()) {
        out += key;
        out += ": ";
    }
    out += message;
    return out;
}

void throwInput(std::string_view where, std::string_view key, std::string_view message) {
    throw InputError(contextMessage(where, key, message));
}

} // namespace skinlab
