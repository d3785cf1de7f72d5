// Framebuffer: receives radiance for blocks of pixels, and clears rectangles of them (a
// render clears each tile in the thread that renders it, not the image in one serial pass).
#pragma once
#include <concepts>

#include "core/concepts/integrator.h"

namespace rtfact {

struct Region {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // half-open pixel rectangle
    int width() const { return x1 - x0; }
    int height() const { return y1 - y0; }
};

template <class F>
concept Framebuffer = requires(F& fb, const Radiance<1>& r1, const Radiance<simd::kNativeWidth>& rn,
                               const PixelSample<1>& s1, const PixelSample<simd::kNativeWidth>& sn, const Mask<1>& m1,
                               const Mask<simd::kNativeWidth>& mn, const Region& region, bool depthToo) {
    { fb.width() } -> std::convertible_to<int>;
    { fb.height() } -> std::convertible_to<int>;
    fb.template write<1>(s1, r1, m1);
    fb.template write<simd::kNativeWidth>(sn, rn, mn);
    fb.clear(region, depthToo);
};

}  // namespace rtfact
