// renderVolumeImage: one pass of the pixel-centre ray tracing renderer with the
// VolumeIntegrator over a VolumeScene<T>, in packets of `packet` rays. It is compiled once
// for the volume tests (render_volume_image.cpp): each packet size instantiates the
// integrator's marches for every layout and mode, a minute of compile time that every test
// file rendering a scene would otherwise spend again.
#pragma once
#include <cstdint>

#include "core/render/framebuffer.h"
#include "core/render/pinhole_camera.h"
#include "core/render/tile_scheduler.h"
#include "volume/volume_scene.h"

namespace rtfact::test {

// The packet sizes compiled: 1, the native width, 16, 64 and 256 (others throw
// std::invalid_argument).
template <class T>
RenderStats renderVolumeImage(int packet, const volume::VolumeScene<T>& scene, const PinholeCamera& cam,
                              RGBAFramebuffer& fb, const RenderOptions& ro);

extern template RenderStats renderVolumeImage(int, const volume::VolumeScene<uint8_t>&, const PinholeCamera&,
                                              RGBAFramebuffer&, const RenderOptions&);
extern template RenderStats renderVolumeImage(int, const volume::VolumeScene<uint16_t>&, const PinholeCamera&,
                                              RGBAFramebuffer&, const RenderOptions&);
extern template RenderStats renderVolumeImage(int, const volume::VolumeScene<float>&, const PinholeCamera&,
                                              RGBAFramebuffer&, const RenderOptions&);

}  // namespace rtfact::test
