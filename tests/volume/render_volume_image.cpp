#include "render_volume_image.h"

#include <stdexcept>
#include <string>

#include "core/render/packet_dispatch.h"
#include "core/render/pixel_center_sampler.h"
#include "core/render/ray_tracing_renderer.h"
#include "volume/volume_integrator.h"

namespace rtfact::test {

template <class T>
RenderStats renderVolumeImage(int packet, const volume::VolumeScene<T>& scene, const PinholeCamera& cam,
                              RGBAFramebuffer& fb, const RenderOptions& ro) {
    const RayTracingRenderer<PixelCenterSampler, volume::VolumeIntegrator> r{};
    RenderStats stats;
    bool done = false;
    dispatchPacketSize(packet, [&]<int N>() {
        // only the sizes the tests render (the other small widths would cost a full set of
        // marches each)
        if constexpr (N == 1 || N == simd::kNativeWidth || N >= 16) {
            stats = renderImage<N>(r, scene, cam, fb, ro);
            done = true;
        }
    });
    if (!done)
        throw std::invalid_argument("renderVolumeImage: packet size " + std::to_string(packet) + " is not compiled");
    return stats;
}

template RenderStats renderVolumeImage(int, const volume::VolumeScene<uint8_t>&, const PinholeCamera&, RGBAFramebuffer&,
                                       const RenderOptions&);
template RenderStats renderVolumeImage(int, const volume::VolumeScene<uint16_t>&, const PinholeCamera&,
                                       RGBAFramebuffer&, const RenderOptions&);
template RenderStats renderVolumeImage(int, const volume::VolumeScene<float>&, const PinholeCamera&, RGBAFramebuffer&,
                                       const RenderOptions&);

}  // namespace rtfact::test
