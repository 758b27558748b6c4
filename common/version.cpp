#include "common/version.h"

namespace skinlab {
std::string version() { return SKINLAB_VERSION_STRING; }
} // namespace skinlab
