// Box4: an axis-aligned box held in two SSE registers (x, y, z and a spare lane), the
// accumulator the SAH builders bin and partition with: extending it is one min and one max.
#pragma once
#include <immintrin.h>

#include <limits>

#include "core/math/aabb.h"
#include "core/simd/native.h"

namespace rtfact {

struct Box4 {
    __m128 lo = _mm_set1_ps(std::numeric_limits<float>::infinity());
    __m128 hi = _mm_set1_ps(-std::numeric_limits<float>::infinity());

    RTFACT_INLINE void extend(__m128 l, __m128 h) {
        lo = _mm_min_ps(lo, l);
        hi = _mm_max_ps(hi, h);
    }
    RTFACT_INLINE void extend(const Box4& b) { extend(b.lo, b.hi); }
    // Half the surface area (SAH costs only compare areas); 0 for an empty box.
    float halfArea() const {
        alignas(16) float l[4], h[4];
        _mm_store_ps(l, lo);
        _mm_store_ps(h, hi);
        const float dx = h[0] - l[0], dy = h[1] - l[1], dz = h[2] - l[2];
        return dx < 0.0f ? 0.0f : dx * dy + dy * dz + dz * dx;
    }
    float area() const { return 2.0f * halfArea(); }
    AABB aabb() const {
        alignas(16) float l[4], h[4];
        _mm_store_ps(l, lo);
        _mm_store_ps(h, hi);
        return {{l[0], l[1], l[2]}, {h[0], h[1], h[2]}};
    }
};

// Twice the centroid of the box (lo, hi) whose fourth lane of lo carries other bits (the
// builders keep an element id there): that lane is zeroed before the add. Ids read as
// denormal floats, and an add with a denormal operand (and the arithmetic after it) takes
// a slow path: binning ran 2.6x slower with them (Zen 5, docs/wide-bvh-build.md). min and
// max do not, so boxes keep the raw lane.
RTFACT_INLINE __m128 doubledCentroid(__m128 lo, __m128 hi) {
    return _mm_add_ps(_mm_blend_ps(lo, _mm_setzero_ps(), 8), hi);
}
// Adds a reference's box (lo, hi) to box and its doubled centroid to cbox (the bounds and
// centroid bounds the SAH builders keep per range).
RTFACT_INLINE void extendWithCentroid(Box4& box, Box4& cbox, __m128 lo, __m128 hi) {
    const __m128 c = doubledCentroid(lo, hi);
    box.extend(lo, hi);
    cbox.extend(c, c);
}

}  // namespace rtfact
