// Fetches two x-adjacent voxels per lane with one 32-bit gather for u8/u16 storage (the
// grid is padded so the over-read stays in bounds); f32 needs two gathers.
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

template <class T, int W>
RTFACT_INLINE void fetchPair(const T* base, const Packet<W, int32_t>& idx, Packet<W>& a, Packet<W>& b) {
    using namespace simd;
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

// Two adjacent floats per lane from base[2 * idx] (for interleaved tables): 64-bit
// gathers on AVX-512 (half the gathered elements of two 32-bit gathers).
template <int W>
RTFACT_INLINE void fetchFloatPair(const float* base, const Packet<W, int32_t>& idx2, Packet<W>& a, Packet<W>& b) {
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
