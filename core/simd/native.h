// The one native-vector layer: GCC vector extensions give portable arithmetic,
// comparisons and blends for every width; the few operations the compiler cannot
// express generically (sqrt, rcp, floor, movemask, gather) use intrinsics per width.
#pragma once
#include <immintrin.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <utility>

#if defined(RTFACT_FORCE_SCALAR)
#define RTFACT_NATIVE_WIDTH 1
#elif defined(__AVX512F__) && defined(__AVX512DQ__) && defined(__AVX512VL__)
#define RTFACT_NATIVE_WIDTH 16
#elif defined(__AVX2__) && defined(__FMA__)
#define RTFACT_NATIVE_WIDTH 8
#elif defined(__SSE4_1__)
#define RTFACT_NATIVE_WIDTH 4
#else
#define RTFACT_NATIVE_WIDTH 1
#endif

#define RTFACT_INLINE inline __attribute__((always_inline))

namespace rtfact::simd {

inline constexpr int kNativeWidth = RTFACT_NATIVE_WIDTH;

constexpr const char* isaName() {
    if constexpr (kNativeWidth == 16)
        return "avx512";
    else if constexpr (kNativeWidth == 8)
        return "avx2";
    else if constexpr (kNativeWidth == 4)
        return "sse4";
    else
        return "scalar";
}

// A width W is usable when the build's ISA has registers of that many lanes.
constexpr bool widthSupported(int w) { return w == 1 || ((w == 4 || w == 8 || w == 16) && w <= kNativeWidth); }

template <class T, int W>
struct NativeType {
    typedef T type __attribute__((vector_size(sizeof(T) * W)));
};
template <class T>
struct NativeType<T, 1> {
    using type = T;
};
// Raw native chunk of W lanes of T (a plain T when W == 1).
template <class T, int W>
using nvec = typename NativeType<T, W>::type;
// The same chunk at any address of a T: loads and stores of packets from arrays.
template <class T, int W>
struct UnalignedType {
    typedef T type __attribute__((vector_size(sizeof(T) * W), aligned(alignof(T)), may_alias));
};
template <class T>
struct UnalignedType<T, 1> {
    using type = T;
};
template <class T, int W>
using uvec = typename UnalignedType<T, W>::type;
// Masks: AVX-512 keeps 16-lane masks in k registers (one bit per lane); other widths
// use 0 / -1 integers per lane, also at width 1.
#if RTFACT_NATIVE_WIDTH >= 16
template <int W>
inline constexpr bool kBitMask = (W == 16);
#else
template <int W>
inline constexpr bool kBitMask = false;
#endif
template <int W, bool Bits = kBitMask<W>>
struct MaskType {
    using type = nvec<int32_t, W>;
};
#if RTFACT_NATIVE_WIDTH >= 16
template <>
struct MaskType<16, true> {
    using type = __mmask16;
};
#endif
template <int W>
using nmask = typename MaskType<W>::type;

template <int W>
RTFACT_INLINE nmask<W> maskSplat(bool b) {
    if constexpr (kBitMask<W>)
        return nmask<W>(b ? 0xFFFF : 0);
    else if constexpr (W == 1)
        return b ? -1 : 0;
    else
        return nvec<int32_t, W>{} - int32_t(b ? 1 : 0);
}
template <int W>
RTFACT_INLINE bool maskLane(nmask<W> m, int j) {
    if constexpr (kBitMask<W>)
        return (m >> j) & 1;
    else if constexpr (W == 1)
        return m != 0;
    else
        return m[j] != 0;
}
template <int W>
RTFACT_INLINE void maskSetLane(nmask<W>& m, int j, bool b) {
    if constexpr (kBitMask<W>)
        m = nmask<W>(b ? (m | (1u << j)) : (m & ~(1u << j)));
    else if constexpr (W == 1)
        m = b ? -1 : 0;
    else
        m[j] = b ? -1 : 0;
}

template <class T, int W>
RTFACT_INLINE nvec<T, W> splat(T s) {
    if constexpr (W == 1) {
        return s;
    } else {
        if constexpr (std::is_same_v<T, float>) {
            // Broadcast intrinsics: GCC builds generic vector fills through the stack.
#if RTFACT_NATIVE_WIDTH >= 16
            if constexpr (W == 16) return _mm512_set1_ps(s);
#endif
#if RTFACT_NATIVE_WIDTH >= 8
            if constexpr (W == 8) return _mm256_set1_ps(s);
#endif
            if constexpr (W == 4) return _mm_set1_ps(s);
        } else if constexpr (sizeof(T) == 4) {
            using I = nvec<int32_t, W>;
#if RTFACT_NATIVE_WIDTH >= 16
            if constexpr (W == 16) return (nvec<T, W>)(I)_mm512_set1_epi32(int32_t(s));
#endif
#if RTFACT_NATIVE_WIDTH >= 8
            if constexpr (W == 8) return (nvec<T, W>)(I)_mm256_set1_epi32(int32_t(s));
#endif
            if constexpr (W == 4) return (nvec<T, W>)(I)_mm_set1_epi32(int32_t(s));
        }
        nvec<T, W> r;
        for (int i = 0; i < W; ++i) r[i] = s;
        return r;
    }
}

#if RTFACT_NATIVE_WIDTH >= 16
// k-mask comparisons for 16 lanes of float, int32 or uint32.
template <int Pred, class V>
RTFACT_INLINE __mmask16 cmp16(V a, V b) {
    using E = std::remove_cvref_t<decltype(a[0])>;
    if constexpr (std::is_same_v<E, float>) {
        constexpr int fp = Pred == 0 ? _CMP_LT_OQ : Pred == 1 ? _CMP_LE_OQ : Pred == 2 ? _CMP_EQ_OQ : _CMP_NEQ_UQ;
        return _mm512_cmp_ps_mask(a, b, fp);
    } else if constexpr (std::is_signed_v<E>) {
        constexpr int ip = Pred == 0   ? _MM_CMPINT_LT
                           : Pred == 1 ? _MM_CMPINT_LE
                           : Pred == 2 ? _MM_CMPINT_EQ
                                       : _MM_CMPINT_NE;
        return _mm512_cmp_epi32_mask((__m512i)a, (__m512i)b, ip);
    } else {
        constexpr int ip = Pred == 0   ? _MM_CMPINT_LT
                           : Pred == 1 ? _MM_CMPINT_LE
                           : Pred == 2 ? _MM_CMPINT_EQ
                                       : _MM_CMPINT_NE;
        return _mm512_cmp_epu32_mask((__m512i)a, (__m512i)b, ip);
    }
}
#define RTFACT_CMP16(pred, a, b)  \
    if constexpr (kBitMask<W>)    \
        return cmp16<pred>(a, b); \
    else
#else
#define RTFACT_CMP16(pred, a, b)
#endif

template <int W, class V>
RTFACT_INLINE nmask<W> cmpLt(V a, V b) {
    RTFACT_CMP16(0, a, b)
    if constexpr (W == 1)
        return -int32_t(a < b);
    else
        return a < b;
}
template <int W, class V>
RTFACT_INLINE nmask<W> cmpLe(V a, V b) {
    RTFACT_CMP16(1, a, b)
    if constexpr (W == 1)
        return -int32_t(a <= b);
    else
        return a <= b;
}
template <int W, class V>
RTFACT_INLINE nmask<W> cmpEq(V a, V b) {
    RTFACT_CMP16(2, a, b)
    if constexpr (W == 1)
        return -int32_t(a == b);
    else
        return a == b;
}
template <int W, class V>
RTFACT_INLINE nmask<W> cmpNe(V a, V b) {
    RTFACT_CMP16(3, a, b)
    if constexpr (W == 1)
        return -int32_t(a != b);
    else
        return a != b;
}
#undef RTFACT_CMP16

template <int W, class V>
RTFACT_INLINE V select(nmask<W> m, V a, V b) {
#if RTFACT_NATIVE_WIDTH >= 16
    if constexpr (kBitMask<W>) {
        using E = std::remove_cvref_t<decltype(a[0])>;
        if constexpr (std::is_same_v<E, float>)
            return _mm512_mask_blend_ps(m, b, a);
        else
            return (V)_mm512_mask_blend_epi32(m, (__m512i)b, (__m512i)a);
    } else
#endif
        if constexpr (W == 1)
        return m ? a : b;
    else
        return m ? a : b;
}

// min/max through intrinsics: the ternary form becomes compare+blend against constants.
template <int W, class V>
RTFACT_INLINE V vmin(V a, V b) {
    if constexpr (W == 1)
        return a < b ? a : b;
    else {
        using E = std::remove_cvref_t<decltype(a[0])>;
        if constexpr (std::is_same_v<E, float>) {
#if RTFACT_NATIVE_WIDTH >= 16
            if constexpr (W == 16) return _mm512_maskz_min_ps(__mmask16(0xFFFF), a, b);  // maskz: no undefined source
#endif
#if RTFACT_NATIVE_WIDTH >= 8
            if constexpr (W == 8) return _mm256_min_ps(a, b);
#endif
            if constexpr (W == 4) return _mm_min_ps(a, b);
        }
        return a < b ? a : b;
    }
}
template <int W, class V>
RTFACT_INLINE V vmax(V a, V b) {
    if constexpr (W == 1)
        return a > b ? a : b;
    else {
        using E = std::remove_cvref_t<decltype(a[0])>;
        if constexpr (std::is_same_v<E, float>) {
#if RTFACT_NATIVE_WIDTH >= 16
            if constexpr (W == 16) return _mm512_maskz_max_ps(__mmask16(0xFFFF), a, b);
#endif
#if RTFACT_NATIVE_WIDTH >= 8
            if constexpr (W == 8) return _mm256_max_ps(a, b);
#endif
            if constexpr (W == 4) return _mm_max_ps(a, b);
        }
        return a > b ? a : b;
    }
}

template <int W>
RTFACT_INLINE nvec<float, W> vsqrt(nvec<float, W> a) {
    if constexpr (W == 1) return std::sqrt(a);
#if RTFACT_NATIVE_WIDTH >= 16
    else if constexpr (W == 16)
        return _mm512_maskz_sqrt_ps(__mmask16(0xFFFF), a);
#endif
#if RTFACT_NATIVE_WIDTH >= 8
    else if constexpr (W == 8)
        return _mm256_sqrt_ps(a);
#endif
    else
        return _mm_sqrt_ps(a);
}

template <int W>
RTFACT_INLINE nvec<float, W> vfloor(nvec<float, W> a) {
    if constexpr (W == 1) return std::floor(a);
#if RTFACT_NATIVE_WIDTH >= 16
    else if constexpr (W == 16)
        return _mm512_maskz_roundscale_ps(__mmask16(0xFFFF), a, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
#endif
#if RTFACT_NATIVE_WIDTH >= 8
    else if constexpr (W == 8)
        return _mm256_floor_ps(a);
#endif
    else
        return _mm_floor_ps(a);
}

// Full-precision reciprocal: hardware estimate refined by one Newton step.
template <int W>
RTFACT_INLINE nvec<float, W> vrcp(nvec<float, W> a) {
    if constexpr (W == 1)
        return 1.0f / a;
    else {
        nvec<float, W> r;
#if RTFACT_NATIVE_WIDTH >= 16
        if constexpr (W == 16)
            r = _mm512_maskz_rcp14_ps(__mmask16(0xFFFF), a);
        else
#endif
#if RTFACT_NATIVE_WIDTH >= 8
            if constexpr (W == 8)
            r = _mm256_rcp_ps(a);
        else
#endif
            r = _mm_rcp_ps(a);
        return r * (2.0f - a * r);
    }
}

template <int W>
RTFACT_INLINE nvec<float, W> vabs(nvec<float, W> a) {
    if constexpr (W == 1)
        return std::fabs(a);
    else
        return (nvec<float, W>)((nvec<int32_t, W>)a & 0x7fffffff);
}

// Bit i set when lane i of the mask is set.
template <int W>
RTFACT_INLINE uint32_t movemask(nmask<W> m) {
    if constexpr (W == 1)
        return m ? 1u : 0u;
    else if constexpr (kBitMask<W>)
        return uint32_t(m);
#if RTFACT_NATIVE_WIDTH >= 16
    else if constexpr (W == 16)
        return _mm512_movepi32_mask((__m512i)m);
#endif
#if RTFACT_NATIVE_WIDTH >= 8
    else if constexpr (W == 8)
        return uint32_t(_mm256_movemask_ps((__m256)m));
#endif
    else
        return uint32_t(_mm_movemask_ps((__m128)m));
}

template <int W>
RTFACT_INLINE nvec<float, W> gather(const float* base, nvec<int32_t, W> idx) {
    if constexpr (W == 1) return base[idx];
#if RTFACT_NATIVE_WIDTH >= 16
    else if constexpr (W == 16)
        return _mm512_mask_i32gather_ps(_mm512_setzero_ps(), __mmask16(0xFFFF), (__m512i)idx, base, 4);
#endif
#if RTFACT_NATIVE_WIDTH >= 8
    else if constexpr (W == 8)
        return _mm256_i32gather_ps(base, (__m256i)idx, 4);
#endif
    else {
        nvec<float, W> r;
        for (int i = 0; i < W; ++i) r[i] = base[idx[i]];
        return r;
    }
}

template <int W>
RTFACT_INLINE nvec<int32_t, W> gather(const int32_t* base, nvec<int32_t, W> idx) {
    if constexpr (W == 1) return base[idx];
#if RTFACT_NATIVE_WIDTH >= 16
    else if constexpr (W == 16)
        return (nvec<int32_t, W>)_mm512_mask_i32gather_epi32(_mm512_setzero_si512(), __mmask16(0xFFFF), (__m512i)idx,
                                                             base, 4);
#endif
#if RTFACT_NATIVE_WIDTH >= 8
    else if constexpr (W == 8)
        return (nvec<int32_t, W>)_mm256_i32gather_epi32(base, (__m256i)idx, 4);
#endif
    else {
        nvec<int32_t, W> r;
        for (int i = 0; i < W; ++i) r[i] = base[idx[i]];
        return r;
    }
}

// Truncating float -> int and exact int -> float conversions.
template <int W>
RTFACT_INLINE nvec<int32_t, W> toInt(nvec<float, W> a) {
    if constexpr (W == 1)
        return int32_t(a);
    else
        return __builtin_convertvector(a, nvec<int32_t, W>);
}
template <int W>
RTFACT_INLINE nvec<float, W> toFloat(nvec<int32_t, W> a) {
    if constexpr (W == 1)
        return float(a);
    else
        return __builtin_convertvector(a, nvec<float, W>);
}

namespace detail {
template <class V, size_t... I>
RTFACT_INLINE auto shuffleLanes(V a, std::index_sequence<I...>) {
    return __builtin_shufflevector(a, a, int(I)...);
}
template <size_t Off, size_t... I>
constexpr auto offsetSeq(std::index_sequence<I...>) {
    return std::index_sequence<(I + Off)...>{};
}
}  // namespace detail
// Lanes [0, W/2) and [W/2, W) of a W-lane vector, as W/2-lane vectors (plain shuffles:
// the cast intrinsics start from an undefined register, which GCC 12 reports).
template <int W, class V>
RTFACT_INLINE auto lowHalf(V a) {
    return detail::shuffleLanes(a, std::make_index_sequence<W / 2>{});
}
template <int W, class V>
RTFACT_INLINE auto highHalf(V a) {
    return detail::shuffleLanes(a, detail::offsetSeq<W / 2>(std::make_index_sequence<W / 2>{}));
}

// Horizontal min/max: halves folded with one vector min per level (log2 W dependent
// steps, not W - 1); the last four lanes one by one. Same result as a lane-by-lane scan
// for inputs without NaN.
template <int W, class V>
RTFACT_INLINE auto hmin(V a) {
    if constexpr (W == 1)
        return a;
    else if constexpr (W > 4)
        return hmin<W / 2>(vmin<W / 2>(lowHalf<W>(a), highHalf<W>(a)));
    else {
        auto r = a[0];
        for (int i = 1; i < W; ++i) r = a[i] < r ? a[i] : r;
        return r;
    }
}
template <int W, class V>
RTFACT_INLINE auto hmax(V a) {
    if constexpr (W == 1)
        return a;
    else if constexpr (W > 4)
        return hmax<W / 2>(vmax<W / 2>(lowHalf<W>(a), highHalf<W>(a)));
    else {
        auto r = a[0];
        for (int i = 1; i < W; ++i) r = a[i] > r ? a[i] : r;
        return r;
    }
}

template <int W, class V>
RTFACT_INLINE auto& laneRef(V& v, int i) {
    if constexpr (W == 1) {
        (void)i;
        return v;
    } else
        return reinterpret_cast<std::remove_reference_t<decltype(v[0])>*>(&v)[i];
}

}  // namespace rtfact::simd
