// Large arrays (tens of millions of discs and nodes) are walked randomly by the
// traversal; 2 MB pages cut its TLB misses. With THP in "madvise" mode the kernel only
// backs a range with huge pages when asked before the pages are first touched, so
// reserve, advise, then fill.
#pragma once
#include <sys/mman.h>

#include <cstdint>
#include <vector>

namespace rtfact::points {

inline void adviseHugePages(const void* p, size_t bytes) {
#ifdef MADV_HUGEPAGE
    constexpr uintptr_t kHuge = uintptr_t(2) << 20;
    if (bytes < 2 * kHuge) return;
    const uintptr_t lo = (reinterpret_cast<uintptr_t>(p) + kHuge - 1) & ~(kHuge - 1);
    const uintptr_t hi = (reinterpret_cast<uintptr_t>(p) + bytes) & ~(kHuge - 1);
    if (hi > lo) ::madvise(reinterpret_cast<void*>(lo), hi - lo, MADV_HUGEPAGE);
#else
    (void)p, (void)bytes;
#endif
}

// Resizes an empty vector to n elements, backed by huge pages where the kernel allows.
template <class T>
void resizeHuge(std::vector<T>& v, size_t n) {
    v.clear();
    v.shrink_to_fit();
    v.reserve(n);
    adviseHugePages(v.data(), n * sizeof(T));
    v.resize(n);
}

}  // namespace rtfact::points
