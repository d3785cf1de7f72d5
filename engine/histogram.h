// The data a transfer-function editor draws: a volume scene's value histogram and the
// transfer function with its data window that a render with these settings uses (the
// given --tf, or the default the engine chooses from the data).
#pragma once
#include <utility>

#include "engine/scene.h"
#include "engine/settings.h"
#include "volume/transfer_function.h"
#include "volume/value_histogram.h"

namespace rtfact::engine {

struct VolumeTransferInfo {
    volume::ValueHistogram histogram;
    volume::TransferFunction tf;
    std::pair<float, float> window;  // data values the TF's normalized points span
};

// Throws UsageError when the scene is not a volume.
VolumeTransferInfo volumeTransferInfo(const Scene& scene, const Settings& settings = {}, int maxBins = 256);

}  // namespace rtfact::engine
