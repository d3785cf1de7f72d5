// Framebuffer: receives radiance for blocks of pixels.
#pragma once
#include <concepts>

#include "core/concepts/integrator.h"

namespace rtfact {

template <class F>
concept Framebuffer = requires(F& fb, const Radiance<1>& r1, const Radiance<simd::kNativeWidth>& rn,
                               const PixelSample<1>& s1, const PixelSample<simd::kNativeWidth>& sn, const Mask<1>& m1,
                               const Mask<simd::kNativeWidth>& mn) {
    { fb.width() } -> std::convertible_to<int>;
    { fb.height() } -> std::convertible_to<int>;
    fb.template write<1>(s1, r1, m1);
    fb.template write<simd::kNativeWidth>(sn, rn, mn);
};

}  // namespace rtfact
