#pragma once
// A rejected request: bad input from a client of one of skinlab's servers (the study server, `skinlab tune`).
// Carries the HTTP status (4xx) the server answers with, as JSON {"error": message}. It is an InputError, so the
// CLI reports it the same way.
#include "common/error.h"

namespace skinlab::net {

class RequestError : public InputError {
public:
    // `retryAfterSeconds` (> 0): a 429's Retry-After.
    RequestError(int status, const std::string& message, int retryAfterSeconds = 0)
        : InputError(message), status_(status), retryAfter_(retryAfterSeconds) {}
    int status() const { return status_; }
    int retryAfter() const { return retryAfter_; }

private:
    int status_;
    int retryAfter_;
};

} // namespace skinlab::net
