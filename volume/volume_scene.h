// VolumeScene<T>: what the volume integrators read, for voxels stored as T (u8, u16,
// f32): the grid in index space, the clip box, the transfer-function lookup table and
// the per-mode brick occupancy. Built once per frame setup; the bricks are referenced.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/util/error.h"
#include "volume/brick_volume.h"
#include "volume/transfer_function.h"
#include "volume/volume_grid.h"

namespace rtfact::volume {

enum class VolumeMode { DVR, Shaded, MIP, Iso };

struct VolumeRenderSettings {
    VolumeMode mode = VolumeMode::DVR;
    float stepVoxels = 0.5f;                 // ray-marching step in voxels (of the smallest spacing)
    float iso = 0.0f;                        // data units (iso mode)
    bool skipping = true;                    // empty-space skipping from the macrocells
    Vec3f clipLo{0, 0, 0}, clipHi{1, 1, 1};  // fractions of each axis
    float earlyTermination = 0.99f;
    // Data-parallel ranks (docs/mpi.md): samples lie on the lattice that starts where the
    // ray enters this world box (the whole volume's clipped box), not the rank's own box,
    // so neighbouring slabs meet without seams.
    bool lattice = false;
    Vec3f latticeLo, latticeHi;
};

template <class T>
struct VolumeScene {
    using Voxel = T;
    static constexpr int kCells = BrickedVolume::kCells, kEdge = BrickedVolume::kEdge;
    const T* voxels = nullptr;  // brick pool
    const int32_t* brickStart = nullptr;
    int dims[3] = {0, 0, 0};
    int32_t nbx = 0, nbxy = 0;  // brick grid strides
    Vec3f origin, invSpacing, spacing;
    Vec3f boxLo, boxHi;  // index space, after clipping
    Vec3f clampHi;       // largest coordinate trilinear sampling may use per axis
    float dt = 0.5f;     // world-space step
    VolumeRenderSettings settings;
    // Transfer function: entry = stored * tfMul + tfAdd.
    TFTable tf;
    float tfMul = 0, tfAdd = 0;
    float isoStored = 0;
    // Bricks are the macrocells: flags (non-zero = may contribute) for DVR/iso, maxima for MIP.
    int cells[3] = {0, 0, 0};
    std::vector<int32_t> cellFlags;
    std::vector<int32_t> brickInfo;  // brick start, sign bit set when the brick is skipped
    std::vector<float> cellMax;
    float invCell = 1.0f / kCells;

    VolumeScene(const BrickedVolume& v, const TFTable& table, const VolumeRenderSettings& s) : settings(s), tf(table) {
        for (int a = 0; a < 3; ++a) {
            if (v.dims[a] < 2) throw Error("", "cannot render a volume with fewer than 2 voxels along an axis");
            dims[a] = v.dims[a];
            cells[a] = v.nb[a];
        }
        voxels = v.data<T>();
        brickStart = v.brickStart.data();
        nbx = v.nb[0];
        nbxy = v.nb[0] * v.nb[1];
        origin = v.origin;
        spacing = v.spacing;
        invSpacing = Vec3f(1.0f / v.spacing.x, 1.0f / v.spacing.y, 1.0f / v.spacing.z);
        for (int a = 0; a < 3; ++a) {
            const float n1 = float(dims[a] - 1);
            boxLo[a] = std::clamp(s.clipLo[a], 0.0f, 1.0f) * n1;
            boxHi[a] = std::clamp(s.clipHi[a], 0.0f, 1.0f) * n1;
            clampHi[a] = std::nextafter(n1, 0.0f);
        }
        if (!(s.stepVoxels > 0) || !std::isfinite(s.stepVoxels)) throw Error("--step", "step must be positive");
        dt = s.stepVoxels * minComponent(v.spacing);
        // TF entry of a stored value: ((stored * scale + offset) - lo) / (hi - lo) * (size - 1)
        const float k = float(tf.size - 1) / (tf.hi - tf.lo);
        tfMul = v.scale * k;
        tfAdd = (v.offset - tf.lo) * k + 0.5f;
        isoStored = (s.iso - v.offset) / v.scale;
        const size_t nc = v.brickCount();
        cellFlags.resize(nc);
        cellMax = v.cellHi;
        for (size_t i = 0; i < nc; ++i) {
            const float lo = v.cellLo[i] * v.scale + v.offset, hi = v.cellHi[i] * v.scale + v.offset;
            bool on = true;
            if (s.mode == VolumeMode::DVR || s.mode == VolumeMode::Shaded)
                on = tf.visible(std::min(lo, hi), std::max(lo, hi));
            else if (s.mode == VolumeMode::Iso)
                on = std::min(lo, hi) <= s.iso && s.iso <= std::max(lo, hi);
            cellFlags[i] = (on || !s.skipping) ? 1 : 0;
        }
        brickInfo.resize(nc);
        for (size_t i = 0; i < nc; ++i) brickInfo[i] = v.brickStart[i] | (cellFlags[i] ? 0 : int32_t(0x80000000u));
        // MIP skips on stored maxima; a decreasing value map (negative scale) or no
        // skipping: never skip.
        if (v.scale < 0 || !s.skipping)
            std::fill(cellMax.begin(), cellMax.end(), std::numeric_limits<float>::infinity());
    }

    AABB bounds() const { return {origin + boxLo * spacing, origin + boxHi * spacing}; }
};

// Calls f(const VolumeScene<T>&) with T the volume's storage type: the one place where
// the run-time storage type becomes a compile-time one.
template <class F>
void withVolumeScene(const BrickedVolume& v, const TFTable& tf, const VolumeRenderSettings& s, F&& f) {
    switch (v.storage) {
        case Storage::U8:
            f(VolumeScene<uint8_t>(v, tf, s));
            break;
        case Storage::U16:
            f(VolumeScene<uint16_t>(v, tf, s));
            break;
        default:
            f(VolumeScene<float>(v, tf, s));
            break;
    }
}

}  // namespace rtfact::volume
