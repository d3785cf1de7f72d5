// Sampler: where inside each pixel the rays of a packet start, per sample index.
#pragma once
#include "core/simd/vec3.h"

namespace rtfact {

template <class S>
concept Sampler = requires(const S& s, const Packet<1, int32_t>& i1, const Packet<simd::kNativeWidth, int32_t>& in,
                           Packet<1>& f1, Packet<simd::kNativeWidth>& fn) {
    s.template offsets<1>(i1, i1, 0, f1, f1);
    s.template offsets<simd::kNativeWidth>(in, in, 0, fn, fn);
};

}  // namespace rtfact
