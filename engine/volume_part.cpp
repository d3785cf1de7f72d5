#include "engine/volume_part.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/util/error.h"
#include "engine/scene_data.h"
#include "engine/usage_error.h"
#include "volume/brick_volume.h"
#include "volume/volume_slices.h"

namespace rtfact::engine {

namespace {

template <class T, class F>
void forOwned(const VolumePart& p, F&& f) {
    const T* src = p.grid.data<T>();
    const auto [a, b] = p.ownedSlices();
    const size_t slice = size_t(p.dims[0]) * size_t(p.dims[1]);
    for (size_t i = size_t(a - p.z0) * slice, e = size_t(b - p.z0) * slice; i < e; ++i)
        f(float(src[i]) * p.scale + p.offset);
}

template <class F>
void forOwnedValues(const VolumePart& p, F&& f) {
    switch (p.grid.storage) {
        case volume::Storage::U8:
            forOwned<uint8_t>(p, f);
            break;
        case volume::Storage::U16:
            forOwned<uint16_t>(p, f);
            break;
        default:
            forOwned<float>(p, f);
            break;
    }
}

}  // namespace

std::pair<int, int> slabPlanes(int slices, int part, int parts) {
    const int64_t cells = slices - 1;
    return {int(cells * part / parts), int(cells * (part + 1) / parts)};
}

int ghostSlices(const VolumeSettings& s) {
    if (!s.preintegrated || !(s.step > 0) || !std::isfinite(s.step)) return kGhostSlices;
    // a step is at most s.step slices along z (its length is s.step times the least spacing)
    return std::max(kGhostSlices, int(std::min(std::ceil(s.step), 1e6f)) + 1);
}

VolumePart loadVolumePart(const std::string& file, const OpenOptions& opt, int part, int parts, int ghosts) {
    VolumePart p;
    p.part = part;
    p.parts = parts;
    p.ghosts = ghosts;
    auto pick = [&](const std::array<int, 3>& dims) -> std::array<int, 2> {
        if (dims[2] - 1 < parts)
            throw UsageError("--distribute", "data: " + std::to_string(dims[2]) + " slices cannot be split into " +
                                                 std::to_string(parts) + " slabs (one cell each at least)");
        const auto [a, b] = slabPlanes(dims[2], part, parts);
        return {std::max(0, a - ghosts), std::min(dims[2], b + 1 + ghosts)};
    };
    volume::VolumeLoadOptions vo = opt.volume;
    vo.progress = opt.progress;
    volume::VolumeSlab slab = volume::loadVolumeSlices(file, vo, pick);
    p.dims = slab.fullDims;
    p.origin = slab.fullOrigin;
    p.spacing = slab.grid.spacing;
    std::tie(p.own0, p.own1) = slabPlanes(p.dims[2], part, parts);
    p.z0 = slab.z0;
    p.readWhole = slab.readWhole;
    p.grid = std::move(slab.grid);
    p.loadedBytes = uint64_t(p.grid.voxelCount()) * uint64_t(volume::storageBytes(p.grid.storage));
    p.meta = p.grid.meta;
    p.scale = p.grid.scale;
    p.offset = p.grid.offset;
    p.storage = p.grid.storage;
    return p;
}

std::pair<float, float> VolumePart::ownedRange() const {
    float lo = std::numeric_limits<float>::infinity(), hi = -lo;
    forOwnedValues(*this, [&](float v) {
        if (!std::isfinite(v)) return;
        lo = std::min(lo, v);
        hi = std::max(hi, v);
    });
    return {lo, hi};
}

volume::ValueHistogram VolumePart::ownedHistogram(float lo, float hi) const {
    volume::ValueHistogram h =
        volume::emptyHistogram(lo, hi, storage == volume::Storage::F32 ? 0.0f : std::fabs(scale));
    forOwnedValues(*this, [&](float v) {
        if (!std::isfinite(v)) return;
        ++h.bins[h.binOf(v)];
        ++h.total;
    });
    return h;
}

AABB wholeClippedBox(const VolumePart& p, const VolumeSettings& s) {
    Vec3f lo, hi;
    for (int a = 0; a < 3; ++a) {
        const float n1 = float(p.dims[size_t(a)] - 1);
        lo[a] = std::clamp(s.clipLo[a], 0.0f, 1.0f) * n1;
        hi[a] = std::clamp(s.clipHi[a], 0.0f, 1.0f) * n1;
    }
    return {p.origin + lo * p.spacing, p.origin + hi * p.spacing};
}

Scene partScene(VolumePart& p) {
    auto d = std::make_shared<detail::SceneData>();
    d->kind = SceneKind::Volume;
    d->source = "";
    try {
        d->volume.vol = volume::brickVolume(p.grid, true);
    } catch (const Error& e) {
        throw Error("volume part", e.what());
    }
    p.grid = {};
    d->bounds = d->volume.vol.bounds();
    d->view = {d->bounds, {0.45f, -1.0f, 0.35f}, {0, 0, 1}};
    d->info.add("kind", "volume");
    return Scene{d};
}

std::optional<Settings> partSettings(const VolumePart& p, const Settings& s) {
    Settings r = s;
    VolumeSettings& v = r.volume;
    v.lattice = wholeClippedBox(p, s.volume);
    // z: the whole clip range in planes, narrowed to the slab, as fractions of the part.
    const float n1 = float(p.dims[2] - 1);
    const float lo = std::max(std::clamp(s.volume.clipLo.z, 0.0f, 1.0f) * n1, float(p.own0));
    const float hi = std::min(std::clamp(s.volume.clipHi.z, 0.0f, 1.0f) * n1, float(p.own1));
    if (!(lo < hi)) return std::nullopt;
    const int loaded = std::min(p.dims[2], p.own1 + 1 + p.ghosts) - p.z0;
    v.clipLo.z = (lo - float(p.z0)) / float(loaded - 1);
    v.clipHi.z = (hi - float(p.z0)) / float(loaded - 1);
    return r;
}

}  // namespace rtfact::engine
