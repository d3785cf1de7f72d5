// Renderer: renders a rectangular region of the image for a scene through a camera,
// writing each pixel of the region once per sample (a framebuffer may take the first
// sample's writes as its clear: RGBAFramebuffer::overwriteSample).
#pragma once
#include "core/concepts/camera.h"
#include "core/concepts/framebuffer.h"

namespace rtfact {

template <class R, class Scene, class Cam, class FB>
concept Renderer = Camera<Cam> && Framebuffer<FB> &&
    requires(const R& r, const Scene& s, const Cam& c, FB& fb, Region region) {
    r.template render<1>(s, c, fb, region, 0);
    r.template render<simd::kNativeWidth>(s, c, fb, region, 0);
};

}  // namespace rtfact
