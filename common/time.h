#pragma once
// Wall-clock timestamps for records (study rows, job records, dashboards).
#include <string>

namespace skinlab {

// Current UTC time as ISO-8601 with milliseconds ("2026-11-23T14:05:31.207Z").
std::string utcTimestamp();

} // namespace skinlab
