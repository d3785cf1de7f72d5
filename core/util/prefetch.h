// prefetchBytes: starts loading every cache line of [p, p + n) ahead of its use, for data
// whose start need not be line aligned (a block or brick in a larger array).
#pragma once
#include <cstddef>
#include <cstdint>

#include "core/simd/native.h"

namespace rtfact {

RTFACT_INLINE void prefetchBytes(const void* p, size_t n) {
    constexpr uintptr_t kLine = 64;
    const uintptr_t end = uintptr_t(p) + n;
    for (uintptr_t q = uintptr_t(p) & ~(kLine - 1); q < end; q += kLine)
        __builtin_prefetch(reinterpret_cast<const void*>(q));
}

}  // namespace rtfact
