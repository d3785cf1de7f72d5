// VolumeScene<T>: what the volume integrators read, for voxels stored as T (u8, u16,
// f32): the grid in index space, the clip box, the transfer-function lookup table and
// the per-mode macrocell occupancy. Built once per frame setup; the grid is referenced.
#pragma once
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/util/error.h"
#include "volume/macrocell_grid.h"
#include "volume/transfer_function.h"
#include "volume/volume_grid.h"

namespace rtfact::volume {

enum class VolumeMode { DVR, Shaded, MIP, Iso };

struct VolumeRenderSettings {
    VolumeMode mode = VolumeMode::DVR;
    float stepVoxels = 0.5f;  // ray-marching step in voxels (of the smallest spacing)
    float iso = 0.0f;         // data units (iso mode)
    bool skipping = true;     // empty-space skipping from the macrocells
    Vec3f clipLo{0, 0, 0}, clipHi{1, 1, 1};  // fractions of each axis
    float earlyTermination = 0.99f;
};

template <class T>
struct VolumeScene {
    using Voxel = T;
    const T* voxels = nullptr;
    int dims[3] = {0, 0, 0};
    int32_t strideY = 0, strideZ = 0;
    Vec3f origin, invSpacing, spacing;
    Vec3f boxLo, boxHi;   // index space, after clipping
    Vec3f clampHi;        // largest coordinate trilinear sampling may use per axis
    float dt = 0.5f;      // world-space step
    VolumeRenderSettings settings;
    // Transfer function: entry = stored * tfMul + tfAdd.
    TFTable tf;
    float tfMul = 0, tfAdd = 0;
    float isoStored = 0;
    // Macrocells: flags (non-zero = may contribute) for DVR/iso, maxima for MIP.
    int cells[3] = {0, 0, 0};
    std::vector<int32_t> cellFlags;
    std::vector<float> cellMax;
    float invCell = 1.0f / MacrocellGrid::kCell;

    VolumeScene(const VolumeGrid& g, const TFTable& table, const MacrocellGrid& mc, const VolumeRenderSettings& s)
        : settings(s), tf(table) {
        for (int a = 0; a < 3; ++a) {
            if (g.dims[a] < 2) throw Error("", "cannot render a volume with fewer than 2 voxels along an axis");
            dims[a] = g.dims[a];
        }
        voxels = g.data<T>();
        strideY = dims[0];
        strideZ = dims[0] * dims[1];
        origin = g.origin;
        spacing = g.spacing;
        invSpacing = Vec3f(1.0f / g.spacing.x, 1.0f / g.spacing.y, 1.0f / g.spacing.z);
        for (int a = 0; a < 3; ++a) {
            const float n1 = float(dims[a] - 1);
            boxLo[a] = std::clamp(s.clipLo[a], 0.0f, 1.0f) * n1;
            boxHi[a] = std::clamp(s.clipHi[a], 0.0f, 1.0f) * n1;
            clampHi[a] = std::nextafter(n1, 0.0f);
        }
        if (!(s.stepVoxels > 0) || !std::isfinite(s.stepVoxels)) throw Error("--step", "step must be positive");
        dt = s.stepVoxels * minComponent(g.spacing);
        // TF entry of a stored value: ((stored * scale + offset) - lo) / (hi - lo) * (size - 1)
        const float k = float(tf.size - 1) / (tf.hi - tf.lo);
        tfMul = g.scale * k;
        tfAdd = (g.offset - tf.lo) * k + 0.5f;
        isoStored = (s.iso - g.offset) / g.scale;
        for (int a = 0; a < 3; ++a) cells[a] = mc.n[a];
        cellFlags.resize(mc.count());
        cellMax = mc.hi;
        for (size_t i = 0; i < mc.count(); ++i) {
            const float lo = mc.lo[i] * g.scale + g.offset, hi = mc.hi[i] * g.scale + g.offset;
            bool on = true;
            if (s.mode == VolumeMode::DVR || s.mode == VolumeMode::Shaded) on = tf.visible(std::min(lo, hi), std::max(lo, hi));
            else if (s.mode == VolumeMode::Iso) on = std::min(lo, hi) <= s.iso && s.iso <= std::max(lo, hi);
            cellFlags[i] = (on || !s.skipping) ? 1 : 0;
        }
        if (g.scale < 0) {
            // MIP on a decreasing map: skip nothing (maxima of stored values mean minima).
            std::fill(cellMax.begin(), cellMax.end(), std::numeric_limits<float>::infinity());
        }
        if (!s.skipping) std::fill(cellMax.begin(), cellMax.end(), std::numeric_limits<float>::infinity());
    }

    AABB bounds() const {
        return {origin + boxLo * spacing, origin + boxHi * spacing};
    }
};

}  // namespace rtfact::volume

namespace rtfact::volume {

// Calls f(const VolumeScene<T>&) with T the grid's storage type: the one place where the
// run-time storage type becomes a compile-time one.
template <class F>
void withVolumeScene(const VolumeGrid& g, const TFTable& tf, const MacrocellGrid& mc, const VolumeRenderSettings& s, F&& f) {
    switch (g.storage) {
        case Storage::U8: f(VolumeScene<uint8_t>(g, tf, mc, s)); break;
        case Storage::U16: f(VolumeScene<uint16_t>(g, tf, mc, s)); break;
        default: f(VolumeScene<float>(g, tf, mc, s)); break;
    }
}

}  // namespace rtfact::volume
