#pragma once
#include <string>

namespace skinlab {
// Project version ("0.1.0"), recorded in every output's metadata.
std::string version();
} // namespace skinlab
