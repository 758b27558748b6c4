#pragma once
// Location of the published separable kernels (../shared/reference/separable-sss-kernels, never copied into the
// repository): $SKINLAB_REFERENCE or the default next to the source tree. Tests that need them skip with a message.
#include <cstdlib>
#include <filesystem>

namespace skinlab::test {

inline std::filesystem::path referenceKernelDir() {
    const char* env = std::getenv("SKINLAB_REFERENCE");
    const std::filesystem::path root = env && *env
                                           ? std::filesystem::path(env)
                                           : std::filesystem::path(SKINLAB_SOURCE_DIR) / ".." / "shared" / "reference";
    return root / "separable-sss-kernels";
}

inline std::filesystem::path referenceKernel(const char* material) {
    return referenceKernelDir() / (std::string(material) + "_PreInt_DISCSEP.bn");
}

} // namespace skinlab::test

#define SKINLAB_REQUIRE_REFERENCE(path)                                                                                \
    if (!std::filesystem::exists(path))                                                                                \
    GTEST_SKIP() << "reference kernel " << (path) << " absent (set SKINLAB_REFERENCE to the folder holding "           \
                 << "separable-sss-kernels/)"
