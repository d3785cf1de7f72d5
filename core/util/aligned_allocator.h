// AlignedAllocator<T, A>: a std::vector allocator whose storage starts on an A-byte
// boundary (A >= alignof(T)), e.g. 64 so that the framebuffer's 4-pixel runs are whole
// cache lines (one line to prefetch and write per run, not two).
#pragma once
#include <cstddef>
#include <new>

namespace rtfact {

template <class T, size_t A>
struct AlignedAllocator {
    static_assert(A >= alignof(T) && (A & (A - 1)) == 0);
    using value_type = T;
    template <class U>
    struct rebind {
        using other = AlignedAllocator<U, A>;
    };
    AlignedAllocator() = default;
    template <class U>
    AlignedAllocator(const AlignedAllocator<U, A>&) {}  // NOLINT: allocators convert implicitly
    T* allocate(size_t n) { return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t(A))); }
    void deallocate(T* p, size_t) { ::operator delete(p, std::align_val_t(A)); }
    template <class U>
    bool operator==(const AlignedAllocator<U, A>&) const {
        return true;
    }
};

}  // namespace rtfact
