#include "engine/histogram.h"

#include <mutex>

#include "engine/built_scene.h"
#include "engine/scene_data.h"
#include "engine/usage_error.h"

namespace rtfact::engine {

using namespace rtfact::volume;

VolumeTransferInfo volumeTransferInfo(const Scene& scene, const Settings& settings, int maxBins) {
    if (!scene.data || scene.kind() != SceneKind::Volume) throw UsageError("histogram", "the scene is not a volume");
    // The TF and window are those a render with these settings uses (render_volume.cpp).
    const BuiltVolume built = builtVolume(scene, settings);
    VolumeTransferInfo info;
    {
        std::lock_guard lock(scene.data->mutex);
        info.histogram = histogramOf(*built.volume, maxBins);
    }
    info.tf = built.setup.tf;
    info.window = built.setup.window;
    return info;
}

}  // namespace rtfact::engine
