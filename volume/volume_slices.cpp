#include "volume/volume_slices.h"

#include <cstring>
#include <vector>

#include "core/util/error.h"

namespace rtfact::volume {

VolumeSlab loadVolumeSlices(const std::string& path, VolumeLoadOptions opt,
                            const std::function<std::array<int, 2>(const std::array<int, 3>&)>& pick) {
    VolumeSlab s;
    std::array<int, 2> z{};
    bool called = false;
    opt.slices = [&](const std::array<int, 3>& dims) {
        s.fullDims = dims;
        z = pick(dims);
        called = true;
        return z;
    };
    s.grid = loadVolume(path, opt);
    if (!called) {
        // No slab access in this format: crop the whole grid.
        s.readWhole = true;
        s.fullDims = {s.grid.dims[0], s.grid.dims[1], s.grid.dims[2]};
        z = pick(s.fullDims);
        if (z[0] < 0 || z[1] <= z[0] || z[1] > s.grid.dims[2]) throw Error(path, "slab outside the volume");
        const std::vector<uint8_t> whole = std::move(s.grid.bytes);
        VolumeGrid c = s.grid;  // the metadata
        c.dims[2] = z[1] - z[0];
        c.allocate(s.grid.storage);
        const size_t slice = size_t(c.dims[0]) * size_t(c.dims[1]) * size_t(storageBytes(c.storage));
        std::memcpy(c.bytes.data(), whole.data() + size_t(z[0]) * slice, size_t(c.dims[2]) * slice);
        s.grid = std::move(c);
    }
    s.z0 = z[0];
    s.fullOrigin = s.grid.origin;
    s.grid.origin.z += float(z[0]) * s.grid.spacing.z;
    return s;
}

}  // namespace rtfact::volume
