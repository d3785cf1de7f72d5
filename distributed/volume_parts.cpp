#include "distributed/volume_parts.h"

#include <algorithm>
#include <utility>

#include "volume/default_transfer_function.h"
#include "volume/transfer_function.h"

namespace rtfact::distributed {

void agreeOnTransferFunction(MPI_Comm comm, const engine::VolumePart& part, engine::Settings& s) {
    auto [lo, hi] = part.ownedRange();
    float range[2] = {lo, -hi};
    MPI_Allreduce(MPI_IN_PLACE, range, 2, MPI_FLOAT, MPI_MIN, comm);
    lo = range[0];
    hi = -range[1];
    engine::VolumeSettings& v = s.volume;
    volume::TransferFunction tf;
    std::pair<float, float> window;
    if (v.tf) {
        tf = *v.tf;
        window = volume::resolveWindow(tf, lo, hi, v.window, v.level);
    } else {
        volume::ValueHistogram h = part.ownedHistogram(lo, hi);
        MPI_Allreduce(MPI_IN_PLACE, h.bins.data(), int(h.bins.size()), MPI_UINT64_T, MPI_SUM, comm);
        MPI_Allreduce(MPI_IN_PLACE, &h.total, 1, MPI_UINT64_T, MPI_SUM, comm);
        const int dims[3] = {part.dims[0], part.dims[1], part.dims[2]};
        const volume::DefaultTransferFunction dt = volume::chooseDefaultTransferFunction(
            part.meta, h, v.mode == "shaded" ? volume::VolumeMode::Shaded : volume::VolumeMode::DVR,
            volume::typicalDepthVoxels(dims, part.spacing));
        tf = dt.tf;
        window = v.window || v.level ? volume::resolveWindow(tf, lo, hi, v.window, v.level) : dt.window;
    }
    v.tf = tf;
    v.window = window.second - window.first;
    v.level = 0.5f * (window.first + window.second);
}

std::vector<int> slabVisibilityOrder(const engine::VolumePart& part, int ranks, Vec3f eye) {
    std::vector<std::pair<float, int>> dist;
    for (int r = 0; r < ranks; ++r) {
        const auto [a, b] = engine::slabPlanes(part.dims[2], r, ranks);
        const float z0 = part.origin.z + float(a) * part.spacing.z, z1 = part.origin.z + float(b) * part.spacing.z;
        dist.push_back({std::max({z0 - eye.z, eye.z - z1, 0.0f}), r});
    }
    std::sort(dist.begin(), dist.end());
    std::vector<int> order;
    for (const auto& d : dist) order.push_back(d.second);
    return order;
}

}  // namespace rtfact::distributed
