#pragma once
// What the study file refuses, said in the study's own terms: an unknown participant, trial or session
// (notFound), an answer or join that contradicts what is stored (conflict), a participant past one of its limits
// (limitReached), a value the store cannot take (invalidValue), a way in the study does not admit (notAdmitted: a
// recruitment platform's preview). The store and the recruitment checks throw these and nothing else for a
// refused request; the server alone maps them to HTTP statuses (StudyServer). Each is an InputError, so the CLI
// reports one like any other bad input.
#include "common/error.h"

namespace skinlab::experiments {

enum class Refusal { invalidValue, notFound, conflict, limitReached, notAdmitted };

class StudyRefusal : public InputError {
public:
    StudyRefusal(Refusal reason, const std::string& message) : InputError(message), reason_(reason) {}
    Refusal reason() const { return reason_; }

private:
    Refusal reason_;
};

class InvalidValue : public StudyRefusal {
public:
    explicit InvalidValue(const std::string& message) : StudyRefusal(Refusal::invalidValue, message) {}
};

class NotFound : public StudyRefusal {
public:
    explicit NotFound(const std::string& message) : StudyRefusal(Refusal::notFound, message) {}
};

class Conflict : public StudyRefusal {
public:
    explicit Conflict(const std::string& message) : StudyRefusal(Refusal::conflict, message) {}
};

class LimitReached : public StudyRefusal {
public:
    explicit LimitReached(const std::string& message) : StudyRefusal(Refusal::limitReached, message) {}
};

class NotAdmitted : public StudyRefusal {
public:
    explicit NotAdmitted(const std::string& message) : StudyRefusal(Refusal::notAdmitted, message) {}
};

} // namespace skinlab::experiments
