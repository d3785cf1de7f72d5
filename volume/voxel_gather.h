// Fetches two x-adjacent voxels per lane with one 32-bit gather for u8/u16 storage (the
// grid is padded so the over-read stays in bounds); f32 needs two 64-bit gathers. The
// load method is chosen per ISA at compile time, by measurement (docs/cli.md, Volumes):
// hardware gathers on AVX-512 and AVX2 (on Zen 5 the AVX2 build's per-lane scalar loads,
// one int-to-float conversion and insert per voxel, took most of the march), per-lane
// loads for narrower or scalar packets. Packets of several native chunks are fetched
// chunk by chunk.
#pragma once
#include <cstring>
#include <type_traits>

#include "core/simd/packet.h"

namespace rtfact::volume {

#if RTFACT_NATIVE_WIDTH >= 16
// Masked/zeroing forms with all lanes on: the plain intrinsics start from an undefined
// register, which GCC 12 reports as uninitialized (-Werror in CI); same instructions.
inline constexpr __mmask16 kAll16 = 0xFFFF;
inline constexpr __mmask8 kAll8 = 0xFF;
// The two 8-lane halves of 16 indices (a plain shuffle: the cast intrinsic has the same
// undefined-source problem).
RTFACT_INLINE __m256i lowHalf(simd::nvec<int32_t, 16> v) {
    return (__m256i)__builtin_shufflevector(v, v, 0, 1, 2, 3, 4, 5, 6, 7);
}
RTFACT_INLINE __m256i highHalf(simd::nvec<int32_t, 16> v) {
    return (__m256i)__builtin_shufflevector(v, v, 8, 9, 10, 11, 12, 13, 14, 15);
}
#endif

#if RTFACT_NATIVE_WIDTH == 8
RTFACT_INLINE __m128i lowHalf8(simd::nvec<int32_t, 8> v) { return _mm256_castsi256_si128((__m256i)v); }
RTFACT_INLINE __m128i highHalf8(simd::nvec<int32_t, 8> v) { return _mm256_extracti128_si256((__m256i)v, 1); }
// Four (even, odd) float pairs from each of two 64-bit gathers -> the even and the odd floats.
RTFACT_INLINE void splitPairs8(__m256 lo, __m256 hi, simd::nvec<float, 8>& even, simd::nvec<float, 8>& odd) {
    const __m256i order = _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7);
    const __m256 l = _mm256_permutevar8x32_ps(lo, order), h = _mm256_permutevar8x32_ps(hi, order);
    even = (simd::nvec<float, 8>)_mm256_permute2f128_ps(l, h, 0x20);
    odd = (simd::nvec<float, 8>)_mm256_permute2f128_ps(l, h, 0x31);
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
            const __m256 lo =
                _mm256_castsi256_ps(_mm256_i32gather_epi64((const long long*)base, lowHalf8(idx.c[0]), 4));
            const __m256 hi =
                _mm256_castsi256_ps(_mm256_i32gather_epi64((const long long*)base, highHalf8(idx.c[0]), 4));
            splitPairs8(lo, hi, a.c[0], b.c[0]);
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
// or 64-bit (u16) gather per lane fetches both entries. a0 = (x, y), a1 = (x, y + 1),
// b0 = (x + 1, y), b1 = (x + 1, y + 1).
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
            const __m256i g = _mm256_i32gather_epi32((const int*)base, (__m256i)idx.c[0], 2);
            const __m256i m = _mm256_set1_epi32(0xFF);
            a0.c[0] = (nvec<float, 8>)_mm256_cvtepi32_ps(_mm256_and_si256(g, m));
            a1.c[0] = (nvec<float, 8>)_mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srli_epi32(g, 8), m));
            b0.c[0] = (nvec<float, 8>)_mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srli_epi32(g, 16), m));
            b1.c[0] = (nvec<float, 8>)_mm256_cvtepi32_ps(_mm256_srli_epi32(g, 24));
        } else {
            const __m256 lo =
                _mm256_castsi256_ps(_mm256_i32gather_epi64((const long long*)base, lowHalf8(idx.c[0]), 4));
            const __m256 hi =
                _mm256_castsi256_ps(_mm256_i32gather_epi64((const long long*)base, highHalf8(idx.c[0]), 4));
            nvec<float, 8> pa, pb;  // (a0 | a1 << 16) and (b0 | b1 << 16) per lane
            splitPairs8(lo, hi, pa, pb);
            const __m256i ia = _mm256_castps_si256((__m256)pa), ib = _mm256_castps_si256((__m256)pb);
            const __m256i m = _mm256_set1_epi32(0xFFFF);
            a0.c[0] = (nvec<float, 8>)_mm256_cvtepi32_ps(_mm256_and_si256(ia, m));
            a1.c[0] = (nvec<float, 8>)_mm256_cvtepi32_ps(_mm256_srli_epi32(ia, 16));
            b0.c[0] = (nvec<float, 8>)_mm256_cvtepi32_ps(_mm256_and_si256(ib, m));
            b1.c[0] = (nvec<float, 8>)_mm256_cvtepi32_ps(_mm256_srli_epi32(ib, 16));
        }
        return;
    }
#endif
#if RTFACT_NATIVE_WIDTH >= 16
    if constexpr (W == 16) {
        if constexpr (sizeof(T) == 1) {
            const __m512i g =
                _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), kAll16, (__m512i)idx.c[0], (const void*)base, 2);
            const __m512i m = _mm512_set1_epi32(0xFF);
            a0.c[0] = (nvec<float, 16>)_mm512_maskz_cvtepi32_ps(kAll16, _mm512_and_si512(g, m));
            a1.c[0] = (nvec<float, 16>)_mm512_maskz_cvtepi32_ps(
                kAll16, _mm512_and_si512(_mm512_maskz_srli_epi32(kAll16, g, 8), m));
            b0.c[0] = (nvec<float, 16>)_mm512_maskz_cvtepi32_ps(
                kAll16, _mm512_and_si512(_mm512_maskz_srli_epi32(kAll16, g, 16), m));
            b1.c[0] = (nvec<float, 16>)_mm512_maskz_cvtepi32_ps(kAll16, _mm512_maskz_srli_epi32(kAll16, g, 24));
        } else {
            const __m512i lo =
                _mm512_mask_i32gather_epi64(_mm512_setzero_si512(), kAll8, lowHalf(idx.c[0]), (const void*)base, 4);
            const __m512i hi =
                _mm512_mask_i32gather_epi64(_mm512_setzero_si512(), kAll8, highHalf(idx.c[0]), (const void*)base, 4);
            const __m512i even = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30);
            const __m512i odd = _mm512_setr_epi32(1, 3, 5, 7, 9, 11, 13, 15, 17, 19, 21, 23, 25, 27, 29, 31);
            const __m512i ia = _mm512_permutex2var_epi32(lo, even, hi);  // a0 | a1 << 16
            const __m512i ib = _mm512_permutex2var_epi32(lo, odd, hi);   // b0 | b1 << 16
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

// Two adjacent floats per lane from base[2 * idx] (for interleaved tables): 64-bit
// gathers on AVX-512 (half the gathered elements of two 32-bit gathers).
template <int W>
RTFACT_INLINE void fetchFloatPair(const float* base, const Packet<W, int32_t>& idx2, Packet<W>& a, Packet<W>& b) {
    if constexpr (Packet<W>::C > 1) {
        for (int k = 0; k < Packet<W>::C; ++k)
            fetchFloatPair<Packet<W>::W>(base, idx2.chunk(k), a.chunk(k), b.chunk(k));
        return;
    }
#if RTFACT_NATIVE_WIDTH == 8
    if constexpr (W == 8) {
        const __m256 lo = _mm256_castsi256_ps(_mm256_i32gather_epi64((const long long*)base, lowHalf8(idx2.c[0]), 8));
        const __m256 hi = _mm256_castsi256_ps(_mm256_i32gather_epi64((const long long*)base, highHalf8(idx2.c[0]), 8));
        splitPairs8(lo, hi, a.c[0], b.c[0]);
        return;
    }
#endif
#if RTFACT_NATIVE_WIDTH >= 16
    if constexpr (W == 16) {
        const __m512 lo = _mm512_castsi512_ps(
            _mm512_mask_i32gather_epi64(_mm512_setzero_si512(), kAll8, lowHalf(idx2.c[0]), (const void*)base, 8));
        const __m512 hi = _mm512_castsi512_ps(
            _mm512_mask_i32gather_epi64(_mm512_setzero_si512(), kAll8, highHalf(idx2.c[0]), (const void*)base, 8));
        const __m512i even = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30);
        const __m512i odd = _mm512_setr_epi32(1, 3, 5, 7, 9, 11, 13, 15, 17, 19, 21, 23, 25, 27, 29, 31);
        a.c[0] = (simd::nvec<float, 16>)_mm512_permutex2var_ps(lo, even, hi);
        b.c[0] = (simd::nvec<float, 16>)_mm512_permutex2var_ps(lo, odd, hi);
        return;
    }
#endif
    for (int i = 0; i < W; ++i) {
        a[i] = base[2 * idx2[i]];
        b[i] = base[2 * idx2[i] + 1];
    }
}

}  // namespace rtfact::volume
