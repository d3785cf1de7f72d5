// The last steps of every rendering subcommand: camera, framebuffer, the renderer at
// the requested packet size on the tile scheduler, the image file and the stats.
#pragma once
#include "apps/rtfact/common_options.h"
#include "core/render/framebuffer.h"
#include "core/render/image_io.h"
#include "core/render/jittered_sampler.h"
#include "core/render/packet_dispatch.h"
#include "core/render/pinhole_camera.h"
#include "core/render/ray_tracing_renderer.h"
#include "core/render/tile_scheduler.h"
#include "core/util/memory_budget.h"

namespace rtfact::app {

// Returns the render statistics (render time excludes writing the image).
template <class Integrator, class Scene>
RenderStats renderToFile(const Scene& scene, const Integrator& integrator, const CommonOptions& o,
                         const CameraFrame& frame, Stats& stats) {
    const PinholeCamera cam(frame, o.width, o.height);
    // Accumulation buffer, resolved copy and 8-bit output.
    checkMemory(o.out, uint64_t(o.width) * uint64_t(o.height) * 36u,
                "a " + std::to_string(o.width) + "x" + std::to_string(o.height) + " framebuffer",
                "use a smaller --size");
    RGBAFramebuffer fb(o.width, o.height);
    const RayTracingRenderer<JitteredSampler, Integrator> renderer{{}, integrator};
    RenderOptions ro;
    ro.threads = o.threads;
    ro.spp = o.spp;
    ro.progress = !o.quiet;
    RenderStats rs;
    dispatchPacketSize(o.packet, [&]<int N>() { rs = renderImage<N>(renderer, scene, cam, fb, ro); });
    writeImage(o.out, o.width, o.height, fb.resolved(o.spp));
    stats.add("render_ms", rs.ms);
    stats.add("rays", (unsigned long long)rs.rays);
    stats.add("mrays_per_s", rs.ms > 0 ? double(rs.rays) / (rs.ms * 1000.0) : 0.0);
    stats.add("threads", rs.threads);
    stats.add("packet", o.packet);
    stats.add("spp", o.spp);
    stats.add("width", o.width);
    stats.add("height", o.height);
    return rs;
}

}  // namespace rtfact::app
