#include "cli/commands.h"

namespace skinlab::cli {
// Placeholder: the owning module fills this in.
void registerKernel(CLI::App& app) { (void)app; }
} // namespace skinlab::cli
