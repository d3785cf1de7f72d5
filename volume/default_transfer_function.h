// The transfer function used when none is given, chosen from the data (the CT bone preset
// on an MRI renders as speckle or a blob):
//   1. a modality the file states wins: CT gets the bone preset (in Hounsfield units when
//      the values are), any other modality the histogram ramp;
//   2. without one, values that look like Hounsfield units (well below zero, with a share
//      of voxels at air, -1000) get the bone preset;
//   3. everything else (MRI, CT in arbitrary units, microscopy, simulations) gets an
//      opacity ramp placed by the histogram: from the end of the background peak (the
//      most common value in the lower half of the range) to the 99.5th percentile of
//      the voxels above it, with its middle at their median.
// Unshaded DVR gets a translucent ramp (see through to the inside), shaded DVR and iso an
// opaque one (surfaces), MIP a grey ramp over the same window (the full range for CT). The
// ramps' opacities are per voxel of distance, tuned for a volume about 200 voxels deep and
// rescaled to the volume's depth so a 48^3 scan is no fainter than a 512^3 one.
#pragma once
#include <string>
#include <utility>

#include "volume/transfer_function.h"
#include "volume/value_histogram.h"
#include "volume/volume_grid.h"
#include "volume/volume_scene.h"

namespace rtfact::volume {

struct DefaultTransferFunction {
    TransferFunction tf;
    std::pair<float, float> window;  // data values the normalized points span
    std::string reason;              // why this one, e.g. "DICOM modality CT"
    // "ct-bone (DICOM modality CT)"
    std::string describe() const { return tf.name + " (" + reason + ")"; }
};

// Where the histogram ramp goes, in data values.
struct RampPlacement {
    float background = 0;  // centre of the background peak's bin
    float lo = 0, hi = 1;  // ramp from transparent at lo to its full opacity at hi
    float median = 0.5f;   // of the voxels above the background: the ramp's middle
};
RampPlacement placeHistogramRamp(const ValueHistogram& h);

// Values reach -500 or below for at least 0.1% of the voxels, and above 0: air and tissue
// in Hounsfield units.
bool looksLikeHounsfield(const ValueHistogram& h);

// Typical ray length through a volume in steps of its smallest spacing (the unit of the
// opacities): the mean physical extent over the smallest spacing.
float typicalDepthVoxels(const int dims[3], Vec3f spacing);
inline constexpr float kReferenceDepthVoxels = 200.0f;

DefaultTransferFunction chooseDefaultTransferFunction(const VolumeMetadata& meta, const ValueHistogram& h,
                                                      VolumeMode mode = VolumeMode::DVR,
                                                      float depthVoxels = kReferenceDepthVoxels);

}  // namespace rtfact::volume
