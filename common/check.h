#pragma once
// Always-on assertions for bugs (docs/architecture.md, "Error policy"): active in every build, the release preset
// included, unlike assert. A failed check prints the place, the expression and, for the comparison forms, both
// values, then aborts:
//   skinlab: check failed at renderer/sss/pscbf_kernel.cpp:53: samples % 2 == 1 (0 vs 1)
// Bad input is never checked this way: it throws InputError with a message for the user (common/error.h).
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>

namespace skinlab::detail {

[[noreturn]] inline void checkFailed(const char* file, int line, const std::string& what) {
    std::fprintf(stderr, "skinlab: check failed at %s:%d: %s\n", file, line, what.c_str());
    std::fflush(stderr);
    std::abort();
}

template <typename A, typename B>
std::string bothValues(const char* expression, const A& a, const B& b) {
    std::ostringstream out;
    out << expression << " (" << a << " vs " << b << ")";
    return out.str();
}

} // namespace skinlab::detail

#define SKINLAB_CHECK(condition)                                                                                       \
    do {                                                                                                               \
        if (!(condition)) ::skinlab::detail::checkFailed(__FILE__, __LINE__, #condition);                              \
    } while (false)

#define SKINLAB_CHECK_OP(a, op, b)                                                                                     \
    do {                                                                                                               \
        const auto& skinlabCheckA = (a);                                                                               \
        const auto& skinlabCheckB = (b);                                                                               \
        if (!(skinlabCheckA op skinlabCheckB))                                                                         \
            ::skinlab::detail::checkFailed(                                                                            \
                __FILE__, __LINE__, ::skinlab::detail::bothValues(#a " " #op " " #b, skinlabCheckA, skinlabCheckB));   \
    } while (false)

#define SKINLAB_CHECK_EQ(a, b) SKINLAB_CHECK_OP(a, ==, b)
#define SKINLAB_CHECK_NE(a, b) SKINLAB_CHECK_OP(a, !=, b)
#define SKINLAB_CHECK_LT(a, b) SKINLAB_CHECK_OP(a, <, b)
#define SKINLAB_CHECK_LE(a, b) SKINLAB_CHECK_OP(a, <=, b)
#define SKINLAB_CHECK_GT(a, b) SKINLAB_CHECK_OP(a, >, b)
#define SKINLAB_CHECK_GE(a, b) SKINLAB_CHECK_OP(a, >=, b)
