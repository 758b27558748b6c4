#pragma once
// A rejected request: bad input from a client of the study server. Carries the HTTP status (4xx) the server
// answers with, as JSON {"error": message}. It is an InputError, so the CLI reports it the same way.
#include "common/error.h"

namespace skinlab::experiments {

class RequestError : public InputError {
public:
    RequestError(int status, const std::string& message) : InputError(message), status_(status) {}
    int status() const { return status_; }

private:
    int status_;
};

} // namespace skinlab::experiments
