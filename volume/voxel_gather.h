// Fetches two x-adjacent voxels per lane with one 32-bit gather for u8/u16 storage (the
// grid is padded so the over-read stays in bounds); f32 needs one 64-bit fetch. The
// load method is chosen per ISA at compile time, by measurement (docs/cli.md, Volumes):
// hardware gathers on AVX-512; on AVX2 hardware gathers for 32-bit elements (on Zen 5 the
// AVX2 build's per-lane scalar loads, one int-to-float conversion and insert per voxel, took
// most of the march) and one scalar load per lane for 64-bit ones (loadQwords8: u16 pairs,
// f32 pairs, u8 quads, TF entries); per-lane loads for narrower or scalar packets. Packets of
// several native chunks are fetched chunk by chunk.
#pragma once
#include <cstring>
#include <type_traits>

#include "core/simd/packet.h"
#include "volume/half_float.h"

namespace rtfact::volume {

#if RTFACT_NATIVE_WIDTH >= 16
// Masked/zeroing forms with all lanes on: the plain intrinsics start from an undefined
// register, which GCC 12 reports as uninitialized (-Werror in CI); same instructions.
inline constexpr __mmask16 kAll16 = 0xFFFF;
inline constexpr __mmask8 kAll8 = 0xFF;
// The two 8-lane halves of 16 indices, as intrinsic operands.
RTFACT_INLINE __m256i lowHalf(simd::nvec<int32_t, 16> v) { return (__m256i)simd::lowHalf<16>(v); }
RTFACT_INLINE __m256i highHalf(simd::nvec<int32_t, 16> v) { return (__m256i)simd::highHalf<16>(v); }
// Per lane the 32-bit entries idx and idx + 1 of base, by one 64-bit gather each (two 8-lane
// gathers), sorted into the first entries and the second.
RTFACT_INLINE void gatherEntryPairs(const void* base, simd::nvec<int32_t, 16> idx, __m512i& first, __m512i& second) {
    const __m512i lo = _mm512_mask_i32gather_epi64(_mm512_setzero_si512(), kAll8, lowHalf(idx), base, 4);
    const __m512i hi = _mm512_mask_i32gather_epi64(_mm512_setzero_si512(), kAll8, highHalf(idx), base, 4);
    const __m512i even = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30);
    const __m512i odd = _mm512_setr_epi32(1, 3, 5, 7, 9, 11, 13, 15, 17, 19, 21, 23, 25, 27, 29, 31);
    first = _mm512_permutex2var_epi32(lo, even, hi);
    second = _mm512_permutex2var_epi32(lo, odd, hi);
}
#endif

// The four bytes of each 32-bit lane of g as floats: byte 0 -> b0 ... byte 3 -> b3 (the
// middle two zero-extended by one byte shuffle each; byte indices are within the 128-bit
// lane: dword k's byte b is 4k + b).
#if RTFACT_NATIVE_WIDTH == 8
RTFACT_INLINE void splitBytes(__m256i g, simd::nvec<float, 8>& b0, simd::nvec<float, 8>& b1, simd::nvec<float, 8>& b2,
                              simd::nvec<float, 8>& b3) {
    using simd::nvec;
    const __m256i byte1 = _mm256_setr_epi32(int(0x80808001u), int(0x80808005u), int(0x80808009u), int(0x8080800Du),
                                            int(0x80808001u), int(0x80808005u), int(0x80808009u), int(0x8080800Du));
    const __m256i byte2 = _mm256_add_epi32(byte1, _mm256_set1_epi32(1));
    b0 = (nvec<float, 8>)_mm256_cvtepi32_ps(_mm256_and_si256(g, _mm256_set1_epi32(0xFF)));
    b1 = (nvec<float, 8>)_mm256_cvtepi32_ps(_mm256_shuffle_epi8(g, byte1));
    b2 = (nvec<float, 8>)_mm256_cvtepi32_ps(_mm256_shuffle_epi8(g, byte2));
    b3 = (nvec<float, 8>)_mm256_cvtepi32_ps(_mm256_srli_epi32(g, 24));
}
#endif
#if RTFACT_NATIVE_WIDTH >= 16
RTFACT_INLINE void splitBytes(__m512i g, simd::nvec<float, 16>& b0, simd::nvec<float, 16>& b1,
                              simd::nvec<float, 16>& b2, simd::nvec<float, 16>& b3) {
    using simd::nvec;
    const __m512i m = _mm512_set1_epi32(0xFF);
    b0 = (nvec<float, 16>)_mm512_maskz_cvtepi32_ps(kAll16, _mm512_and_si512(g, m));
#if defined(__AVX512BW__)
    const __m512i byte1 = _mm512_set4_epi32(int(0x8080800Du), int(0x80808009u), int(0x80808005u), int(0x80808001u));
    const __m512i byte2 = _mm512_add_epi32(byte1, _mm512_set1_epi32(1));
    b1 = (nvec<float, 16>)_mm512_maskz_cvtepi32_ps(kAll16, _mm512_maskz_shuffle_epi8(~__mmask64(0), g, byte1));
    b2 = (nvec<float, 16>)_mm512_maskz_cvtepi32_ps(kAll16, _mm512_maskz_shuffle_epi8(~__mmask64(0), g, byte2));
#else
    b1 = (nvec<float, 16>)_mm512_maskz_cvtepi32_ps(kAll16, _mm512_and_si512(_mm512_maskz_srli_epi32(kAll16, g, 8), m));
    b2 = (nvec<float, 16>)_mm512_maskz_cvtepi32_ps(kAll16, _mm512_and_si512(_mm512_maskz_srli_epi32(kAll16, g, 16), m));
#endif
    b3 = (nvec<float, 16>)_mm512_maskz_cvtepi32_ps(kAll16, _mm512_maskz_srli_epi32(kAll16, g, 24));
}
#endif

#if RTFACT_NATIVE_WIDTH == 8
// The eight (non-negative) 32-bit indices of idx for per-lane loads, taken out as four 64-bit
// words, two lanes each (vmovq / vpextrq, then a shift), instead of a store and eight reloads,
// which GCC turns into eight two-micro-op vpextrd whose results it then spills (AVX2 build, Zen
// 5, session 46: the 512^3 phantom every step 2-4% faster, the CTs' DVR within the noise to 3%;
// the same images).
struct LaneIndices8 {
    uint64_t q[4];
    RTFACT_INLINE explicit LaneIndices8(__m256i idx) {
        const __m128i l = _mm256_castsi256_si128(idx), h = _mm256_extracti128_si256(idx, 1);
        q[0] = uint64_t(_mm_cvtsi128_si64(l));
        q[1] = uint64_t(_mm_extract_epi64(l, 1));
        q[2] = uint64_t(_mm_cvtsi128_si64(h));
        q[3] = uint64_t(_mm_extract_epi64(h, 1));
    }
    RTFACT_INLINE size_t operator[](int lane) const {
        return size_t(uint32_t(lane & 1 ? q[lane >> 1] >> 32 : q[lane >> 1]));
    }
};

// The 8 bytes at base + S * idx[i] per lane, lanes[0..3] into lo and lanes[4..7] into hi as
// their 64-bit words: AVX2's 64-bit fetches (quads, u16 and f32 pairs, TF entries) take scalar loads instead of
// vpgatherdq. On Zen 4 (AVX2 build, tooth) the frame took 55.5 ms against 59.8 with the
// gathers (the u8 pairs' 32-bit gathers as scalar loads: no faster, they stay gathers). The
// u16 pairs' two 32-bit gathers per face as one 64-bit load per lane: 256^3 phantom 141-158
// -> 125-146 ms, 512^3 every step 323-337 -> 295-307 ms; f32 pairs' vpgatherdq likewise: the
// bonsai VDB 72-89 -> 67-78 ms (Zen 5, one thread, session 31).
template <size_t S>
RTFACT_INLINE void loadQwords8(const void* base, __m256i idx, const int (&lanes)[8], __m256i& lo, __m256i& hi) {
    const LaneIndices8 ix(idx);
    const auto* b = static_cast<const uint8_t*>(base);
    auto pair = [&](int i, int j) __attribute__((always_inline)) {
        const __m128i x = _mm_loadl_epi64((const __m128i*)(b + S * ix[lanes[i]]));
        long long y;
        std::memcpy(&y, b + S * ix[lanes[j]], 8);
        return _mm_insert_epi64(x, y, 1);
    };
    lo = _mm256_set_m128i(pair(2, 3), pair(0, 1));
    hi = _mm256_set_m128i(pair(6, 7), pair(4, 5));
}
// The 8 bytes at base + 4 idx[i] per lane split into their first and their second dword,
// lanes in order (lanes 0, 1, 4, 5 and 2, 3, 6, 7 loaded side by side, so that one in-lane
// shuffle each sorts them).
RTFACT_INLINE void loadDwordPairs8(const void* base, __m256i idx, __m256i& first, __m256i& second) {
    __m256i qlo, qhi;
    loadQwords8<4>(base, idx, {0, 1, 4, 5, 2, 3, 6, 7}, qlo, qhi);
    const __m256 lo = _mm256_castsi256_ps(qlo), hi = _mm256_castsi256_ps(qhi);
    first = _mm256_castps_si256(_mm256_shuffle_ps(lo, hi, 0x88));
    second = _mm256_castps_si256(_mm256_shuffle_ps(lo, hi, 0xDD));
}
#endif

template <class T, int W>
RTFACT_INLINE void fetchPair(const T* base, const Packet<W, int32_t>& idx, Packet<W>& a, Packet<W>& b) {
    using namespace simd;
    if constexpr (Packet<W>::C > 1) {
        for (int k = 0; k < Packet<W>::C; ++k) fetchPair<T, Packet<W>::W>(base, idx.chunk(k), a.chunk(k), b.chunk(k));
        return;
    }
#if RTFACT_NATIVE_WIDTH == 8
    if constexpr (W == 8) {
        if constexpr (sizeof(T) < 4) {
            const __m256i g = _mm256_i32gather_epi32((const int*)base, (__m256i)idx.c[0], int(sizeof(T)));
            const __m256i m = _mm256_set1_epi32(sizeof(T) == 1 ? 0xFF : 0xFFFF);
            a.c[0] = (nvec<float, 8>)_mm256_cvtepi32_ps(_mm256_and_si256(g, m));
            b.c[0] = (nvec<float, 8>)_mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srli_epi32(g, 8 * sizeof(T)), m));
        } else {
            // f32: the (x, x + 1) pair as one 64-bit scalar load per lane
            __m256i x0, x1;
            loadDwordPairs8(base, (__m256i)idx.c[0], x0, x1);
            a.c[0] = (nvec<float, 8>)_mm256_castsi256_ps(x0);
            b.c[0] = (nvec<float, 8>)_mm256_castsi256_ps(x1);
        }
        return;
    }
#endif
#if RTFACT_NATIVE_WIDTH >= 16
    if constexpr (W == 16) {
        __m512i g = _mm512_setzero_si512();
        if constexpr (sizeof(T) < 4)
            g = _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), kAll16, (__m512i)idx.c[0], (const void*)base,
                                            int(sizeof(T)));
        if constexpr (sizeof(T) == 1) {
            a.c[0] = (nvec<float, 16>)_mm512_maskz_cvtepi32_ps(kAll16, _mm512_and_si512(g, _mm512_set1_epi32(0xFF)));
            b.c[0] = (nvec<float, 16>)_mm512_maskz_cvtepi32_ps(
                kAll16, _mm512_and_si512(_mm512_maskz_srli_epi32(kAll16, g, 8), _mm512_set1_epi32(0xFF)));
        } else if constexpr (sizeof(T) == 2) {
            a.c[0] = (nvec<float, 16>)_mm512_maskz_cvtepi32_ps(kAll16, _mm512_and_si512(g, _mm512_set1_epi32(0xFFFF)));
            b.c[0] = (nvec<float, 16>)_mm512_maskz_cvtepi32_ps(kAll16, _mm512_maskz_srli_epi32(kAll16, g, 16));
        } else {
            (void)g;
        }
        if constexpr (sizeof(T) == 4) {
            // f32: gather the (x, x+1) pairs as 64-bit elements (half the gathered
            // elements of two 32-bit gathers), then split even/odd floats.
            const __m512 lo = _mm512_castsi512_ps(
                _mm512_mask_i32gather_epi64(_mm512_setzero_si512(), kAll8, lowHalf(idx.c[0]), (const void*)base, 4));
            const __m512 hi = _mm512_castsi512_ps(
                _mm512_mask_i32gather_epi64(_mm512_setzero_si512(), kAll8, highHalf(idx.c[0]), (const void*)base, 4));
            const __m512i even = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30);
            const __m512i odd = _mm512_setr_epi32(1, 3, 5, 7, 9, 11, 13, 15, 17, 19, 21, 23, 25, 27, 29, 31);
            a.c[0] = (nvec<float, 16>)_mm512_permutex2var_ps(lo, even, hi);
            b.c[0] = (nvec<float, 16>)_mm512_permutex2var_ps(lo, odd, hi);
        }
        return;
    }
#endif
    for (int i = 0; i < W; ++i) {
        const T* p = base + idx[i];
        if constexpr (std::is_same_v<T, float>) {
            a[i] = p[0];
            b[i] = p[1];
        } else {
            a[i] = float(p[0]);
            b[i] = float(p[1]);
        }
    }
}

// The four corners of a cell face from the y-pair layout (BrickedVolume::pairs): entry
// idx holds (x, y), (x, y + 1), entry idx + 1 (x + 1, y), (x + 1, y + 1); one 32-bit (u8)
// or 64-bit (u16; on AVX2 a scalar load, loadDwordPairs8) fetch per lane reads both
// entries. a0 = (x, y), a1 = (x, y + 1), b0 = (x + 1, y), b1 = (x + 1, y + 1).
template <class T, int W>
RTFACT_INLINE void fetchQuad(const T* base, const Packet<W, int32_t>& idx, Packet<W>& a0, Packet<W>& a1, Packet<W>& b0,
                             Packet<W>& b1) {
    static_assert(sizeof(T) < 4, "y-pairs are u8 or u16");
    using namespace simd;
    if constexpr (Packet<W>::C > 1) {
        for (int k = 0; k < Packet<W>::C; ++k)
            fetchQuad<T, Packet<W>::W>(base, idx.chunk(k), a0.chunk(k), a1.chunk(k), b0.chunk(k), b1.chunk(k));
        return;
    }
#if RTFACT_NATIVE_WIDTH == 8
    if constexpr (W == 8) {
        if constexpr (sizeof(T) == 1) {
            // bytes a0 a1 b0 b1 of each dword
            splitBytes(_mm256_i32gather_epi32((const int*)base, (__m256i)idx.c[0], 2), a0.c[0], a1.c[0], b0.c[0],
                       b1.c[0]);
        } else {
            // entries idx and idx + 1 as one 64-bit scalar load per lane
            __m256i ga, gb;
            loadDwordPairs8(base, (__m256i)idx.c[0], ga, gb);
            const __m256i m = _mm256_set1_epi32(0xFFFF);
            a0.c[0] = (nvec<float, 8>)_mm256_cvtepi32_ps(_mm256_and_si256(ga, m));
            a1.c[0] = (nvec<float, 8>)_mm256_cvtepi32_ps(_mm256_srli_epi32(ga, 16));
            b0.c[0] = (nvec<float, 8>)_mm256_cvtepi32_ps(_mm256_and_si256(gb, m));
            b1.c[0] = (nvec<float, 8>)_mm256_cvtepi32_ps(_mm256_srli_epi32(gb, 16));
        }
        return;
    }
#endif
#if RTFACT_NATIVE_WIDTH >= 16
    if constexpr (W == 16) {
        if constexpr (sizeof(T) == 1) {
            splitBytes(
                _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), kAll16, (__m512i)idx.c[0], (const void*)base, 2),
                a0.c[0], a1.c[0], b0.c[0], b1.c[0]);
        } else {
            __m512i ia, ib;  // a0 | a1 << 16, b0 | b1 << 16
            gatherEntryPairs(base, idx.c[0], ia, ib);
            const __m512i m = _mm512_set1_epi32(0xFFFF);
            a0.c[0] = (nvec<float, 16>)_mm512_maskz_cvtepi32_ps(kAll16, _mm512_and_si512(ia, m));
            a1.c[0] = (nvec<float, 16>)_mm512_maskz_cvtepi32_ps(kAll16, _mm512_maskz_srli_epi32(kAll16, ia, 16));
            b0.c[0] = (nvec<float, 16>)_mm512_maskz_cvtepi32_ps(kAll16, _mm512_and_si512(ib, m));
            b1.c[0] = (nvec<float, 16>)_mm512_maskz_cvtepi32_ps(kAll16, _mm512_maskz_srli_epi32(kAll16, ib, 16));
        }
        return;
    }
#endif
    for (int i = 0; i < W; ++i) {
        const T* p = base + 2 * size_t(uint32_t(idx[i]));
        a0[i] = float(p[0]);
        a1[i] = float(p[1]);
        b0[i] = float(p[2]);
        b1[i] = float(p[3]);
    }
}

// The eight corners of a cell from the y-z quad layout (BrickedVolume::quads, u8): entry
// idx holds the samples (x, y, z), (x, y + 1, z), (x, y, z + 1), (x, y + 1, z + 1), entry
// idx + 1 the same at x + 1: one 64-bit fetch per lane reads both (half the fetched
// elements of the y-pairs' two 32-bit gathers; AVX2: scalar loads, loadDwordPairs8). a_k: corner
// k of x, b_k of x + 1.
template <int W>
RTFACT_INLINE void fetchCube(const uint8_t* base, const Packet<W, int32_t>& idx, Packet<W>& a0, Packet<W>& a1,
                             Packet<W>& a2, Packet<W>& a3, Packet<W>& b0, Packet<W>& b1, Packet<W>& b2, Packet<W>& b3) {
    using namespace simd;
    if constexpr (Packet<W>::C > 1) {
        for (int k = 0; k < Packet<W>::C; ++k)
            fetchCube<Packet<W>::W>(base, idx.chunk(k), a0.chunk(k), a1.chunk(k), a2.chunk(k), a3.chunk(k), b0.chunk(k),
                                    b1.chunk(k), b2.chunk(k), b3.chunk(k));
        return;
    }
#if RTFACT_NATIVE_WIDTH == 8
    if constexpr (W == 8) {
        __m256i x0, x1;  // the quads at x and at x + 1
        loadDwordPairs8(base, (__m256i)idx.c[0], x0, x1);
        splitBytes(x0, a0.c[0], a1.c[0], a2.c[0], a3.c[0]);
        splitBytes(x1, b0.c[0], b1.c[0], b2.c[0], b3.c[0]);
        return;
    }
#endif
#if RTFACT_NATIVE_WIDTH >= 16
    if constexpr (W == 16) {
        __m512i ia, ib;
        gatherEntryPairs(base, idx.c[0], ia, ib);
        splitBytes(ia, a0.c[0], a1.c[0], a2.c[0], a3.c[0]);
        splitBytes(ib, b0.c[0], b1.c[0], b2.c[0], b3.c[0]);
        return;
    }
#endif
    for (int i = 0; i < W; ++i) {
        const uint8_t* p = base + 4 * size_t(uint32_t(idx[i]));
        a0[i] = float(p[0]);
        a1[i] = float(p[1]);
        a2[i] = float(p[2]);
        a3[i] = float(p[3]);
        b0[i] = float(p[4]);
        b1[i] = float(p[5]);
        b2[i] = float(p[6]);
        b3[i] = float(p[7]);
    }
}

// Per lane the 2B consecutive 32-bit words at base + idx[i], two adjacent entries of B words
// (the gradient bricks' cell corners x and x + 1): first[k] = word k, second[k] = word B + k.
// AVX2: one 64-bit (B = 1, 3: per pair of words) or 128-bit (B = 2) load per lane instead of
// 2B gathers, as for the voxels' pairs (Zen 5: the gathers' micro-ops cost more than the
// per-lane loads); AVX-512: 64-bit gathers (half the elements); scalar: per lane.
template <int B, int W, class T>
RTFACT_INLINE void fetchEntryPair(const T* base, const Packet<W, int32_t>& idx, Packet<W, T> (&first)[B],
                                  Packet<W, T> (&second)[B]) {
    static_assert(sizeof(T) == 4 && B >= 1 && B <= 3);
    using I = Packet<W, int32_t>;
    if constexpr (I::C > 1) {
        using PC = typename Packet<W, T>::ChunkPacket;
        for (int c = 0; c < I::C; ++c) {
            PC f[B], s[B];
            fetchEntryPair<B, PC::size>(base, idx.chunk(c), f, s);
            for (int k = 0; k < B; ++k) first[k].chunk(c) = f[k], second[k].chunk(c) = s[k];
        }
        return;
    }
#if RTFACT_NATIVE_WIDTH == 8
    if constexpr (W == 8 && B == 2) {
        using V = simd::nvec<T, 8>;
        const LaneIndices8 ix((__m256i)idx.c[0]);
        // lanes i and i + 4 side by side, then a 4 x 4 transpose within each 128-bit half
        auto rows = [&](int i) __attribute__((always_inline)) {
            return _mm256_loadu2_m128i((const __m128i*)(base + ix[i + 4]), (const __m128i*)(base + ix[i]));
        };
        const __m256i r0 = rows(0), r1 = rows(1), r2 = rows(2), r3 = rows(3);
        const __m256i t0 = _mm256_unpacklo_epi32(r0, r1), t1 = _mm256_unpacklo_epi32(r2, r3);
        const __m256i t2 = _mm256_unpackhi_epi32(r0, r1), t3 = _mm256_unpackhi_epi32(r2, r3);
        first[0].c[0] = (V)_mm256_unpacklo_epi64(t0, t1);
        first[1].c[0] = (V)_mm256_unpackhi_epi64(t0, t1);
        second[0].c[0] = (V)_mm256_unpacklo_epi64(t2, t3);
        second[1].c[0] = (V)_mm256_unpackhi_epi64(t2, t3);
        return;
    } else if constexpr (W == 8) {
        // words (0, 1), (2, 3), (4, 5): one 64-bit load per lane each
        __m256i w[2 * B];
        for (int k = 0; k < B; ++k) loadDwordPairs8(base + 2 * k, (__m256i)idx.c[0], w[2 * k], w[2 * k + 1]);
        for (int k = 0; k < B; ++k) first[k].c[0] = (simd::nvec<T, 8>)w[k], second[k].c[0] = (simd::nvec<T, 8>)w[B + k];
        return;
    }
#elif RTFACT_NATIVE_WIDTH >= 16
    if constexpr (W == 16) {
        // the same word pairs by 64-bit gathers
        __m512i w[2 * B];
        for (int k = 0; k < B; ++k) gatherEntryPairs(base + 2 * k, idx.c[0], w[2 * k], w[2 * k + 1]);
        for (int k = 0; k < B; ++k)
            first[k].c[0] = (simd::nvec<T, 16>)w[k], second[k].c[0] = (simd::nvec<T, 16>)w[B + k];
        return;
    }
#endif
    for (int k = 0; k < B; ++k) {
        first[k] = gather(base, idx + I(k));
        second[k] = gather(base, idx + I(B + k));
    }
}

// One transfer-function entry per lane: r, g, b, a as four halves in 64 bits (half_float.h)
// at base[idx], one 64-bit fetch per lane (AVX2: scalar loads); the halves are sorted by
// channel with byte and dword shuffles, then converted with F16C.
template <int W>
RTFACT_INLINE void fetchRgbaHalf(const uint64_t* base, const Packet<W, int32_t>& idx, Packet<W>& r, Packet<W>& g,
                                 Packet<W>& b, Packet<W>& a) {
    if constexpr (Packet<W>::C > 1) {
        for (int k = 0; k < Packet<W>::C; ++k)
            fetchRgbaHalf<Packet<W>::W>(base, idx.chunk(k), r.chunk(k), g.chunk(k), b.chunk(k), a.chunk(k));
        return;
    }
#if RTFACT_NATIVE_WIDTH == 8 && defined(__F16C__)
    if constexpr (W == 8) {
        using namespace simd;
        // per 128 bits (two entries): r0 g0 b0 a0 r1 g1 b1 a1 -> r0 r1 g0 g1 b0 b1 a0 a1
        const __m256i bytes = _mm256_setr_epi8(0, 1, 8, 9, 2, 3, 10, 11, 4, 5, 12, 13, 6, 7, 14, 15, 0, 1, 8, 9, 2, 3,
                                               10, 11, 4, 5, 12, 13, 6, 7, 14, 15);
        const __m256i order = _mm256_setr_epi32(0, 4, 1, 5, 2, 6, 3, 7);
        __m256i lo, hi;
        loadQwords8<8>(base, (__m256i)idx.c[0], {0, 1, 2, 3, 4, 5, 6, 7}, lo, hi);
        // lanes 0-3 (4-7): r r r r g g g g | b b b b a a a a
        const __m256i l = _mm256_permutevar8x32_epi32(_mm256_shuffle_epi8(lo, bytes), order);
        const __m256i h = _mm256_permutevar8x32_epi32(_mm256_shuffle_epi8(hi, bytes), order);
        const __m256i rb = _mm256_unpacklo_epi64(l, h), ga = _mm256_unpackhi_epi64(l, h);
        r.c[0] = (nvec<float, 8>)_mm256_cvtph_ps(_mm256_castsi256_si128(rb));
        b.c[0] = (nvec<float, 8>)_mm256_cvtph_ps(_mm256_extracti128_si256(rb, 1));
        g.c[0] = (nvec<float, 8>)_mm256_cvtph_ps(_mm256_castsi256_si128(ga));
        a.c[0] = (nvec<float, 8>)_mm256_cvtph_ps(_mm256_extracti128_si256(ga, 1));
        return;
    }
#endif
#if RTFACT_NATIVE_WIDTH >= 16 && defined(__AVX512BW__)
    if constexpr (W == 16) {
        using namespace simd;
        const __m512i bytes = _mm512_set4_epi32(0x0f0e0706, 0x0d0c0504, 0x0b0a0302, 0x09080100);
        const __m512i lo =
            _mm512_mask_i32gather_epi64(_mm512_setzero_si512(), kAll8, lowHalf(idx.c[0]), (const void*)base, 8);
        const __m512i hi =
            _mm512_mask_i32gather_epi64(_mm512_setzero_si512(), kAll8, highHalf(idx.c[0]), (const void*)base, 8);
        // dword 4c + k of each: channel k of the entries 2c, 2c + 1
        const __m512i l = _mm512_maskz_shuffle_epi8(~__mmask64(0), lo, bytes);
        const __m512i h = _mm512_maskz_shuffle_epi8(~__mmask64(0), hi, bytes);
        const __m512i rg = _mm512_permutex2var_epi32(
            l, _mm512_setr_epi32(0, 4, 8, 12, 16, 20, 24, 28, 1, 5, 9, 13, 17, 21, 25, 29), h);
        const __m512i ba = _mm512_permutex2var_epi32(
            l, _mm512_setr_epi32(2, 6, 10, 14, 18, 22, 26, 30, 3, 7, 11, 15, 19, 23, 27, 31), h);
        const auto low = [](__m512i v) { return (__m256i)__builtin_shufflevector(v, v, 0, 1, 2, 3); };
        const auto high = [](__m512i v) { return (__m256i)__builtin_shufflevector(v, v, 4, 5, 6, 7); };
        r.c[0] = (nvec<float, 16>)_mm512_maskz_cvtph_ps(kAll16, low(rg));
        g.c[0] = (nvec<float, 16>)_mm512_maskz_cvtph_ps(kAll16, high(rg));
        b.c[0] = (nvec<float, 16>)_mm512_maskz_cvtph_ps(kAll16, low(ba));
        a.c[0] = (nvec<float, 16>)_mm512_maskz_cvtph_ps(kAll16, high(ba));
        return;
    }
#endif
    for (int i = 0; i < W; ++i) {
        const uint64_t e = base[idx[i]];
        r[i] = fromHalf(uint16_t(e));
        g[i] = fromHalf(uint16_t(e >> 16));
        b[i] = fromHalf(uint16_t(e >> 32));
        a[i] = fromHalf(uint16_t(e >> 48));
    }
}

}  // namespace rtfact::volume
