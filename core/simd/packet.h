// Packet<N, T>: N lanes of T stored as N / W native chunks. Three ways to use it:
// whole-packet arithmetic (a + b), per-lane access (p[i]) and per-chunk loops
// (p.chunk(c)), the last one being the default inside hot loops.
#pragma once
#include <type_traits>

#include "core/simd/native.h"

namespace rtfact::simd {

// Width of one chunk of an N-lane packet: 1 for single rays, the native width for
// wide packets, and narrower registers (SSE/AVX) for small packets on wide ISAs.
constexpr int chunkWidth(int n) {
    if (n == 1) return 1;
    return n < kNativeWidth ? n : kNativeWidth;
}

template <int N>
concept ValidPacketSize = N >= 1 && widthSupported(chunkWidth(N)) && N % chunkWidth(N) == 0;

template <int N>
struct Mask;
template <int N, class T = float>
struct Packet;

template <int N, class T>
struct __attribute__((may_alias)) Packet {
    static_assert(ValidPacketSize<N>, "packet size must be 1 or a multiple of a supported SIMD width");
    static constexpr int size = N;
    static constexpr int W = chunkWidth(N);
    static constexpr int C = N / W;
    using value_type = T;
    using Chunk = nvec<T, W>;
    using ChunkPacket = Packet<W, T>;

    Chunk c[C];

    Packet() = default;
    RTFACT_INLINE Packet(T s) {  // NOLINT: implicit broadcast is the point
        for (int i = 0; i < C; ++i) c[i] = splat<T, W>(s);
    }
    static RTFACT_INLINE Packet fromChunk(Chunk v) requires(C == 1) {
        Packet p;
        p.c[0] = v;
        return p;
    }
    // Chunk by chunk, as unaligned vector loads: one memcpy over the whole array becomes
    // 16-byte moves through the stack (GCC 12), and a memcpy per chunk still goes through
    // a stack slot in large functions (the AVX2 wide BVH node test: load, store, reload),
    // each read then waiting on store forwarding.
    static RTFACT_INLINE Packet load(const T* p) {
        Packet r;
        for (int i = 0; i < C; ++i) r.c[i] = *reinterpret_cast<const uvec<T, W>*>(p + i * W);
        return r;
    }
    RTFACT_INLINE void store(T* p) const {
        for (int i = 0; i < C; ++i) *reinterpret_cast<uvec<T, W>*>(p + i * W) = c[i];
    }
    // Lane i = start + i * step.
    static Packet ramp(T start, T step = T(1)) {
        Packet r;
        for (int i = 0; i < N; ++i) r[i] = start + T(i) * step;
        return r;
    }

    RTFACT_INLINE T& operator[](int i) { return reinterpret_cast<T*>(c)[i]; }
    RTFACT_INLINE const T& operator[](int i) const { return reinterpret_cast<const T*>(c)[i]; }
    RTFACT_INLINE ChunkPacket& chunk(int k) { return reinterpret_cast<ChunkPacket&>(c[k]); }
    RTFACT_INLINE const ChunkPacket& chunk(int k) const { return reinterpret_cast<const ChunkPacket&>(c[k]); }
    // Single-lane packets read as the scalar they hold.
    RTFACT_INLINE operator T() const requires(N == 1) { return c[0]; }

#define RTFACT_PACKET_BINOP(op)                                                 \
    friend RTFACT_INLINE Packet operator op(const Packet& a, const Packet& b) { \
        Packet r;                                                               \
        for (int i = 0; i < C; ++i) r.c[i] = a.c[i] op b.c[i];                  \
        return r;                                                               \
    }                                                                           \
    RTFACT_INLINE Packet& operator op##=(const Packet& b) {                     \
        for (int i = 0; i < C; ++i) c[i] = c[i] op b.c[i];                      \
        return *this;                                                           \
    }
    RTFACT_PACKET_BINOP(+)
    RTFACT_PACKET_BINOP(-)
    RTFACT_PACKET_BINOP(*)
    RTFACT_PACKET_BINOP(/)
#undef RTFACT_PACKET_BINOP
    friend RTFACT_INLINE Packet operator-(const Packet& a) {
        Packet r;
        for (int i = 0; i < C; ++i) r.c[i] = -a.c[i];
        return r;
    }
    // Shifts by k bits (arithmetic right shift for signed T).
    friend RTFACT_INLINE Packet operator<<(const Packet& a, int k) requires std::is_integral_v<T> {
        Packet r;
        for (int i = 0; i < C; ++i) r.c[i] = a.c[i] << k;
        return r;
    }
    friend RTFACT_INLINE Packet operator>>(const Packet& a, int k) requires std::is_integral_v<T> {
        Packet r;
        for (int i = 0; i < C; ++i) r.c[i] = a.c[i] >> k;
        return r;
    }
    friend RTFACT_INLINE Packet operator&(const Packet& a, const Packet& b) requires std::is_integral_v<T> {
        Packet r;
        for (int i = 0; i < C; ++i) r.c[i] = a.c[i] & b.c[i];
        return r;
    }
    friend RTFACT_INLINE Packet operator|(const Packet& a, const Packet& b) requires std::is_integral_v<T> {
        Packet r;
        for (int i = 0; i < C; ++i) r.c[i] = a.c[i] | b.c[i];
        return r;
    }

#define RTFACT_PACKET_CMP(op, fn)                                                \
    friend RTFACT_INLINE Mask<N> operator op(const Packet& a, const Packet& b) { \
        Mask<N> r;                                                               \
        for (int i = 0; i < C; ++i) r.c[i] = fn<W>(a.c[i], b.c[i]);              \
        return r;                                                                \
    }
    RTFACT_PACKET_CMP(<, cmpLt)
    RTFACT_PACKET_CMP(<=, cmpLe)
    RTFACT_PACKET_CMP(==, cmpEq)
    RTFACT_PACKET_CMP(!=, cmpNe)
#undef RTFACT_PACKET_CMP
    friend RTFACT_INLINE Mask<N> operator>(const Packet& a, const Packet& b) { return b < a; }
    friend RTFACT_INLINE Mask<N> operator>=(const Packet& a, const Packet& b) { return b <= a; }
};

// Lane mask (0 / all ones per lane) used for blends and as the active set of a packet.
template <int N>
struct __attribute__((may_alias)) Mask {
    static constexpr int W = chunkWidth(N);
    static constexpr int C = N / W;
    using Chunk = nmask<W>;
    using ChunkMask = Mask<W>;
    Chunk c[C];

    Mask() = default;
    RTFACT_INLINE Mask(bool b) {  // NOLINT
        for (int i = 0; i < C; ++i) c[i] = maskSplat<W>(b);
    }
    RTFACT_INLINE bool operator[](int i) const { return maskLane<W>(c[i / W], i % W); }
    RTFACT_INLINE void set(int i, bool b) { maskSetLane<W>(c[i / W], i % W, b); }
    RTFACT_INLINE ChunkMask& chunk(int k) { return reinterpret_cast<ChunkMask&>(c[k]); }
    RTFACT_INLINE const ChunkMask& chunk(int k) const { return reinterpret_cast<const ChunkMask&>(c[k]); }

    friend RTFACT_INLINE Mask operator&(const Mask& a, const Mask& b) {
        Mask r;
        for (int i = 0; i < C; ++i) r.c[i] = Chunk(a.c[i] & b.c[i]);
        return r;
    }
    friend RTFACT_INLINE Mask operator|(const Mask& a, const Mask& b) {
        Mask r;
        for (int i = 0; i < C; ++i) r.c[i] = Chunk(a.c[i] | b.c[i]);
        return r;
    }
    friend RTFACT_INLINE Mask operator^(const Mask& a, const Mask& b) {
        Mask r;
        for (int i = 0; i < C; ++i) r.c[i] = Chunk(a.c[i] ^ b.c[i]);
        return r;
    }
    friend RTFACT_INLINE Mask operator~(const Mask& a) {
        Mask r;
        for (int i = 0; i < C; ++i) r.c[i] = Chunk(~a.c[i]);
        return r;
    }
    // a & ~b
    friend RTFACT_INLINE Mask andNot(const Mask& a, const Mask& b) {
        Mask r;
        for (int i = 0; i < C; ++i) r.c[i] = Chunk(a.c[i] & ~b.c[i]);
        return r;
    }
    Mask& operator&=(const Mask& b) { return *this = *this & b; }
    Mask& operator|=(const Mask& b) { return *this = *this | b; }
};

// ---- whole-packet functions -------------------------------------------------------

template <int N, class T>
RTFACT_INLINE Packet<N, T> select(const Mask<N>& m, const Packet<N, T>& a, const Packet<N, T>& b) {
    Packet<N, T> r;
    for (int i = 0; i < Packet<N, T>::C; ++i) r.c[i] = simd::select<Packet<N, T>::W>(m.c[i], a.c[i], b.c[i]);
    return r;
}
template <int N>
RTFACT_INLINE Mask<N> select(const Mask<N>& m, const Mask<N>& a, const Mask<N>& b) {
    return (m & a) | andNot(b, m);
}

#define RTFACT_PACKET_UNARY(name, fn)                                             \
    template <int N>                                                              \
    RTFACT_INLINE Packet<N> name(const Packet<N>& a) {                            \
        Packet<N> r;                                                              \
        for (int i = 0; i < Packet<N>::C; ++i) r.c[i] = fn<Packet<N>::W>(a.c[i]); \
        return r;                                                                 \
    }
RTFACT_PACKET_UNARY(sqrt, vsqrt)
RTFACT_PACKET_UNARY(rcp, vrcp)
RTFACT_PACKET_UNARY(floor, vfloor)
RTFACT_PACKET_UNARY(abs, vabs)
#undef RTFACT_PACKET_UNARY

template <int N, class T>
RTFACT_INLINE Packet<N, T> min(const Packet<N, T>& a, const Packet<N, T>& b) {
    Packet<N, T> r;
    for (int i = 0; i < Packet<N, T>::C; ++i) r.c[i] = vmin<Packet<N, T>::W>(a.c[i], b.c[i]);
    return r;
}
template <int N, class T>
RTFACT_INLINE Packet<N, T> max(const Packet<N, T>& a, const Packet<N, T>& b) {
    Packet<N, T> r;
    for (int i = 0; i < Packet<N, T>::C; ++i) r.c[i] = vmax<Packet<N, T>::W>(a.c[i], b.c[i]);
    return r;
}
template <int N, class T>
RTFACT_INLINE Packet<N, T> clamp(const Packet<N, T>& a, const Packet<N, T>& lo, const Packet<N, T>& hi) {
    return min(max(a, lo), hi);
}
template <int N>
RTFACT_INLINE Packet<N> fma(const Packet<N>& a, const Packet<N>& b, const Packet<N>& c) {
    return a * b + c;  // contracted to vfmadd by -ffp-contract=fast
}

template <int N, class T>
RTFACT_INLINE T hmin(const Packet<N, T>& a) {
    auto m = a.c[0];
    for (int i = 1; i < Packet<N, T>::C; ++i) m = vmin<Packet<N, T>::W>(m, a.c[i]);
    return simd::hmin<Packet<N, T>::W>(m);
}
template <int N, class T>
RTFACT_INLINE T hmax(const Packet<N, T>& a) {
    auto m = a.c[0];
    for (int i = 1; i < Packet<N, T>::C; ++i) m = vmax<Packet<N, T>::W>(m, a.c[i]);
    return simd::hmax<Packet<N, T>::W>(m);
}

template <int N>
RTFACT_INLINE Packet<N, int32_t> toInt(const Packet<N>& a) {
    Packet<N, int32_t> r;
    for (int i = 0; i < Packet<N>::C; ++i) r.c[i] = simd::toInt<Packet<N>::W>(a.c[i]);
    return r;
}
template <int N>
RTFACT_INLINE Packet<N> toFloat(const Packet<N, int32_t>& a) {
    Packet<N> r;
    for (int i = 0; i < Packet<N>::C; ++i) r.c[i] = simd::toFloat<Packet<N>::W>(a.c[i]);
    return r;
}
template <int N, class T>
RTFACT_INLINE Packet<N, T> gather(const T* base, const Packet<N, int32_t>& idx) {
    Packet<N, T> r;
    for (int i = 0; i < Packet<N, T>::C; ++i) r.c[i] = simd::gather<Packet<N, T>::W>(base, idx.c[i]);
    return r;
}

// ---- mask reductions ----------------------------------------------------------------

template <int N>
RTFACT_INLINE bool any(const Mask<N>& m) {
    auto a = m.c[0];
    for (int i = 1; i < Mask<N>::C; ++i) a = typename Mask<N>::Chunk(a | m.c[i]);
    return movemask<Mask<N>::W>(a) != 0;
}
template <int N>
RTFACT_INLINE bool all(const Mask<N>& m) {
    auto a = m.c[0];
    for (int i = 1; i < Mask<N>::C; ++i) a = typename Mask<N>::Chunk(a & m.c[i]);
    constexpr uint32_t full = Mask<N>::W == 32 ? ~0u : ((1u << Mask<N>::W) - 1u);
    return movemask<Mask<N>::W>(a) == full;
}
template <int N>
RTFACT_INLINE bool none(const Mask<N>& m) {
    return !any(m);
}
template <int N>
RTFACT_INLINE int popcount(const Mask<N>& m) {
    int n = 0;
    for (int i = 0; i < Mask<N>::C; ++i) n += __builtin_popcount(movemask<Mask<N>::W>(m.c[i]));
    return n;
}

}  // namespace rtfact::simd
