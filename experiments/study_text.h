#pragma once
// The study file's text helpers: tokens and completion codes, the participant-facing trial reference, and the one
// way a client's string is made fit to store.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace skinlab::experiments {

// Bytes of a stored client string (User-Agent, client time).
inline constexpr std::size_t kMaxStoredText = 512;

// The participant-facing reference of a trial: the row id with a tag derived from the participant's token above
// it, so a trial reference can be neither guessed nor used by another participant (both are unknown: NotFound).
std::int64_t trialReference(const std::string& participantToken, std::int64_t trialId);
// `text` as well-formed UTF-8 of at most `maxBytes` bytes: ill-formed sequences and control characters become
// U+FFFD, and a character cut by the limit is dropped whole. Every client string is stored through this.
std::string validUtf8(std::string_view text, std::size_t maxBytes);

// Random lower-case hex string of `bytes` bytes from the OS entropy source (tokens).
std::string randomHex(std::size_t bytes);
// A participant's completion code: 8 random characters of an unambiguous alphabet (no 0/O, 1/I/L).
std::string makeCompletionCode();

} // namespace skinlab::experiments
