// VolumeScene<T>: what the volume integrators read, for voxels stored as T (u8, u16,
// f32): the grid in index space, the clip box, the transfer-function lookup table and
// the per-mode brick occupancy. Built once per frame setup; the bricks are referenced.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

#include "core/util/error.h"
#include "core/util/memory_budget.h"
#include "volume/brick_volume.h"
#include "volume/gradient_bricks.h"
#include "volume/half_float.h"
#include "volume/tf_range_extrema.h"
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
    // Pre-integrated transfer function (DVR, shaded): each sample composites the segment
    // from the previous sample, its value taken as linear between the two (VolumeScene::
    // tfIntegral), instead of the TF at the sample alone.
    bool preintegrated = false;
    // Opacity-adaptive steps (DVR, shaded): a brick whose transfer-function opacity stays
    // low is marched with 2 or 4 times the step, on the same sample lattice, as long as one
    // longer step's opacity stays <= adaptiveOpacity. maxStepMultiple 1: the plain march.
    int maxStepMultiple = 4;
    float adaptiveOpacity = 0.01f;
    // Data-parallel ranks (docs/mpi.md): samples lie on the lattice that starts where the
    // ray enters this world box (the whole volume's clipped box), not the rank's own box,
    // so neighbouring slabs meet without seams.
    bool lattice = false;
    Vec3f latticeLo, latticeHi;
};

// Where the march reads voxels from. Chosen once per packet march (VolumeIntegrator::
// eval), a closed list of template arguments, so the sampling code has no per-sample test.
enum class VoxelLayout {
    Rows,     // the brick pool: x-rows of kEdge samples
    YPairs,   // BrickedVolume::pairs (u8/u16): entries of two y-neighbours
    YZQuads,  // BrickedVolume::quads (u8): entries of a y-z square of four samples
};

template <class T>
struct VolumeScene {
    using Voxel = T;
    static constexpr int kCells = BrickedVolume::kCells, kEdge = BrickedVolume::kEdge, kBrick = BrickedVolume::kBrick;
    // Entries per brick, y row and z slice of layout L (an entry: a sample, a y-pair or a
    // y-z quad).
    template <VoxelLayout L>
    static constexpr int kBrickStride = L == VoxelLayout::YPairs    ? BrickedVolume::kPairEntries
                                        : L == VoxelLayout::YZQuads ? BrickedVolume::kQuadEntries
                                                                    : kBrick;
    template <VoxelLayout L>
    static constexpr int kRowStride = L == VoxelLayout::YPairs    ? BrickedVolume::kPairRow
                                      : L == VoxelLayout::YZQuads ? BrickedVolume::kQuadRow
                                                                  : kEdge;
    template <VoxelLayout L>
    static constexpr int kSliceStride = L == VoxelLayout::YPairs    ? BrickedVolume::kPairSlice
                                        : L == VoxelLayout::YZQuads ? BrickedVolume::kQuadSlice
                                                                    : kEdge* kEdge;
    const T* voxels = nullptr;  // brick pool
    const int32_t* brickStart = nullptr;
    // The march's copy (BrickedVolume::pairs or quads; null when the volume has neither),
    // its layout and per brick its first entry.
    const T* copyVoxels = nullptr;
    VoxelLayout copyLayout = VoxelLayout::Rows;
    std::vector<int32_t> copyStart;
    template <VoxelLayout L>
    const int32_t* entryStart() const {
        return L == VoxelLayout::Rows ? brickStart : copyStart.data();
    }
    // Bytes of one entry of layout L, and where the entries start.
    template <VoxelLayout L>
    static constexpr size_t kEntryBytes = L == VoxelLayout::YPairs    ? 2 * sizeof(T)
                                          : L == VoxelLayout::YZQuads ? 4 * sizeof(T)
                                                                      : sizeof(T);
    template <VoxelLayout L>
    const uint8_t* entryBase() const {
        return reinterpret_cast<const uint8_t*>(L == VoxelLayout::Rows ? voxels : copyVoxels);
    }
    int dims[3] = {0, 0, 0};
    int32_t nbx = 0, nbxy = 0;  // brick grid strides
    Vec3f origin, invSpacing, spacing;
    Vec3f boxLo, boxHi;  // index space, after clipping
    // The box whose lattice the samples lie on (index space): boxLo/boxHi, on a data-parallel
    // rank (settings.lattice) the whole volume's. A pre-integrated ray's first look-back sample,
    // a step before the box, is taken at its face.
    Vec3f latticeBoxLo, latticeBoxHi;
    Vec3f clampHi;    // largest coordinate trilinear sampling may use per axis
    float dt = 0.5f;  // world-space step
    VolumeRenderSettings settings;
    // Transfer function: entry = stored * tfMul + tfAdd.
    TFTable tf;
    float tfMul = 0, tfAdd = 0;
    // Entries outside [tfVisibleLo, tfVisibleHi) have zero opacity (in every step table).
    float tfVisibleLo = 0, tfVisibleHi = 0;
    float isoStored = 0;
    // Macrocells: for DVR, shaded and iso the sub-bricks (the bricks' octants, 4^3 cells:
    // finer than bricks, so fewer invisible samples are marched where a brick is only partly
    // visible) with flags (non-zero = may contribute); for MIP the bricks' maxima.
    static constexpr int kSub = BrickedVolume::kSubCells;
    int cells[3] = {0, 0, 0};  // bricks per axis
    int subs[3] = {0, 0, 0};   // sub-bricks per axis (2 cells[a])
    std::vector<int32_t> subFlags;
    // Per sub-brick, one load for the march. Skipped (sign bit set): the low bits hold the
    // Chebyshev distance in sub-bricks to the nearest one that is not skipped (>= 1), so a
    // ray jumps the whole empty cube around it. Otherwise: its brick's pool brick (start /
    // kBrick) in bits 0-27, log2 of the step multiple in bits 28-29 and, in bit 30, whether
    // that multiple is the sub-brick's own rather than its brick's (stepBits).
    std::vector<int32_t> subInfo;
    static constexpr int32_t kSkipBit = int32_t(0x80000000u), kPoolMask = (1 << 28) - 1, kMaxDistance = 16;
    static constexpr int32_t kSubScopeBit = 1 << 30;
    // Whether the march takes long steps (opacity-adaptive steps, DVR and shaded): only when
    // at least kMinLongStepShare of the sub-bricks the TF shows allow them. Below that, the
    // march's per-sample check of the long step's room costs about what the samples it saves
    // do (Zen 4, translucent ramp at step 1: the head CT (10% of them) and the bonsai (11%)
    // 2-4% faster without, the tooth (25%) the same speed at 3.5 dB more PSNR; the phantom's
    // faint TF (68%) a third faster with them). Below it the step bits are all 0.
    static constexpr double kMinLongStepShare = 0.3;
    bool longSteps = false;
    // Transfer-function tables for 1, 2 and 4 steps (tf.size entries each): r, g, b and
    // the opacity 1 - (1 - a)^m of table m as four halves per entry (half_float.h), so that
    // one 64-bit gather fetches an entry.
    std::vector<uint64_t> rgbaSteps;
    // Pre-integrated march (settings.preintegrated): per entry e = 0 .. tf.size the sums over
    // the entries before e of the extinction of one step, tau = -ln(1 - a), and of tau r,
    // tau g, tau b, as four floats. A segment whose ends fall on entries i <= j gets the
    // mean extinction (T[j + 1] - T[i]) / (j + 1 - i) and the extinction-weighted mean colour
    // (K[j + 1] - K[i]) / (T[j + 1] - T[i]): for i = j exactly the plain march's entry (the
    // segment's value taken as linear: Engel et al. 2001, without self-attenuation inside
    // the segment). Empty otherwise.
    std::vector<float> tfIntegral;
    static constexpr float kMaxExtinction = 16.0f;  // per step: an opacity of 1 - 1e-7
    // MIP: per brick its stored maximum (float bits; infinity: never skipped) and its first
    // entry in the march's layout (copyStart or brickStart), side by side: one 64-bit fetch a
    // lane gives the skip test and the sample's brick. Empty in the other modes.
    std::vector<int32_t> mipBricks;
    // The march prefetches the bricks ahead of its rays where the voxels it reads (the pool
    // in the row layout, else the march's copy) outgrow 8 MB and it waits on memory at
    // every new brick. Measured on Zen 5, 1 thread: the bonsai's 14.5 MB of u8 y-pairs 3%
    // (AVX2) and 6% (AVX-512) faster, the 256^3 u16 phantom's pool 6% and 14%; the tooth's
    // 7.2 MB of quads and the head CT's 2 MB of pairs 6-9% slower with the prefetches.
    static constexpr size_t kPrefetchBytes = size_t(8) << 20;
    bool prefetchBricks = false;
    // Shaded: the voxels' central differences, per brick the TF shows (empty in the other
    // modes, and beyond kMaxGradientBytes or a quarter of the available memory: the march
    // then takes six trilinear samples a gradient). Measured (AVX-512, 1 thread): faster
    // with 56 MB of them (256^3 u16 phantom, 368 -> 314 ms), slower with 412 MB (512^3,
    // 548 -> 714 ms: six samples reread voxels the cache holds, the bricks miss).
    // The bricks depend on the TF only through which bricks are shown: `reuse` (bricks an
    // earlier scene of the same volume built) is taken when it holds every brick shown now,
    // so a TF edit in the viewer does not rebuild them.
    static constexpr uint64_t kMaxGradientBytes = uint64_t(128) << 20;
    std::shared_ptr<const GradientBricks> gradients;  // null: none

    VolumeScene(const BrickedVolume& v, const TFTable& table, const VolumeRenderSettings& s,
                std::shared_ptr<const GradientBricks> reuse = {})
        : settings(s), tf(table) {
        for (int a = 0; a < 3; ++a) {
            if (v.dims[a] < 2) throw Error("", "cannot render a volume with fewer than 2 voxels along an axis");
            dims[a] = v.dims[a];
            cells[a] = v.nb[a];
            subs[a] = 2 * v.nb[a];
        }
        voxels = v.data<T>();
        brickStart = v.brickStart.data();
        // the voxels the march reads: the copy where there is one (VolumeIntegrator::eval)
        size_t marchBytes = v.pool.size();
        if (sizeof(T) < 4 && !(v.pairs.empty() && v.quads.empty())) {
            const bool quads = !v.quads.empty();
            const std::vector<uint8_t>& copy = quads ? v.quads : v.pairs;
            copyVoxels = reinterpret_cast<const T*>(copy.data());
            copyLayout = quads ? VoxelLayout::YZQuads : VoxelLayout::YPairs;
            marchBytes = copy.size();
            const int entries = quads ? BrickedVolume::kQuadEntries : BrickedVolume::kPairEntries;
            copyStart.resize(v.brickStart.size());
            for (size_t i = 0; i < copyStart.size(); ++i) copyStart[i] = v.brickStart[i] / kBrick * entries;
        }
        prefetchBricks = marchBytes > kPrefetchBytes;
        nbx = v.nb[0];
        nbxy = v.nb[0] * v.nb[1];
        origin = v.origin;
        spacing = v.spacing;
        invSpacing = Vec3f(1.0f / v.spacing.x, 1.0f / v.spacing.y, 1.0f / v.spacing.z);
        for (int a = 0; a < 3; ++a) {
            const float n1 = float(dims[a] - 1);
            boxLo[a] = std::clamp(s.clipLo[a], 0.0f, 1.0f) * n1;
            boxHi[a] = std::clamp(s.clipHi[a], 0.0f, 1.0f) * n1;
            latticeBoxLo[a] = s.lattice ? (s.latticeLo[a] - origin[a]) * invSpacing[a] : boxLo[a];
            latticeBoxHi[a] = s.lattice ? (s.latticeHi[a] - origin[a]) * invSpacing[a] : boxHi[a];
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
        const size_t ns = nc * 8;
        subFlags.resize(ns);
        std::vector<uint8_t> visible(ns);
        for (size_t i = 0; i < ns; ++i) {
            const auto [b, o] = brickOctant(i);
            bool on = true;
            if (s.mode == VolumeMode::DVR || s.mode == VolumeMode::Shaded) {
                const float lo = v.subLo[b * 8 + o] * v.scale + v.offset, hi = v.subHi[b * 8 + o] * v.scale + v.offset;
                on = tf.visible(std::min(lo, hi), std::max(lo, hi));
            } else if (s.mode == VolumeMode::Iso) {
                // Whole bricks: a ray may pass a sub-brick holding the crossing between two
                // samples, and skipping the finer cells beyond widens the bracket over the
                // surface's other side (the crossing is found from one sample on each side).
                const float lo = v.cellLo[b] * v.scale + v.offset, hi = v.cellHi[b] * v.scale + v.offset;
                on = std::min(lo, hi) <= s.iso && s.iso <= std::max(lo, hi);
            }
            visible[i] = on ? 1 : 0;
            subFlags[i] = (on || !s.skipping) ? 1 : 0;
        }
        if (s.mode == VolumeMode::Shaded) {
            std::vector<uint8_t> shown(nc, 0);
            for (size_t i = 0; i < ns; ++i)
                if (visible[i]) shown[brickOctant(i).first] = 1;
            // Pre-integrated segments may end past the bricks they cross visible values in
            // (at most a step away), and are shaded there: those bricks' neighbours too.
            if (s.preintegrated) shown = dilated(shown, int(std::ceil(s.stepVoxels / float(kCells))));
            bool covered = reuse && reuse->start.size() == nc;
            for (size_t b = 0; b < nc && covered; ++b) covered = !shown[b] || reuse->start[b] != 0;
            if (covered) {
                gradients = std::move(reuse);
            } else {
                GradientBricks g =
                    GradientBricks::build(v, shown, std::min(kMaxGradientBytes, availableMemoryBytes() / 4));
                if (!g.empty()) gradients = std::make_shared<const GradientBricks>(std::move(g));
            }
        }
        subInfo.resize(ns);
        std::vector<int32_t> steps = stepBits(v, visible);
        size_t shown = 0, stepping = 0;
        for (size_t i = 0; i < ns; ++i) {
            shown += visible[i];
            stepping += steps[i] != 0;
        }
        longSteps = stepping > 0 && double(stepping) >= kMinLongStepShare * double(shown);
        if (!longSteps) std::fill(steps.begin(), steps.end(), 0);
        const std::vector<int32_t> dist = emptyDistance();
        for (size_t i = 0; i < ns; ++i) {
            const size_t b = brickOctant(i).first;
            if (v.brickStart[b] / kBrick > kPoolMask) throw Error("", "volume too large for the brick table");
            subInfo[i] = subFlags[i] ? (v.brickStart[b] / kBrick) | steps[i] : (kSkipBit | dist[i]);
        }
        const size_t n = size_t(tf.size);
        for (size_t e = 0; e < n; ++e)
            if (tf.a[e] > 0.0f) {
                if (tfVisibleHi == 0) tfVisibleLo = float(e);
                tfVisibleHi = float(e + 1);
            }
        rgbaSteps.resize(n * 3);
        for (int m = 0; m < 3; ++m)
            for (size_t e = 0; e < n; ++e)
                rgbaSteps[size_t(m) * n + e] = packRgbaHalf(
                    tf.r[e], tf.g[e], tf.b[e], 1.0f - std::pow(1.0f - std::min(tf.a[e], 1.0f), float(1 << m)));
        if (s.preintegrated && (s.mode == VolumeMode::DVR || s.mode == VolumeMode::Shaded)) {
            // summed in double, stored rounded once
            tfIntegral.resize(4 * (n + 1));
            double sum[4] = {0, 0, 0, 0};
            for (size_t e = 0;; ++e) {
                for (int c = 0; c < 4; ++c) tfIntegral[4 * e + size_t(c)] = float(sum[c]);
                if (e == n) break;
                const double a = std::clamp(double(tf.a[e]), 0.0, 1.0);
                const double tau = std::min(-std::log1p(-a), double(kMaxExtinction));
                sum[0] += tau;
                sum[1] += tau * tf.r[e];
                sum[2] += tau * tf.g[e];
                sum[3] += tau * tf.b[e];
            }
        }
        // MIP skips on stored maxima; a decreasing value map (negative scale) or no
        // skipping: never skip.
        if (s.mode == VolumeMode::MIP) {
            const bool never = v.scale < 0 || !s.skipping;
            const int32_t* first = copyVoxels ? copyStart.data() : brickStart;
            mipBricks.resize(2 * nc);
            for (size_t b = 0; b < nc; ++b) {
                const float m = never ? std::numeric_limits<float>::infinity() : v.cellHi[b];
                std::memcpy(&mipBricks[2 * b], &m, 4);
                mipBricks[2 * b + 1] = first[b];
            }
        }
    }

    AABB bounds() const { return {origin + boxLo * spacing, origin + boxHi * spacing}; }

   private:
    // Brick flags `on` grown by r bricks (Chebyshev distance), a pass per axis.
    std::vector<uint8_t> dilated(std::vector<uint8_t> on, int r) const {
        const int n[3] = {cells[0], cells[1], cells[2]};
        const size_t stride[3] = {1, size_t(n[0]), size_t(n[0]) * size_t(n[1])};
        for (int a = 0; a < 3; ++a) {
            std::vector<uint8_t> out(on.size(), 0);
            for (size_t i = 0; i < on.size(); ++i) {
                if (!on[i]) continue;
                const int x = int(i / stride[a] % size_t(n[a]));
                for (int d = std::max(0, x - r); d <= std::min(n[a] - 1, x + r); ++d)
                    out[i + (size_t(d) - size_t(x)) * stride[a]] = 1;
            }
            on = std::move(out);
        }
        return on;
    }
    // Sub-brick i (x fastest over subs) as (brick, octant).
    std::pair<size_t, size_t> brickOctant(size_t i) const {
        const size_t sx = i % size_t(subs[0]), sy = i / size_t(subs[0]) % size_t(subs[1]),
                     sz = i / (size_t(subs[0]) * size_t(subs[1]));
        const size_t b = ((sz / 2) * size_t(cells[1]) + sy / 2) * size_t(cells[0]) + sx / 2;
        return {b, (sx & 1) + 2 * (sy & 1) + 4 * (sz & 1)};
    }
    // Per sub-brick, the step bits of subInfo: log2 of the step multiple of its brick or,
    // where the brick's value range allows none, of the sub-brick alone (with kSubScopeBit:
    // long steps then end at the sub-brick's exit). 0 where the TF hides the sub-brick, so
    // that a march without skipping reaches the same sample positions as one that skips.
    std::vector<int32_t> stepBits(const BrickedVolume& v, const std::vector<uint8_t>& visible) const {
        const size_t ns = visible.size();
        std::vector<int32_t> out(ns, 0);
        const bool dvr = settings.mode == VolumeMode::DVR || settings.mode == VolumeMode::Shaded;
        if (!dvr || settings.maxStepMultiple < 2) return out;
        const TFRangeExtrema extrema(tf);
        // each brick's multiple once (-1: not computed yet); ranges in data units
        std::vector<int8_t> brickM(v.brickCount(), -1);
        auto value = [&](float stored) { return stored * v.scale + v.offset; };
        for (size_t i = 0; i < ns; ++i) {
            if (!visible[i]) continue;
            const auto [b, o] = brickOctant(i);
            if (brickM[b] < 0) brickM[b] = int8_t(stepMultiple(extrema, value(v.cellLo[b]), value(v.cellHi[b])));
            if (brickM[b] > 0) {
                out[i] = int32_t(brickM[b]) << 28;
            } else if (const int m = stepMultiple(extrema, value(v.subLo[b * 8 + o]), value(v.subHi[b * 8 + o]))) {
                out[i] = (m << 28) | kSubScopeBit;
            }
        }
        return out;
    }
    // log2 of the step multiple for values in [lo, hi]: the largest m <= maxStepMultiple
    // for which one step of M = 2^m times the base step differs from M plain steps by at
    // most eps = adaptiveOpacity, whatever samples the range gives. With the TF's
    // opacities amin..amax over that range, M plain steps reach an opacity between
    // 1 - (1 - amin)^M and 1 - (1 - amax)^M, as does the one long step, so the opacity
    // error is at most their difference; the colour error is at most the colour range
    // times the opacity 1 - (1 - amax)^M. Faint ranges (the earlier rule: every entry's
    // M-step opacity <= eps) pass both, and so do homogeneous ones at any opacity, where
    // the long step is exact. Ranges the TF leaves invisible keep m = 0.
    int stepMultiple(const TFRangeExtrema& extrema, float lo, float hi) const {
        if (!tf.visible(std::min(lo, hi), std::max(lo, hi))) return 0;
        int i0 = tf.index(lo), i1 = tf.index(hi);
        if (i0 > i1) std::swap(i0, i1);
        const TFRangeExtrema::Extrema e = extrema.range(i0, i1);
        const float amin = std::min(e.lo[3], 1.0f), amax = std::min(e.hi[3], 1.0f);
        const float dc = std::max({e.hi[0] - e.lo[0], e.hi[1] - e.lo[1], e.hi[2] - e.lo[2]});
        const float eps = settings.adaptiveOpacity;
        for (int m = 2; m >= 1; --m) {
            const float M = float(1 << m);
            if ((1 << m) > settings.maxStepMultiple) continue;
            const float tmin = std::pow(1.0f - amin, M), tmax = std::pow(1.0f - amax, M);
            if (tmin - tmax <= eps && dc * (1.0f - tmax) <= eps) return m;
        }
        return 0;
    }
    // Chebyshev distance (in sub-bricks, capped at kMaxDistance) from each skipped sub-brick
    // to the nearest one that is not: all sub-bricks closer than that are skipped too. Grows the
    // non-skipped set one sub-brick per pass (separable 3x3x3 dilation).
    std::vector<int32_t> emptyDistance() const {
        // The reached set as bits, 64 sub-bricks of an x row a word: one pass is a shift-or
        // along x and an or of neighbouring rows along y and z (a 512^3 volume has 2M
        // sub-bricks, too many for a byte a cell and pass when the TF changes interactively).
        const int n[3] = {subs[0], subs[1], subs[2]};
        const size_t words = (size_t(n[0]) + 63) / 64, rows = size_t(n[1]) * size_t(n[2]);
        const uint64_t lastMask = n[0] % 64 == 0 ? ~uint64_t(0) : (uint64_t(1) << (n[0] % 64)) - 1;
        std::vector<int32_t> dist(size_t(n[0]) * rows, kMaxDistance);
        std::vector<uint64_t> reached(words * rows, 0);
        size_t left = 0;
        for (size_t r = 0; r < rows; ++r)
            for (int x = 0; x < n[0]; ++x) {
                const size_t i = r * size_t(n[0]) + size_t(x);
                if (subFlags[i]) {
                    reached[r * words + size_t(x) / 64] |= uint64_t(1) << (x % 64);
                    dist[i] = 0;
                } else {
                    ++left;
                }
            }
        // One pass ors each row into its neighbours along y (a = 1) or z (a = 2).
        auto orRows = [&](const std::vector<uint64_t>& src, std::vector<uint64_t>& dst, int a) {
            const size_t step = a == 1 ? words : words * size_t(n[1]);
            for (size_t r = 0; r < rows; ++r) {
                const int c = a == 1 ? int(r % size_t(n[1])) : int(r / size_t(n[1]));
                for (size_t k = 0; k < words; ++k) {
                    const size_t i = r * words + k;
                    uint64_t v = src[i];
                    if (c > 0) v |= src[i - step];
                    if (c + 1 < n[a]) v |= src[i + step];
                    dst[i] = v;
                }
            }
        };
        std::vector<uint64_t> alongX(reached.size()), alongY(reached.size()), next(reached.size());
        for (int d = 1; d < kMaxDistance && left > 0; ++d) {
            // x: each bit ors in its two neighbours in the row
            for (size_t r = 0; r < rows; ++r) {
                const uint64_t* w = reached.data() + r * words;
                for (size_t k = 0; k < words; ++k) {
                    uint64_t v = w[k] | (w[k] << 1) | (w[k] >> 1);
                    if (k > 0) v |= w[k - 1] >> 63;
                    if (k + 1 < words) v |= w[k + 1] << 63;
                    alongX[r * words + k] = k + 1 == words ? v & lastMask : v;
                }
            }
            orRows(alongX, alongY, 1);
            orRows(alongY, next, 2);
            for (size_t r = 0; r < rows; ++r)
                for (size_t k = 0; k < words; ++k)
                    for (uint64_t fresh = next[r * words + k] & ~reached[r * words + k]; fresh; fresh &= fresh - 1) {
                        dist[r * size_t(n[0]) + k * 64 + size_t(__builtin_ctzll(fresh))] = d;
                        --left;
                    }
            reached.swap(next);
        }
        return dist;
    }
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
