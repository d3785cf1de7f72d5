// prefetchBytes: starts loading every cache line of [p, p + n) ahead of its use, for data
// whose start need not be line aligned (a block or brick in a larger array); PrefetchRange
// does the same a few lines at a time.
#pragma once
#include <cstddef>
#include <cstdint>

#include "core/simd/native.h"

namespace rtfact {

inline constexpr uintptr_t kPrefetchLine = 64;

RTFACT_INLINE void prefetchBytes(const void* p, size_t n) {
    const uintptr_t end = uintptr_t(p) + n;
    for (uintptr_t q = uintptr_t(p) & ~(kPrefetchLine - 1); q < end; q += kPrefetchLine)
        __builtin_prefetch(reinterpret_cast<const void*>(q));
}

// The lines of [p, p + n) prefetched a few at a time, spread over the steps of a loop: a
// large block issued at once fills the miss buffers, and the loop's own loads wait behind it.
struct PrefetchRange {
    uintptr_t next = 0, end = 0;
    // Lines [p, p + n) spans at most (it need not start on a line).
    static constexpr size_t maxLines(size_t n) { return (n + kPrefetchLine - 1) / kPrefetchLine + 1; }
    void reset(const void* p, size_t n) {
        next = uintptr_t(p) & ~(kPrefetchLine - 1);
        end = uintptr_t(p) + n;
    }
    // Issues up to `lines` more of the range's lines.
    RTFACT_INLINE void issue(int lines) {
        for (; lines > 0 && next < end; --lines, next += kPrefetchLine)
            __builtin_prefetch(reinterpret_cast<const void*>(next));
    }
};

}  // namespace rtfact
