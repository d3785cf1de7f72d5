// BitMask<N>: one bit per lane, compact for branching (any/all/none, first set lane).
#pragma once
#include <cstdint>

#include "core/simd/packet.h"

namespace rtfact::simd {

template <int N>
struct BitMask {
    static constexpr int kWords = (N + 63) / 64;
    uint64_t w[kWords] = {};

    BitMask() = default;
    explicit BitMask(const Mask<N>& m) {
        constexpr int W = Mask<N>::W;
        for (int k = 0; k < Mask<N>::C; ++k) w[(k * W) / 64] |= uint64_t(movemask<W>(m.c[k])) << ((k * W) % 64);
    }
    bool operator[](int i) const { return (w[i >> 6] >> (i & 63)) & 1; }
    void set(int i) { w[i >> 6] |= uint64_t(1) << (i & 63); }
    void clear(int i) { w[i >> 6] &= ~(uint64_t(1) << (i & 63)); }
    bool any() const {
        uint64_t a = 0;
        for (int i = 0; i < kWords; ++i) a |= w[i];
        return a != 0;
    }
    bool none() const { return !any(); }
    bool all() const {
        for (int i = 0; i < kWords; ++i) {
            const int bits = (i == kWords - 1 && N % 64) ? N % 64 : 64;
            const uint64_t full = bits >= 64 ? ~uint64_t(0) : ((uint64_t(1) << (bits & 63)) - 1);
            if (w[i] != full) return false;
        }
        return true;
    }
    int count() const {
        int n = 0;
        for (int i = 0; i < kWords; ++i) n += __builtin_popcountll(w[i]);
        return n;
    }
    // Index of the first set lane, or N when none is set.
    int first() const {
        for (int i = 0; i < kWords; ++i)
            if (w[i]) return i * 64 + __builtin_ctzll(w[i]);
        return N;
    }
    // Calls f(lane) for each set lane in increasing order.
    template <class F>
    void forEach(F&& f) const {
        for (int i = 0; i < kWords; ++i)
            for (uint64_t b = w[i]; b; b &= b - 1) f(i * 64 + __builtin_ctzll(b));
    }
    // Bits of native chunk k.
    uint32_t chunkBits(int k) const {
        constexpr int W = Mask<N>::W;
        return uint32_t((w[(k * W) / 64] >> ((k * W) % 64)) & ((W == 64) ? ~0ull : ((1ull << W) - 1)));
    }
    friend BitMask operator&(BitMask a, const BitMask& b) {
        for (int i = 0; i < kWords; ++i) a.w[i] &= b.w[i];
        return a;
    }
    friend BitMask operator|(BitMask a, const BitMask& b) {
        for (int i = 0; i < kWords; ++i) a.w[i] |= b.w[i];
        return a;
    }
};

}  // namespace rtfact::simd
