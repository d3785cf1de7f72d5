// VolumeIntegrator: direct volume rendering (front-to-back, optionally gradient shaded),
// maximum-intensity projection and isosurfaces for a VolumeScene<T>, modelling the
// core's Integrator concept. Each native chunk of a packet marches together: samples
// sit at t = tEnter + (k + 1/2) dt, so lanes that jump over empty macrocells land on the
// same sample positions they would have reached by stepping (skipping changes nothing),
// and lanes drop out when they leave the box or become opaque.
#pragma once
#include <cstring>
#include <type_traits>
#include <utility>

#include "core/concepts/integrator.h"
#include "core/render/render_counters.h"
#include "core/simd/chunk_group.h"
#include "core/util/prefetch.h"
#include "volume/exp_negative.h"
#include "volume/volume_scene.h"
#include "volume/voxel_gather.h"

namespace rtfact::volume {

struct VolumeIntegrator {
    Vec3f background{0.0f, 0.0f, 0.0f};

    template <int N, class Scene>
    Radiance<N> eval(const Scene& s, RayPacket<N>& rays, const Mask<N>& active, const PixelSample<N>&) const {
        // The voxel layout, once per packet: the march's copy when the volume has one.
        if constexpr (sizeof(typename Scene::Voxel) < 4) {
            if constexpr (sizeof(typename Scene::Voxel) == 1)
                if (s.copyLayout == VoxelLayout::YZQuads) return evalIn<VoxelLayout::YZQuads, N>(s, rays, active);
            if (s.copyLayout == VoxelLayout::YPairs) return evalIn<VoxelLayout::YPairs, N>(s, rays, active);
        }
        return evalIn<VoxelLayout::Rows, N>(s, rays, active);
    }

    template <VoxelLayout L, int N, class Scene>
    Radiance<N> evalIn(const Scene& s, RayPacket<N>& rays, const Mask<N>& active) const {
        tlsCounters.rays += uint64_t(popcount(active));
        Radiance<N> r;
        uint64_t samples = 0;
        float skipped = 0;
        // Four native chunks (two when the packet has fewer) march together: their gather
        // chains (brick, voxels, TF) are independent, so each hides the others' latency. Eight
        // AVX2 chunks spill too much. Pairs where more lanes cost more than they hide (measured):
        // isosurfaces (a crossing in any lane bisects all), and on AVX2 MIP (a short step: the
        // spills weigh more).
        constexpr int W = Packet<N>::W, C = Packet<N>::C, G = C % 4 == 0 ? 4 : C % 2 == 0 ? 2 : 1;
        constexpr int G2 = G == 4 ? 2 : G;
        // The mode is fixed at compile time: the other modes' state and branches drop out of
        // the loop, whose values do not fit the registers (fewer of them, fewer spills).
        auto marchGroups = [&]<int GG, VolumeMode M, bool Pre>() {
            for (int k = 0; k < C; k += GG) {
                Vec3<GG * W> col;
                Packet<GG * W> alpha, depth;
                march<GG * W, L, M, Pre>(s, chunkGroup<GG * W>(rays.org, k), chunkGroup<GG * W>(rays.dir, k),
                                         chunkGroup<GG * W>(rays.tMin, k), chunkGroup<GG * W>(rays.tMax, k),
                                         chunkGroup<GG * W>(active, k), col, alpha, depth, samples, skipped);
                for (int j = 0; j < GG; ++j) {
                    r.color.setChunk(k + j, col.chunk(j));
                    r.alpha.chunk(k + j) = alpha.chunk(j);
                    r.depth.chunk(k + j) = depth.chunk(j);
                }
            }
        };
        auto marchMode = [&]<VolumeMode M>() {
            if constexpr (M == VolumeMode::Iso || (W == 8 && M == VolumeMode::MIP)) {
                marchGroups.template operator()<G2, M, false>();
            } else if constexpr (M == VolumeMode::MIP) {
                marchGroups.template operator()<G, M, false>();
            } else if (s.tfIntegral.empty()) {
                marchGroups.template operator()<G, M, false>();
            } else {
                marchGroups.template operator()<G, M, true>();
            }
        };
        // the settings' mode as a template argument (VolumeMode's values are 0 .. 3)
        static_assert(int(VolumeMode::Iso) == 3);
        [&]<int... M>(std::integer_sequence<int, M...>) {
            ((int(s.settings.mode) == M && (marchMode.template operator()<VolumeMode(M)>(), true)) || ...);
        }
        (std::make_integer_sequence<int, 4>{});
        tlsCounters.volumeSamples += samples;
        tlsCounters.volumeSkipped += uint64_t(skipped);
        return r;
    }

    // The brick grid index of brick coordinates b.
    template <int W, class Scene>
    static RTFACT_INLINE Packet<W, int32_t> brickId(const Scene& s, const Packet<W, int32_t> (&b)[3]) {
        using I = Packet<W, int32_t>;
        return b[0] + b[1] * I(s.nbx) + b[2] * I(s.nbxy);
    }
    // A cell's first sample inside its brick (8 cells a brick edge), for rows of R and
    // slices of S entries.
    template <int W, int R, int S>
    static RTFACT_INLINE Packet<W, int32_t> cellInBrick(const Packet<W, int32_t> (&cell)[3]) {
        using I = Packet<W, int32_t>;
        return (cell[0] & I(7)) + (cell[1] & I(7)) * I(R) + (cell[2] & I(7)) * I(S);
    }
    // Trilinear sample (stored units) at index-space p; p must be clamped into the grid.
    template <int W, VoxelLayout L = VoxelLayout::Rows, class Scene>
    static RTFACT_INLINE Packet<W> sample(const Scene& s, const Vec3<W>& p) {
        using I = Packet<W, int32_t>;
        static_assert(Scene::kCells == 8);
        const I cell[3] = {toInt(p.x), toInt(p.y), toInt(p.z)};
        const I brick[3] = {cell[0] >> 3, cell[1] >> 3, cell[2] >> 3};
        const I start = gather(s.template entryStart<L>(), brickId<W>(s, brick));
        return sampleCell<W, L>(s, p, cell, start);
    }
    // The same with the cell (toInt of p) and its brick's first entry (in layout L) known.
    template <int W, VoxelLayout L, class Scene>
    static RTFACT_INLINE Packet<W> sampleCell(const Scene& s, const Vec3<W>& p, const Packet<W, int32_t> (&cell)[3],
                                              const Packet<W, int32_t>& start) {
        using P = Packet<W>;
        using I = Packet<W, int32_t>;
        static_assert(L != VoxelLayout::YZQuads || sizeof(typename Scene::Voxel) == 1, "y-z quads are u8");
        constexpr int R = Scene::template kRowStride<L>, S = Scene::template kSliceStride<L>;
        const P fx = p.x - toFloat(cell[0]), fy = p.y - toFloat(cell[1]), fz = p.z - toFloat(cell[2]);
        const I base = start + cellInBrick<W, R, S>(cell);
        // rows (y, z), (y + 1, z), (y, z + 1), (y + 1, z + 1): a = x, b = x + 1
        P a0, b0, a1, b1, a2, b2, a3, b3;
        // Further rows and faces from the same indices and a moved base: AVX2's per-lane loads
        // take each index out of the vector once for all of them.
        if constexpr (L == VoxelLayout::YZQuads) {
            fetchCube<W>(reinterpret_cast<const uint8_t*>(s.copyVoxels), base, a0, a1, a2, a3, b0, b1, b2, b3);
        } else if constexpr (L == VoxelLayout::YPairs) {
            // an entry is two voxels
            fetchQuad<typename Scene::Voxel, W>(s.copyVoxels, base, a0, a1, b0, b1);
            fetchQuad<typename Scene::Voxel, W>(s.copyVoxels + 2 * S, base, a2, a3, b2, b3);
        } else {
            fetchPair<typename Scene::Voxel, W>(s.voxels, base, a0, b0);
            fetchPair<typename Scene::Voxel, W>(s.voxels + R, base, a1, b1);
            fetchPair<typename Scene::Voxel, W>(s.voxels + S, base, a2, b2);
            fetchPair<typename Scene::Voxel, W>(s.voxels + (S + R), base, a3, b3);
        }
        const P c0 = a0 + (b0 - a0) * fx, c1 = a1 + (b1 - a1) * fx, c2 = a2 + (b2 - a2) * fx, c3 = a3 + (b3 - a3) * fx;
        const P d0 = c0 + (c1 - c0) * fy, d1 = c2 + (c3 - c2) * fy;
        return d0 + (d1 - d0) * fz;
    }
    template <int W, class Scene>
    static RTFACT_INLINE Vec3<W> clampToGrid(const Scene& s, const Vec3<W>& p) {
        using P = Packet<W>;
        return {clamp(p.x, P(0.0f), P(s.clampHi.x)), clamp(p.y, P(0.0f), P(s.clampHi.y)),
                clamp(p.z, P(0.0f), P(s.clampHi.z))};
    }
    // Central-difference gradient in world units (stored values per world distance).
    template <int W, VoxelLayout L = VoxelLayout::Rows, class Scene>
    static Vec3<W> gradient(const Scene& s, const Vec3<W>& p) {
        Vec3<W> g;
        for (int a = 0; a < 3; ++a) {
            Vec3<W> lo = p, hi = p;
            lo[a] = lo[a] - Packet<W>(1.0f);
            hi[a] = hi[a] + Packet<W>(1.0f);
            g[a] = (sample<W, L>(s, clampToGrid<W>(s, hi)) - sample<W, L>(s, clampToGrid<W>(s, lo))) *
                   Packet<W>(0.5f * s.invSpacing[a]);
        }
        return g;
    }
    // The same from the gradient bricks (VolumeScene::gradients, not null), for p in cell
    // `cell` of brick `brick`: the trilinear interpolation of the cell's eight central
    // differences: a brick lookup and the cell's four rows of x-adjacent entries
    // (fetchEntryPair: 8 (u8), 16 (u16) or 24 (f32) gathered words) instead of six trilinear
    // samples.
    template <int W, class Scene>
    static RTFACT_INLINE Vec3<W> gradientFromBricks(const Scene& s, const Vec3<W>& p,
                                                    const Packet<W, int32_t> (&cell)[3],
                                                    const Packet<W, int32_t> (&brick)[3]) {
        using P = Packet<W>;
        using I = Packet<W, int32_t>;
        using V = typename Scene::Voxel;
        constexpr int E = Scene::kEdge, B = std::is_same_v<V, float> ? 3 : int(sizeof(V));  // words an entry
        const I base = gather(s.gradients->start.data(), brickId<W>(s, brick)) + cellInBrick<W, E, E * E>(cell) * I(B);
        const P fx = p.x - toFloat(cell[0]), fy = p.y - toFloat(cell[1]), fz = p.z - toFloat(cell[2]);
        // corner (x, y, z) of the cell: entry x + E y + E^2 z from the cell's first
        Vec3<W> row[4];  // the x-lerps of rows (y, z) = (0, 0), (1, 0), (0, 1), (1, 1)
        for (int r = 0; r < 4; ++r) {
            const int off = ((r & 1) * E + (r >> 1) * E * E) * B;
            P g0[3], g1[3];
            if constexpr (B == 3) {
                fetchEntryPair<3, W>(s.gradients->values.data() + off, base, g0, g1);
            } else {
                I w0[B], w1[B], d0[3], d1[3];
                fetchEntryPair<B, W>(s.gradients->entries.data() + off, base, w0, w1);
                GradientBricks::decode<B>(w0, d0);
                GradientBricks::decode<B>(w1, d1);
                for (int a = 0; a < 3; ++a) g0[a] = toFloat(d0[a]), g1[a] = toFloat(d1[a]);
            }
            for (int a = 0; a < 3; ++a) row[r][a] = g0[a] + (g1[a] - g0[a]) * fx;
        }
        Vec3<W> g;
        for (int a = 0; a < 3; ++a) {
            const P d0 = row[0][a] + (row[1][a] - row[0][a]) * fy, d1 = row[2][a] + (row[3][a] - row[2][a]) * fy;
            g[a] = (d0 + (d1 - d0) * fz) * P(0.5f * s.invSpacing[a]);
        }
        return g;
    }
    // Headlight Blinn-Phong with the surface normal from the gradient; lanes without a
    // meaningful gradient stay unshaded.
    template <int W>
    static RTFACT_INLINE Packet<W> shadeFactor(const Vec3<W>& grad, const Vec3<W>& dir) {
        using P = Packet<W>;
        const P g2 = dot(grad, grad);
        const P c = abs(dot(grad, dir)) / sqrt(max(g2, P(1e-30f)));
        const P c2 = c * c, c4 = c2 * c2, c8 = c4 * c4, c16 = c8 * c8;
        return select(g2 > P(1e-12f), P(0.2f) + P(0.8f) * c + P(0.25f) * c16 * c4, P(1.0f));
    }
    // The TF table entry of stored values v, as a float (toInt gives the index).
    template <int W, class Scene>
    static RTFACT_INLINE Packet<W> tfEntry(const Scene& s, const Packet<W>& v) {
        using P = Packet<W>;
        return clamp(v * P(s.tfMul) + P(s.tfAdd), P(0.0f), P(float(s.tf.size - 1)));
    }
    template <int W, class Scene>
    static RTFACT_INLINE Packet<W, int32_t> tfIndex(const Scene& s, const Packet<W>& v) {
        return toInt(tfEntry<W>(s, v));
    }

    // The pre-integrated segment colour (r, g, b) and opacity a between TF entries lo < hi
    // (VolumeScene::tfIntegral: entries lo .. hi - 1), len steps long. Each end's four sums
    // (extinction, r, g, b) are one 16-byte entry: one load a lane on AVX2 (fetchEntryPair)
    // instead of four gathers.
    template <int W, class Scene>
    static RTFACT_INLINE void segment(const Scene& s, const Packet<W, int32_t>& lo, const Packet<W, int32_t>& hi,
                                      const Packet<W>& len, Vec3<W>& rgb, Packet<W>& a) {
        using P = Packet<W>;
        using I = Packet<W, int32_t>;
        P l01[2], l23[2], h01[2], h23[2];  // sums 0, 1 and 2, 3 of the entries lo and hi
        fetchEntryPair<2, W>(s.tfIntegral.data(), lo * I(4), l01, l23);
        fetchEntryPair<2, W>(s.tfIntegral.data(), hi * I(4), h01, h23);
        const P dT = h01[0] - l01[0];
        a = P(1.0f) - expNegative<W>(dT / toFloat(hi - lo) * len);
        const P inv = P(1.0f) / max(dT, P(1e-30f));  // dT 0: no opacity, any colour
        rgb = Vec3<W>(h01[1] - l01[1], h23[0] - l23[0], h23[1] - l23[1]) * inv;
    }

    template <int W, VoxelLayout L, VolumeMode mode, bool kPre, class Scene>
    void march(const Scene& s, const Vec3<W>& o, const Vec3<W>& d, const Packet<W>& tMin, const Packet<W>& tMax,
               const Mask<W>& act, Vec3<W>& col, Packet<W>& alpha, Packet<W>& depth, uint64_t& samples,
               float& skipped) const {
        using P = Packet<W>;
        using I = Packet<W, int32_t>;
        const bool adaptive = (mode == VolumeMode::DVR || mode == VolumeMode::Shaded) && s.longSteps;
        // Rays into index space; t stays the world distance.
        const Vec3<W> oi = (o - Vec3<W>(s.origin)) * Vec3<W>(s.invSpacing);
        const Vec3<W> di = d * Vec3<W>(s.invSpacing);
        Vec3<W> inv;
        for (int a = 0; a < 3; ++a) {
            const P tiny(1e-20f);
            inv[a] = P(1.0f) / select(abs(di[a]) < tiny, select(di[a] < P(0.0f), -tiny, tiny), di[a]);
        }
        P tNear = tMin, tFar = tMax;
        for (int a = 0; a < 3; ++a) {
            const P t0 = (P(s.boxLo[a]) - oi[a]) * inv[a], t1 = (P(s.boxHi[a]) - oi[a]) * inv[a];
            tNear = max(tNear, min(t0, t1));
            tFar = min(tFar, max(t0, t1));
        }
        const P dt(s.dt), dt3(3.0f * s.dt), invDt(1.0f / s.dt);
        // Sample k sits at tNear + (k + 1/2) dt, computed directly (not accumulated) so
        // that skipping and stepping reach bit-identical positions.
        P kf(0.0f);
        if (s.settings.lattice) {
            // A data-parallel rank: the first lattice point (of the whole volume's box)
            // inside this rank's box; tNear then stands for the lattice's start.
            P tL = tMin;
            for (int a = 0; a < 3; ++a) {
                const P lo(s.latticeBoxLo[a]), hi(s.latticeBoxHi[a]);
                tL = max(tL, min((lo - oi[a]) * inv[a], (hi - oi[a]) * inv[a]));
            }
            kf = max(P(0.0f), -floor(-((tNear - tL) * invDt - P(0.5f))));
            tNear = tL;
        }
        P t = tNear + (kf + P(0.5f)) * dt;
        Mask<W> alive = act & (tNear <= tFar) & (t < tFar);
        col = Vec3<W>(Vec3f(0.0f));
        alpha = P(0.0f);
        depth = P(kInfinity);
        P maxv(-kInfinity);
        P prev(0.0f), tPrev(0.0f);
        Mask<W> hasPrev(false);
        const P isoV(s.isoStored);
        const P term(s.settings.earlyTermination);
        const I ncx(s.cells[0]), ncxy(s.cells[0] * s.cells[1]);  // brick grid (MIP)
        const I nsx(s.subs[0]), nsxy(s.subs[0] * s.subs[1]);     // sub-brick grid
        P skipAcc(0.0f);
        Packet<W, int32_t> sampleCount(0);
        // pre-integration: the previous sample's TF entry and index, where it is the sample
        // just before (not before a jump)
        I jPrev(0);
        P kfPrev(0.0f);
        Mask<W> prevOk(false);
        // a data-parallel rank's lanes with a lattice point before their first (in a neighbour)
        Mask<W> rankEntry(false);
        if (kPre && s.settings.lattice) rankEntry = alive & (kf > P(0.5f));

        // Per axis, once a ray: the side of a brick the ray leaves by follows inv's sign (an
        // axis the ray runs along, inv +-1e20, gives a far exit, not a near one), and the
        // exit distance of plane x is x kCells inv - oi inv (sub-bricks: x kSub inv - oi inv).
        Mask<W> up[3];
        P invBrick[3], invSub[3], oiInv[3];
        for (int a = 0; a < 3; ++a) {
            up[a] = inv[a] > P(0.0f);
            invBrick[a] = inv[a] * P(float(Scene::kCells));
            invSub[a] = inv[a] * P(float(Scene::kSub));
            oiInv[a] = oi[a] * inv[a];
        }
        // Where the ray leaves the cube of cells of edge `size` (bricks: invBrick, sub-bricks:
        // invSub) within `reach` - 1 of cell c (1: cell c itself).
        auto cubeExit = [&](const I(&c)[3], const I& reach, const P(&invSize)[3]) __attribute__((always_inline)) {
            P tExit(kInfinity);
            for (int a = 0; a < 3; ++a) {
                const I side = c[a] + select(up[a], reach, I(1) - reach);
                tExit = min(tExit, toFloat(side) * invSize[a] - oiInv[a]);
            }
            return tExit;
        };
        // Index of the first sample at or past distance tx.
        auto sampleIndexAt = [&](const P& tx) __attribute__((always_inline)) {
            return -floor(-((tx - tNear) * invDt - P(0.5f)));
        };
        // Volumes larger than the caches (VolumeScene::prefetchBricks: the voxels the march
        // reads past 8 MB) wait on memory each time a ray enters a brick: two lanes
        // of the group (its first and last alive ones: opposite corners of its footprint)
        // prefetch the brick one brick edge ahead along their ray and its sub-brick entries,
        // once per brick (the last two bricks prefetched are remembered: the two lanes mostly
        // share one). In cache the prefetches cost more than they save.
        // The brick's lines are issued a quarter a step (PrefetchRange: all of them in the four
        // steps before the next look ahead), for the last two bricks, at the end of the step:
        // behind the step's own loads, which then do not queue behind them.
        int32_t recent[2] = {-1, -1};
        const float aheadT = float(Scene::kCells) * s.dt / s.settings.stepVoxels;
        constexpr size_t kBrickBytes = Scene::template kEntryBytes<L> * size_t(Scene::template kBrickStride<L>);
        constexpr int kLinesPerStep = int(PrefetchRange::maxLines(kBrickBytes) + 3) / 4;
        PrefetchRange brickLines[2];
        int pfSlot = 0;
        auto prefetchAhead = [&](int i) __attribute__((always_inline)) {
            const float ta = t[i] + aheadT;
            int32_t b[3];
            for (int a = 0; a < 3; ++a) {
                const float x = oi[a][i] + di[a][i] * ta;
                b[a] = int32_t(x > 0.0f ? std::min(x, s.clampHi[a]) : 0.0f) >> 3;  // NaN: 0
            }
            const int32_t id = b[0] + b[1] * s.nbx + b[2] * s.nbxy;
            if (id == recent[0] || id == recent[1]) return;
            recent[1] = recent[0];
            recent[0] = id;
            // its eight sub-brick entries: two per line along x
            const int32_t sx = s.subs[0], sxy = s.subs[0] * s.subs[1];
            const int32_t* si = s.subInfo.data() + 2 * (b[0] + b[1] * sx + b[2] * sxy);
            __builtin_prefetch(si);
            __builtin_prefetch(si + sx);
            __builtin_prefetch(si + sxy);
            __builtin_prefetch(si + sx + sxy);
            brickLines[pfSlot].reset(
                s.template entryBase<L>() + size_t(s.template entryStart<L>()[id]) * Scene::template kEntryBytes<L>,
                kBrickBytes);
            pfSlot ^= 1;
        };
        uint32_t iteration = 0;
        while (any(alive)) {
            // every fourth step: the brick ahead is at least kCells / stepVoxels steps away
            if (s.prefetchBricks && (iteration++ & 3) == 0) {
                static_assert(W <= 64);
                const uint64_t lanes = BitMask<W>(alive).w[0];
                prefetchAhead(__builtin_ctzll(lanes));
                prefetchAhead(63 - __builtin_clzll(lanes));
            }
            const Vec3<W> p = clampToGrid<W>(s, oi + di * t);
            // the sample's cell, its brick and sub-brick (p >= 0: floor(p / 8) = floor(p) / 8;
            // p < dims - 1 keeps them inside their grids)
            static_assert(Scene::kCells == 8 && Scene::kSub == 4);
            const I cell[3] = {toInt(p.x), toInt(p.y), toInt(p.z)};
            const I c[3] = {cell[0] >> 3, cell[1] >> 3, cell[2] >> 3};
            const I sc[3] = {cell[0] >> 2, cell[1] >> 2, cell[2] >> 2};
            // Pre-integration: this step's segments (lanes that sample, and lanes that close theirs
            // at the edge of an empty cube), composited once below
            Mask<W> segM(false), closing(false);
            I segJ(0), segJp(0);
            P segLen(0.0f), segT(0.0f);
            Mask<W> samp = alive;
            I start(0);
            bool haveStart = false;
            P mStep(1.0f);  // step multiple of the lanes' bricks (opacity-adaptive steps)
            I tfOffset(0);  // their TF table's first entry
            // Empty-space skipping: jump to the first sample position past the empty cube of
            // sub-bricks around the lane's sub-brick (one brick for MIP).
            {
                Mask<W> empty;
                P tExit;  // where the lanes' empty cube ends (computed when one is empty)
                if constexpr (mode == VolumeMode::MIP) {
                    // the brick's maximum and first entry in one fetch (VolumeScene::mipBricks)
                    const I cid = select(alive, c[0] + c[1] * ncx + c[2] * ncxy, I(0));
                    I maxBits[1], first[1];
                    fetchEntryPair<1, W>(s.mipBricks.data(), cid + cid, maxBits, first);
                    P brickMax;
                    for (int k = 0; k < P::C; ++k) std::memcpy(&brickMax.c[k], &maxBits[0].c[k], sizeof(brickMax.c[k]));
                    empty = alive & (brickMax <= maxv);
                    start = first[0];
                    haveStart = true;
                    if (any(empty)) tExit = cubeExit(c, I(1), invBrick);
                } else {
                    // one gather gives the brick, its step multiple, or (sign bit) the
                    // distance to the nearest sub-brick that is not skipped
                    const I cid = select(alive, sc[0] + sc[1] * nsx + sc[2] * nsxy, I(0));
                    const I info = gather(s.subInfo.data(), cid);
                    const Mask<W> skipped = info < I(0);
                    empty = alive & skipped;
                    // The gathers read every lane: a skipped sub-brick's lanes read pool brick 0
                    // (the shared zero brick), not the pool index its distance bits would give,
                    // which lies past the pool of a sparse volume.
                    start = select(skipped, I(0), (info & I(Scene::kPoolMask)) * I(Scene::template kBrickStride<L>));
                    haveStart = true;
                    if constexpr (kPre) {
                        // A rank's first samples are taken even in an empty cube: the segment
                        // into them starts on the neighbour's side, which does not composite it
                        // (a segment the whole volume's march drops lies in one empty cube and
                        // adds nothing). Their bricks then by the full lookup (sample()).
                        if (any(rankEntry)) {
                            haveStart = none(rankEntry & empty);
                            empty = andNot(empty, rankEntry);
                            rankEntry = Mask<W>(false);
                        }
                    }
                    if (adaptive) {
                        I l = (info >> 28) & I(3);
                        if (any(l > I(0))) {
                            // A long step stands for samples kf .. kf + m - 1, which must all
                            // lie in this brick (this sub-brick where the multiple is the
                            // sub-brick's own) and before tFar: near either it shortens to the
                            // samples left (a power of two), so it never carries the brick's
                            // opacity into the next one or past the box (a data-parallel rank's
                            // neighbour has those samples), and homogeneous bricks stay exact.
                            // (samples kf + 1, kf + 3 lie dt, 3 dt past t)
                            const Mask<W> subScope = (info & I(Scene::kSubScopeBit)) != I(0);
                            P exitT = cubeExit(c, I(1), invBrick);
                            if (any(subScope)) exitT = select(subScope, cubeExit(sc, I(1), invSub), exitT);
                            // Pre-integration: the next sample too, where the long step's
                            // segment ends (past tFar none would composite it: a rank's seam).
                            const P room = min(exitT, tFar) - t - (kPre ? dt : P(0.0f));
                            l = select(room > dt3, l, select(room > dt, min(l, I(1)), I(0)));
                        }
                        mStep = select(l == I(2), P(4.0f), select(l == I(1), P(2.0f), P(1.0f)));
                        tfOffset = l * I(s.tf.size);
                    }
                    // skipped: empty cube radius + 1, in sub-bricks
                    if (any(empty)) tExit = cubeExit(sc, info & I(0x7fffffff), invSub);
                }
                if (any(empty)) {
                    if constexpr (kPre) {
                        // Lanes entering the empty cube from a sample: the segment up to here,
                        // whose values may pass visible ones on the way (the cube's own segments
                        // add nothing: its values stay invisible). Its end is sampled below.
                        closing = empty & prevOk;
                        segLen = kf - kfPrev;
                        segT = t;
                        prevOk = andNot(prevOk, empty);
                    }
                    const P kk = max(sampleIndexAt(tExit), kf + P(1.0f));
                    const P tn = tNear + (kk + P(0.5f)) * dt;
                    skipAcc += select(empty, min(kk, (tFar - tNear) * invDt) - kf, P(0.0f));
                    kf = select(empty, kk, kf);
                    t = select(empty, tn, t);
                    samp = andNot(alive, empty);
                }
            }
            // Pre-integration's extra samples, one trilinear fetch for both kinds: the closing
            // lanes' end here, and for a lane's first sample (entering the box or after a jump)
            // the lattice point one step before, where its segment opens (after a jump: in the
            // empty cube, an invisible value).
            P kp = kfPrev;
            if constexpr (kPre) {
                const Mask<W> fresh = andNot(samp, prevOk), extra = closing | fresh;
                segJp = jPrev;
                if (any(extra)) {
                    sampleCount = sampleCount + select(extra, I(1), I(0));
                    // A ray's first segment opens a step before its first sample, outside the
                    // box: its look-back sample is taken at the lattice box's face, so that a
                    // clip plane hides what lies beyond it.
                    const Vec3<W> q0 = oi + di * (tNear + (kf - P(0.5f)) * dt);
                    const Vec3f &lo = s.latticeBoxLo, &hi = s.latticeBoxHi;
                    const Vec3<W> back =
                        clampToGrid<W>(s, Vec3<W>(clamp(q0.x, P(lo.x), P(hi.x)), clamp(q0.y, P(lo.y), P(hi.y)),
                                                  clamp(q0.z, P(lo.z), P(hi.z))));
                    const Vec3<W> q(select(closing, p.x, back.x), select(closing, p.y, back.y),
                                    select(closing, p.z, back.z));
                    const I je = toInt(tfEntry<W>(s, sample<W, L>(s, q)));
                    segJ = je;
                    segJp = select(fresh, je, segJp);
                    kp = select(fresh, kf - P(1.0f), kp);
                }
                segM = closing;
            }
            if (any(samp)) {
                sampleCount = sampleCount + select(samp, I(1), I(0));
                // sampling lanes have not moved since the brick lookup; the others are masked
                const P v = haveStart ? sampleCell<W, L>(s, p, cell, start) : sample<W, L>(s, p);
                if constexpr (kPre) {
                    const I j = toInt(tfEntry<W>(s, v));
                    segM = segM | samp;
                    segJ = select(samp, j, segJ);
                    segLen = select(samp, kf - kp, segLen);
                    segT = select(samp, t, segT);
                    jPrev = select(samp, j, jPrev);
                    kfPrev = select(samp, kf, kfPrev);
                    prevOk = prevOk | samp;
                } else if constexpr (mode == VolumeMode::DVR || mode == VolumeMode::Shaded) {
                    // TF entries outside [tfVisibleLo, tfVisibleHi) have zero opacity: when no
                    // lane's entry is inside, the sample adds nothing (inside partly visible
                    // sub-bricks most samples are invisible) and the TF fetch is left out.
                    const P e = tfEntry<W>(s, v);
                    const Mask<W> seen = samp & (e >= P(s.tfVisibleLo)) & (e < P(s.tfVisibleHi));
                    if (any(seen)) {
                        // the whole RGBA entry in one 64-bit gather per lane
                        P tr, tg, tb, ta;
                        fetchRgbaHalf<W>(s.rgbaSteps.data(), toInt(e) + tfOffset, tr, tg, tb, ta);
                        const P a = select(seen, ta, P(0.0f));
                        const Mask<W> contrib = a > P(0.0f);
                        if (any(contrib)) {
                            Vec3<W> rgb(tr, tg, tb);
                            if constexpr (mode == VolumeMode::Shaded) {
                                const Vec3<W> g =
                                    s.gradients ? gradientFromBricks<W>(s, p, cell, c) : gradient<W, L>(s, p);
                                rgb = rgb * shadeFactor<W>(g, d);
                            }
                            const P w = (P(1.0f) - alpha) * a;
                            col += rgb * w;
                            alpha += w;
                            // t grows along the ray: the first contribution's is the least
                            depth = min(depth, select(contrib, t, P(kInfinity)));
                        }
                        alive = alive & (alpha < term);
                    }
                } else if constexpr (mode == VolumeMode::MIP) {
                    maxv = select(samp, max(maxv, v), maxv);
                } else {
                    const Mask<W> cross = samp & hasPrev & ((prev < isoV) ^ (v < isoV));
                    if (any(cross)) {
                        // Bisection on [tPrev, t] keeping the bracket around the crossing.
                        P lo = tPrev, hi = t;
                        const Mask<W> prevBelow = prev < isoV;
                        for (int it = 0; it < 12; ++it) {
                            const P mid = P(0.5f) * (lo + hi);
                            const P vm = sample<W, L>(s, clampToGrid<W>(s, oi + di * mid));
                            const Mask<W> sameAsPrev = ~((vm < isoV) ^ prevBelow);
                            lo = select(sameAsPrev, mid, lo);
                            hi = select(sameAsPrev, hi, mid);
                        }
                        const P th = P(0.5f) * (lo + hi);
                        const Vec3<W> ph = clampToGrid<W>(s, oi + di * th);
                        const Vec3<W> g = gradient<W, L>(s, ph);
                        const I idx = tfIndex<W>(s, isoV);
                        const Vec3<W> c(gather(s.tf.r.data(), idx), gather(s.tf.g.data(), idx),
                                        gather(s.tf.b.data(), idx));
                        const Vec3<W> sh = c * shadeFactor<W>(g, d);
                        col = select(cross, sh, col);
                        alpha = select(cross, P(1.0f), alpha);
                        depth = select(cross, th, depth);
                        alive = andNot(alive, cross);
                    }
                    prev = select(samp, v, prev);
                    tPrev = select(samp, t, tPrev);
                    hasPrev = hasPrev | samp;
                }
                kf = select(samp, kf + mStep, kf);
                t = select(samp, tNear + (kf + P(0.5f)) * dt, t);
            }
            if constexpr (kPre) {
                // The segments over entries lo .. hi - 1; those with none in [tfVisibleLo,
                // tfVisibleHi) have no opacity, and no fetch when that holds for every lane (most
                // of them, for narrow TFs).
                const I lo = min(segJ, segJp), hi = max(segJ, segJp) + I(1);
                const Mask<W> seen = segM & (hi > I(int32_t(s.tfVisibleLo))) & (lo < I(int32_t(s.tfVisibleHi)));
                if (any(seen)) {
                    Vec3<W> rgb;
                    P a;
                    segment<W>(s, lo, hi, segLen, rgb, a);
                    a = select(seen, a, P(0.0f));
                    const Mask<W> contrib = a > P(0.0f);
                    if (any(contrib)) {
                        // shaded with the gradient where the segment ends (p, for both kinds)
                        if constexpr (mode == VolumeMode::Shaded)
                            rgb =
                                rgb * shadeFactor<W>(
                                          s.gradients ? gradientFromBricks<W>(s, p, cell, c) : gradient<W, L>(s, p), d);
                        const P w = (P(1.0f) - alpha) * a;
                        col += rgb * w;
                        alpha += w;
                        depth = min(depth, select(contrib, segT, P(kInfinity)));
                    }
                    alive = alive & (alpha < term);
                }
            }
            alive = alive & (t < tFar);
            if (s.prefetchBricks) {
                brickLines[0].issue(kLinesPerStep);
                brickLines[1].issue(kLinesPerStep);
            }
        }
        if constexpr (mode == VolumeMode::MIP) {
            const Mask<W> hit = maxv > P(-kInfinity);
            const I idx = tfIndex<W>(s, select(hit, maxv, P(0.0f)));
            const Vec3<W> c(gather(s.tf.r.data(), idx), gather(s.tf.g.data(), idx), gather(s.tf.b.data(), idx));
            col = select(hit, c, col);
            alpha = select(hit, P(1.0f), alpha);
        }
        // Over the background.
        col = col + Vec3<W>(background) * (P(1.0f) - alpha);
        // The chunks added as vectors, then one chunk's lanes (32 dependent scalar adds per
        // group of rays were 1% of a frame).
        using IC = typename I::ChunkPacket;
        using PC = typename P::ChunkPacket;
        IC sc = sampleCount.chunk(0);
        PC sk = skipAcc.chunk(0);
        for (int k = 1; k < I::C; ++k) {
            sc = sc + sampleCount.chunk(k);
            sk = sk + skipAcc.chunk(k);
        }
        for (int i = 0; i < IC::size; ++i) {
            samples += uint64_t(sc[i]);
            skipped += sk[i];
        }
    }
};
static_assert(Integrator<VolumeIntegrator, VolumeScene<uint8_t>>);
static_assert(Integrator<VolumeIntegrator, VolumeScene<uint16_t>>);
static_assert(Integrator<VolumeIntegrator, VolumeScene<float>>);

}  // namespace rtfact::volume
