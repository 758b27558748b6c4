#pragma once
#include <string>

namespace skinlab {
// One CSV field (RFC 4180): quoted, with inner quotes doubled, when it holds a comma, a quote or a line break.
std::string csvField(const std::string& text);
} // namespace skinlab
