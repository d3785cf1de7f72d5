// RayTracingRenderer<Sampler, Integrator>: walks a region in blocks of N pixels (as square
// as N allows), asks the sampler where the rays start, the camera for the rays and the
// integrator for their radiance, and writes it into the framebuffer.
#pragma once
#include "core/concepts/camera.h"
#include "core/concepts/framebuffer.h"
#include "core/concepts/integrator.h"
#include "core/concepts/renderer.h"
#include "core/concepts/sampler.h"

namespace rtfact {

// Block shape of an N-ray packet: the smallest divisor of N that is at least sqrt(N)
// is the width (16x16 for 256, 8x8 for 64, 4x4 for 16, 4x2 for 8).
constexpr int packetBlockWidth(int n) {
    for (int d = 1; d <= n; ++d)
        if (n % d == 0 && d * d >= n) return d;
    return n;
}

template <Sampler S, class I>
struct RayTracingRenderer {
    S sampler{};
    I integrator{};

    template <int N, class Scene, Camera Cam, Framebuffer FB>
    requires Integrator<I, Scene>
    void render(const Scene& scene, const Cam& cam, FB& fb, Region region, int sample) const {
        constexpr int bw = packetBlockWidth(N), bh = N / bw;
        const Packet<N, int32_t> lx = laneOffsets<N>(bw, true), ly = laneOffsets<N>(bw, false);
        for (int y = region.y0; y < region.y1; y += bh) {
            for (int x = region.x0; x < region.x1; x += bw) {
                PixelSample<N> s;
                s.px = lx + Packet<N, int32_t>(x);
                s.py = ly + Packet<N, int32_t>(y);
                s.sample = sample;
                const Mask<N> valid = (s.px < Packet<N, int32_t>(region.x1)) & (s.py < Packet<N, int32_t>(region.y1));
                Packet<N> ox, oy;
                sampler.template offsets<N>(s.px, s.py, sample, ox, oy);
                RayPacket<N> rays;
                cam.template generate<N>(toFloat(s.px) + ox, toFloat(s.py) + oy, rays);
                if constexpr (requires { fb.template prefetch<N>(s); }) fb.template prefetch<N>(s);
                const Radiance<N> r = integrator.template eval<N>(scene, rays, valid, s);
                fb.template write<N>(s, r, valid);
            }
        }
    }

   private:
    template <int N>
    static Packet<N, int32_t> laneOffsets(int bw, bool xs) {
        Packet<N, int32_t> p;
        for (int i = 0; i < N; ++i) p[i] = xs ? i % bw : i / bw;
        return p;
    }
};

}  // namespace rtfact
