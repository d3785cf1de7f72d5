// A z-slab of a volume file, for a data-parallel rank (docs/mpi.md): raw, MetaImage, NRRD
// and NIfTI read only the slab's bytes (VolumeLoadOptions::slices); VTK image data, DICOM
// series and OpenVDB are read whole and cropped (their readers have no slab access).
#pragma once
#include <array>
#include <functional>
#include <string>

#include "volume/volume_grid.h"
#include "volume/volume_io.h"

namespace rtfact::volume {

struct VolumeSlab {
    VolumeGrid grid;                // the slab's slices; origin moved to its first slice
    std::array<int, 3> fullDims{};  // the whole volume's
    Vec3f fullOrigin;               // the whole volume's
    int z0 = 0;                     // first slice of the slab in the whole volume
    bool readWhole = false;         // the format had no slab access: read whole and cropped
};

// `pick` gets the whole volume's dims and returns the slices [z0, z1) to keep.
VolumeSlab loadVolumeSlices(const std::string& path, VolumeLoadOptions opt,
                            const std::function<std::array<int, 2>(const std::array<int, 3>&)>& pick);

}  // namespace rtfact::volume
