#pragma once
// Participants and their visits in the study file: joining (idempotent by join key; one participant per
// recruitment-platform id), looking a participant up by token, sessions (one per page load) and the addresses
// joins and sessions came from. Each call takes the connection's mutex and runs in its own transaction.
#include "experiments/study_records.h"

#include <cstdint>
#include <optional>
#include <string>

namespace skinlab::experiments {

struct StudyConnection;

class ParticipantRegistry {
public:
    explicit ParticipantRegistry(StudyConnection& connection) : connection_(connection) {}

    // StudyStore::join without the first batch of an active design: `created` says whether a new participant was
    // stored (with a fixed design's planned trials). Refusals: Conflict (label or join key taken, a known platform
    // id without its secret: the attempt is recorded), LimitReached (a participant resumed too often).
    ParticipantRecord join(const std::string& label, const std::string& joinKey,
                           const std::optional<ExternalIds>& external, const std::optional<ClientOrigin>& origin,
                           bool& created);
    // NotFound for an unknown token.
    ParticipantRecord participant(const std::string& token);
    // LimitReached when the participant has `maxSessions` sessions already (0 = no limit); nothing is stored then.
    std::int64_t startSession(std::int64_t participantId, const std::string& userAgent, int viewportWidth,
                              int viewportHeight, double devicePixelRatio,
                              const std::optional<ViewingConditions>& viewing, int maxSessions,
                              const std::optional<ClientOrigin>& origin);
    void recordJoinAddress(std::int64_t participantId, const std::string& address, const std::string& source);

private:
    // The connection's mutex held, inside a transaction.
    ParticipantRecord insertParticipant(const std::string& label, const std::string& joinKey,
                                        const std::optional<ExternalIds>& external,
                                        const std::optional<ClientOrigin>& origin);
    void insertVisit(std::int64_t participantId, const char* outcome, const ClientOrigin& origin);
    // The participant's visits with this outcome ("resumed", "refused").
    int visitCount(std::int64_t participantId, const char* outcome);

    StudyConnection& connection_;
};

} // namespace skinlab::experiments
