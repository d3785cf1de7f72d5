#include "render_volume_image.h"

#include <stdexcept>
#include <string>

#include "core/render/pixel_center_sampler.h"
#include "core/render/ray_tracing_renderer.h"
#include "volume/volume_integrator.h"

namespace rtfact::test {

template <class T>
RenderStats renderVolumeImage(int packet, const volume::VolumeScene<T>& scene, const PinholeCamera& cam,
                              RGBAFramebuffer& fb, const RenderOptions& ro) {
    const RayTracingRenderer<PixelCenterSampler, volume::VolumeIntegrator> r{};
    constexpr int kW = simd::kNativeWidth;
    switch (packet) {
        case 1:
            return renderImage<1>(r, scene, cam, fb, ro);
        case 16:
            return renderImage<16>(r, scene, cam, fb, ro);
        case 64:
            return renderImage<64>(r, scene, cam, fb, ro);
        case 256:
            return renderImage<256>(r, scene, cam, fb, ro);
        default:
            break;
    }
    // the native width, where it is none of the above (SSE4: 4, AVX2: 8)
    if constexpr (kW != 1 && kW != 16)
        if (packet == kW) return renderImage<kW>(r, scene, cam, fb, ro);
    throw std::invalid_argument("renderVolumeImage: packet size " + std::to_string(packet) + " is not compiled");
}

template RenderStats renderVolumeImage(int, const volume::VolumeScene<uint8_t>&, const PinholeCamera&, RGBAFramebuffer&,
                                       const RenderOptions&);
template RenderStats renderVolumeImage(int, const volume::VolumeScene<uint16_t>&, const PinholeCamera&,
                                       RGBAFramebuffer&, const RenderOptions&);
template RenderStats renderVolumeImage(int, const volume::VolumeScene<float>&, const PinholeCamera&, RGBAFramebuffer&,
                                       const RenderOptions&);

}  // namespace rtfact::test
