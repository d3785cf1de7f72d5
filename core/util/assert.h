// RTFACT_ASSERT(cond, message): checks an invariant the code relies on (traversal stack
// bounds, branches that cannot be reached). On in builds without NDEBUG (debug, and the
// sanitizer build, which compiles at -O1 without it) and when RTFACT_ENABLE_ASSERTS is
// defined; compiled out of release builds, where the hot paths cannot afford a branch.
#pragma once

#if !defined(NDEBUG) || defined(RTFACT_ENABLE_ASSERTS)
#include <cstdio>
#include <cstdlib>
#define RTFACT_ASSERTS_ON 1
#define RTFACT_ASSERT(cond, message)                                                                           \
    do {                                                                                                       \
        if (!(cond)) [[unlikely]] {                                                                            \
            std::fprintf(stderr, "%s:%d: RTFACT_ASSERT(%s) failed: %s\n", __FILE__, __LINE__, #cond, message); \
            std::abort();                                                                                      \
        }                                                                                                      \
    } while (0)
#else
#define RTFACT_ASSERTS_ON 0
#define RTFACT_ASSERT(cond, message) \
    do {                             \
    } while (0)
#endif

// A branch the logic rules out: checked where asserts are on, an optimisation hint elsewhere.
#if RTFACT_ASSERTS_ON
#define RTFACT_UNREACHABLE(message) RTFACT_ASSERT(false, message)
#else
#define RTFACT_UNREACHABLE(message) __builtin_unreachable()
#endif
