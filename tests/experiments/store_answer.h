#pragma once
// A participant's answer as the page would post it (fixed timing and viewport), for tests that answer through the
// store directly.
#include "experiments/study_store.h"

#include <cstdint>
#include <string>

namespace skinlab::experiments::test_support {

inline ResponseInput storeAnswer(const ParticipantRecord& p, std::int64_t session, const TrialRecord& t,
                                 const std::string& side) {
    ResponseInput in;
    in.token = p.token;
    in.trialId = trialReference(p.token, t.id);
    in.side = side;
    in.sessionId = session;
    in.responseMs = 700;
    in.clientTime = "2026-11-23T14:00:00.000Z";
    in.viewportWidth = 1280;
    in.viewportHeight = 800;
    in.userAgent = "test";
    return in;
}

} // namespace skinlab::experiments::test_support
