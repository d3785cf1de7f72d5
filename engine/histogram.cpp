#include "engine/histogram.h"

#include <mutex>

#include "engine/scene_data.h"
#include "engine/usage_error.h"
#include "volume/default_transfer_function.h"

namespace rtfact::engine {

using namespace rtfact::volume;

VolumeTransferInfo volumeTransferInfo(const Scene& scene, const Settings& settings, int maxBins) {
    if (!scene.data || scene.kind() != SceneKind::Volume) throw UsageError("histogram", "the scene is not a volume");
    detail::SceneData& d = *scene.data;
    const VolumeSettings& s = settings.volume;
    // The same choice as the volume render unit makes (render_volume.cpp).
    const VolumeMode mode = s.mode == "shaded" ? VolumeMode::Shaded
                            : s.mode == "mip"  ? VolumeMode::MIP
                            : s.mode == "iso"  ? VolumeMode::Iso
                                               : VolumeMode::DVR;
    std::lock_guard lock(d.mutex);
    const BrickedVolume& vol = d.volume.vol;
    const auto [lo, hi] = vol.valueRange();
    VolumeTransferInfo info;
    info.histogram = histogramOf(vol, maxBins);
    if (s.tf) {
        info.tf = *s.tf;
        info.window = resolveWindow(info.tf, lo, hi, s.window, s.level);
    } else {
        // The default is chosen on the full-resolution histogram, as the render does.
        const DefaultTransferFunction dt =
            chooseDefaultTransferFunction(vol.meta, histogramOf(vol), mode, typicalDepthVoxels(vol.dims, vol.spacing));
        info.tf = dt.tf;
        info.window = s.window || s.level ? resolveWindow(info.tf, lo, hi, s.window, s.level) : dt.window;
    }
    return info;
}

}  // namespace rtfact::engine
