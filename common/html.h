#pragma once
#include <string>
#include <string_view>

namespace skinlab {
// Escapes &, <, > and " for HTML text and attribute values (reports, contact sheets).
std::string escapeHtml(std::string_view text);
} // namespace skinlab
