// LoDWideIntersector: single-ray traversal of a LoDWideBVH with level-of-detail cuts.
// At each node one SIMD op per slab tests the ray against the K child boxes, as the core's
// WideBVHIntersector does; then one compare cuts every child hit whose representative
// disc is no larger than `quality` times the ray's footprint where the ray enters the
// child's box (the camera cone, width(t) = base + slope * t, unit directions), and one
// SIMD disc test intersects the ray with the cut children's representatives (hit at
// `repScale` of their covering radius, as the kd-tree's). The other children are visited
// near to far. Quality 0 is full detail.
// Packets go through the tree a native chunk of W rays at a time (traverseGroup; ISAs
// narrower than 16 lanes take two or four chunks as one group of 16): the
// levels above the cut are then fetched once per group instead of once per ray, which
// is where single rays spend their time on large clouds (dependent misses ~15 levels
// deep). The cut stays each ray's own (its footprint at its own entry into the child's
// box), so a packet answers every ray as a single ray would (up to the visiting order of
// representatives that reach outside their boxes).
#pragma once
#include "core/accel/wide_bvh_packet_intersector.h"
#include "core/concepts/camera.h"
#include "core/concepts/intersector.h"
#include "core/util/assert.h"
#include "core/util/prefetch.h"
#include "points/lod_wide_bvh.h"
#include "points/ray_disc_plane.h"

namespace rtfact::points {

struct LoDWideIntersector {
    DiscBlockIntersector elem{};
    RayCone cone{};
    float quality = 0.0f;  // 0: full detail
    float repScale = 0.7f;
    template <int N>
    using Hit = DiscIntersector::Hit<N>;

    // Chunks reached by at most this fraction of their lanes (at least one) go on as single
    // rays; leaves reached by at most singleRayLeafFraction of them test their blocks
    // lane by lane (one SIMD test over a block's discs per ray), else disc by disc for the
    // chunk's lanes at once. One eighth (one AVX2 lane, two AVX-512 ones) against a
    // quarter: full detail on the 2M dragon +2-5% at 1 and 2 threads on both ISAs
    // (session 20, alternating runs); the 32M LoD frames did not move.
    float singleRayFraction = 0.125f;
    float singleRayLeafFraction = 0.5f;
    // Narrow chunks (AVX2 and SSE) are traced in groups of this many lanes (4 x 4 pixels):
    // each node's frustum test, the stack and the cut decisions serve two AVX2 chunks at
    // once. LoD frames since session 20; full detail since session 31 (2M dragon, AVX2
    // build on Zen 5: 34-35 -> 31-33 ms a frame at one thread; 32M: 79-84 -> 75-77 ms).
    static constexpr int kGroupLanes = 16;

    template <bool CommonOrigin, HitData D, int N>
    void intersect(const LoDWideBVH& bvh, const RayPacket<N>& rays, Hit<N>& hit, const Mask<N>& active) const {
        hit.t = rays.tMax;
        hit.id = Packet<N, int32_t>(-1);
        if constexpr (N == 1) {
            if (active[0]) traverse<D, false>(bvh, rays, hit, 0);
        } else {
            tracePacket<CommonOrigin, D, false>(bvh, rays, hit, active);
            hit.t = select(active, hit.t, rays.tMax);
        }
    }

    template <bool CommonOrigin, int N>
    Mask<N> occluded(const LoDWideBVH& bvh, const RayPacket<N>& rays, const Mask<N>& active) const {
        Hit<N> hit;
        hit.t = rays.tMax;
        hit.id = Packet<N, int32_t>(-1);
        if constexpr (N == 1) {
            if (active[0]) traverse<HitData::Distance, true>(bvh, rays, hit, 0);
        } else {
            tracePacket<CommonOrigin, HitData::Distance, true>(bvh, rays, hit, active);
        }
        return active & (hit.id != Packet<N, int32_t>(-1));
    }

   private:
    static constexpr int K = LoDWideBVH::K;
    using P = Packet<K>;

    static RTFACT_INLINE void prefetchNode(const LoDWideBVH& bvh, int32_t n) {
        prefetchBytes(bvh.nodes.data() + n, sizeof(WideBVHNode<K>));
        // The radii decide the cut; the rest of the summaries only when a child is cut.
        __builtin_prefetch(bvh.childReps[size_t(n)].radius);
    }

    // A pushed entry's inner node, or its leaf's blocks of discs: its turn comes later.
    // (Every block, not the first only: SAH leaves hold up to two; 2M dragon full detail
    // about +2% on the AVX2 build, Zen 5, inside the noise of three runs.)
    static RTFACT_INLINE void prefetchEntry(const LoDWideBVH& bvh, int32_t child, int32_t count) {
        if (count == 0)
            prefetchNode(bvh, child);
        else
            prefetchBytes(bvh.blocks.data() + child, sizeof(bvh.blocks[0]) * size_t(DiscWideBVH::blockCount(count)));
    }

    // The ray against the representatives of the children in `cut`; returns true when an
    // any-hit query is done.
    template <bool AnyHit>
    RTFACT_INLINE bool cutChildren(const LoDWideBVH& bvh, const LoDChildReps<K>& r, int32_t node, uint64_t cut,
                                   const RayPacket<1>& ray, Hit<1>& hit) const {
        const P rr = P::load(r.radius) * P(repScale);
        const auto [t, dist2] = rayDiscPlane(r.c, r.n, ray);
        uint64_t m = BitMask<K>((dist2 <= rr * rr) & (t > P(float(ray.tMin))) & (t < P(float(hit.t)))).w[0] & cut;
        if (!m) return false;
        if constexpr (AnyHit) {
            const int c = __builtin_ctzll(m);
            hit.t = t[c];
            hit.id = LoDWideBVH::repId(node, c);
            return true;
        }
        int best = -1;
        float bt = float(hit.t);
        for (; m; m &= m - 1) {
            const int c = __builtin_ctzll(m);
            if (t[c] < bt) bt = t[c], best = c;
        }
        if (best >= 0) {
            __builtin_prefetch(&bvh.reps[size_t(node) * K + size_t(best)]);  // for the shading
            hit.t = bt;
            hit.id = LoDWideBVH::repId(node, best);
        }
        return false;
    }

    template <HitData D, bool AnyHit>
    RTFACT_INLINE bool leaf(const LoDWideBVH& bvh, int32_t first, int32_t count, const RayPacket<1>& ray,
                            Hit<1>& hit) const {
        const auto* b = bvh.blocks.data() + first;
        const int n = DiscWideBVH::blockCount(count);
        if constexpr (AnyHit)
            return elem.occludedBlocks(b, n, ray, hit);
        else
            elem.intersectBlocks<D>(b, n, ray, hit);
        return false;
    }

    // Closest hit: children hit are visited near to far and a popped entry is skipped once
    // a closer hit is known. Any hit: no ordering.
    template <HitData D, bool AnyHit>
    void traverse(const LoDWideBVH& bvh, const RayPacket<1>& ray, Hit<1>& hit, int32_t start) const {
        if (bvh.nodes.empty()) return;
        const WideBVHNode<K>* nodes = bvh.nodes.data();
        int nearOff[3], farOff[3];
        P org[3], inv[3];
        for (int a = 0; a < 3; ++a) {
            const float id = ray.invDir[a][0];
            nearOff[a] = (id < 0.0f ? 3 * K : 0) + a * K;
            farOff[a] = (id < 0.0f ? 0 : 3 * K) + a * K;
            inv[a] = P(id);
            org[a] = P(ray.org[a][0]);
        }
        const P tMin(float(ray.tMin));
        const bool lod = quality > 0.0f;
        // Cut when 2 radius <= quality (base + slope t), i.e. radius <= a + b t.
        const P cutBase(0.5f * quality * cone.base), cutSlope(0.5f * quality * cone.slope);
        struct Entry {
            int32_t child, count;
            float dist;
        };
        Entry stack[(K - 1) * LoDWideBVH::kMaxDepth + 1];
        int sp = 0;
        int32_t node = start;
        for (;;) {
            const WideBVHNode<K>& n = nodes[node];
            const float* f = n.lo[0];
            P tn = tMin, tf(float(hit.t));
            for (int a = 0; a < 3; ++a) {
                tn = max(tn, (P::load(f + nearOff[a]) - org[a]) * inv[a]);
                tf = min(tf, (P::load(f + farOff[a]) - org[a]) * inv[a]);
            }
            uint64_t bits = BitMask<K>(tn <= tf).w[0];
            if (lod && bits) {
                const LoDChildReps<K>& r = bvh.childReps[size_t(node)];
                const uint64_t cut = bits & BitMask<K>(P::load(r.radius) <= cutBase + cutSlope * max(tn, P(0.0f))).w[0];
                if (cut) {
                    bits &= ~cut;
                    if (cutChildren<AnyHit>(bvh, r, node, cut, ray, hit)) return;
                }
            }
            if constexpr (!AnyHit) {
                if (bits && !(bits & (bits - 1))) {
                    const int c = __builtin_ctzll(bits);
                    if (!n.isLeaf(c)) {
                        node = n.child[c];
                        prefetchNode(bvh, node);
                        continue;
                    }
                }
            }
            if (bits) {
                RTFACT_ASSERT(sp + K <= int(sizeof stack / sizeof stack[0]), "wide BVH deeper than the stack");
                if constexpr (AnyHit) {
                    while (bits) {
                        const int c = 63 - __builtin_clzll(bits);
                        bits &= ~(uint64_t(1) << c);
                        prefetchEntry(bvh, n.child[c], n.count[c]);
                        stack[sp++] = Entry{n.child[c], n.count[c], 0.0f};
                    }
                } else {
                    // far to near: the nearest ends on top
                    pushRanked(stack, sp, bits, tn, [&](int c) {
                        prefetchEntry(bvh, n.child[c], n.count[c]);
                        return Entry{n.child[c], n.count[c], tn[c]};
                    });
                }
            }
            for (;;) {
                if (sp == 0) return;
                const Entry e = stack[--sp];
                if constexpr (!AnyHit) {
                    if (!(e.dist <= float(hit.t))) continue;
                }
                if (e.count == 0) {
                    node = e.child;
                    break;
                }
                if (leaf<D, AnyHit>(bvh, e.child, e.count, ray, hit)) return;
            }
        }
    }

    // The packet chunk by chunk, its lanes regrouped so that each chunk is a compact tile
    // of the image (the core's PacketChunkTiles order) when the packet has one. Inactive and
    // finished (any hit) lanes carry hit.t = -inf: no box test passes for them.
    template <bool CommonOrigin, HitData D, bool AnyHit, int N>
    void tracePacket(const LoDWideBVH& bvh, const RayPacket<N>& rays, Hit<N>& hit, const Mask<N>& active) const {
        if (bvh.nodes.empty()) return;
        hit.t = select(active, hit.t, Packet<N>(-kInfinity));
        if constexpr (Packet<N>::W < 4) {
            BitMask<N>(active).forEach([&](int i) { singleLane<D, AnyHit>(bvh, rays, hit, i, 0); });
        } else {
            traceInChunkTiles<groupLanes<N>()>(
                rays, hit, [&](const RayPacket<N>& r, Hit<N>& h) { traceChunks<CommonOrigin, D, AnyHit>(bvh, r, h); });
        }
    }

    // Lanes traced together: a native chunk, or narrow ones in groups of kGroupLanes.
    template <int N>
    static constexpr int groupLanes() {
        constexpr int W = Packet<N>::W;
        return kGroupLanes <= N && W < kGroupLanes ? kGroupLanes : W;
    }

    template <bool CommonOrigin, HitData D, bool AnyHit, int N>
    void traceChunks(const LoDWideBVH& bvh, const RayPacket<N>& rays, Hit<N>& hit) const {
        constexpr int W = Packet<N>::W, GW = groupLanes<N>();
        const BitMask<N> bits(hit.t > Packet<N>(-kInfinity));
        auto run = [&]<int M>() __attribute__((always_inline)) {
            for (int g = 0; g < N / M; ++g) {
                uint32_t lanes = 0;  // the group's native chunks' bits side by side
                for (int j = 0; j < M / W; ++j) lanes |= bits.chunkBits(g * (M / W) + j) << (j * W);
                if (lanes) {
                    traverseGroup<CommonOrigin, D, AnyHit, M>(bvh, rays, hit, g, lanes);
                    // The shading reads each hit disc next (a cache miss per pixel on large
                    // clouds): start those loads while the other groups trace.
                    if constexpr (!AnyHit)
                        for (int i = g * M; i < (g + 1) * M; ++i)
                            if (const int32_t id = hit.id[i]; id >= 0) __builtin_prefetch(&bvh.elems[size_t(id)]);
                }
            }
        };
        if constexpr (GW > W)
            run.template operator()<GW>();
        else
            run.template operator()<W>();
    }

    // Packet lane i as a single ray from inner node `start`; the result goes back into hit.
    template <HitData D, bool AnyHit, int N>
    RTFACT_INLINE void singleLane(const LoDWideBVH& bvh, const RayPacket<N>& rays, Hit<N>& hit, int i,
                                  int32_t start) const {
        const RayPacket<1> r = rays.lane(i);
        Hit<1> h;
        h.t = hit.t[i];
        h.id = -1;
        traverse<D, AnyHit>(bvh, r, h, start);
        if (int32_t(h.id) == -1) return;
        hit.t[i] = AnyHit ? -kInfinity : float(h.t);  // any hit: done, no box test passes any more
        hit.id[i] = int32_t(h.id);
    }

    // The lanes of a W-lane chunk given as bits, as a lane mask.
    template <int W>
    static RTFACT_INLINE Mask<W> laneMask(uint32_t bits) {
        using PI = Packet<W, int32_t>;
        static const PI laneBit = [] {
            PI p;
            for (int i = 0; i < W; ++i) p[i] = int32_t(1u << i);
            return p;
        }();
        return (PI(int32_t(bits)) & laneBit) != PI(0);
    }

    // Group k of W lanes (one native chunk, or W / Wn of them as one group; active lanes
    // `lanes`) through the tree. Per node, one interval test culls the K children for the
    // whole group (core WideFrustum), then each candidate is tested against the group's
    // lanes; the lanes whose footprint at their entry covers the child's representative
    // are answered by it (one disc test for those lanes), the others descend. Entries
    // reached by few lanes continue as single rays (a fraction of a native chunk's lanes).
    template <bool CommonOrigin, HitData D, bool AnyHit, int W, int N>
    void traverseGroup(const LoDWideBVH& bvh, const RayPacket<N>& rays, Hit<N>& hit, int k, uint32_t lanes) const {
        static_assert(W <= 32, "lane masks are 32 bits");
        using PW = Packet<W>;
        const int k0 = k * (W / Packet<N>::W);  // the group's first native chunk
        PW& ht = chunkGroup<W>(hit.t, k0);
        Packet<W, int32_t>& hid = chunkGroup<W>(hit.id, k0);
        const int singleLanes = std::max(1, int(singleRayFraction * float(Packet<N>::W)));
        const int singleLeafLanes = std::max(1, int(singleRayLeafFraction * float(Packet<N>::W)));
        if (__builtin_popcount(lanes) <= singleLanes) {
            for (uint32_t b = lanes; b; b &= b - 1) singleLane<D, AnyHit>(bvh, rays, hit, k * W + __builtin_ctz(b), 0);
            return;
        }
        uint32_t open = lanes;  // lanes still searching (any hit: without an occluder)
        PW org[3], inv[3];
        for (int a = 0; a < 3; ++a) {
            inv[a] = chunkGroup<W>(rays.invDir[a], k0);
            org[a] = CommonOrigin ? PW(rays.org[a][0]) : chunkGroup<W>(rays.org[a], k0);
        }
        const PW& tMin = chunkGroup<W>(rays.tMin, k0);
        WideFrustum fr;
        fr.template init<K, W>(org, inv, tMin, ht > PW(-kInfinity), CommonOrigin);
        fr.tMaxHi = hmax(ht);
        const bool uniform = fr.uniform;
        const bool lod = quality > 0.0f;
        const PW cutBase(0.5f * quality * cone.base), cutSlope(0.5f * quality * cone.slope);
        const PW inf(kInfinity);
        // Slab test of the chunk's lanes against child c of the node with bounds f, up to
        // each lane's current hit; tn receives the entry distances.
        auto laneHits = [&](const float* f, int c, PW& tn) __attribute__((always_inline)) {
            PW tf = ht;
            tn = tMin;
            for (int a = 0; a < 3; ++a) {
                const PW t0 = (PW(f[a * K + c]) - org[a]) * inv[a], t1 = (PW(f[3 * K + a * K + c]) - org[a]) * inv[a];
                tn = max(tn, min(t0, t1));
                tf = min(tf, max(t0, t1));
            }
            return uint32_t(BitMask<W>(tn <= tf).w[0]);
        };
        // Any hit: lanes that found an occluder leave the traversal.
        auto retire = [&]() {
            const Mask<W> found = hid != Packet<W, int32_t>(-1);
            ht = select(found, PW(-kInfinity), ht);
            open &= ~uint32_t(BitMask<W>(found).w[0]);
        };
        // An entry keeps its lanes' distances into the child's box (closest hit), so at its
        // turn one compare drops the lanes whose hit, found since, lies before the box: the
        // slab test again, since their far distances and the box are unchanged. (Re-testing
        // the parent's slabs at every pop instead: full detail 6-7% slower, AVX2, Zen 5.)
        struct Entry {
            int32_t child, count;
            float dist;
            uint32_t lanes;
            float tn[AnyHit ? 1 : W];
        };
        Entry stack[(K - 1) * LoDWideBVH::kMaxDepth + 1];
        int sp = 0;
        int32_t node = 0;
        uint32_t nodeLanes = lanes;
        for (;;) {
            const WideBVHNode<K>& n = bvh.nodes[size_t(node)];
            const float* f = n.lo[0];
            P entry;
            uint64_t cand = fr.template children<CommonOrigin, K>(f, entry);
            const int base = sp;
            RTFACT_ASSERT(sp + K <= int(sizeof stack / sizeof stack[0]), "wide BVH deeper than the stack");
            for (; cand; cand &= cand - 1) {
                const int c = __builtin_ctzll(cand);
                PW tn;
                uint32_t m = laneHits(f, c, tn) & nodeLanes;
                if (!m) continue;
                if (lod) {
                    // Cut where 2 radius <= quality (base + slope t) at the lane's own entry.
                    const LoDChildReps<K>& r = bvh.childReps[size_t(node)];
                    const uint32_t cut =
                        m & uint32_t(BitMask<W>(PW(r.radius[c]) <= cutBase + cutSlope * max(tn, PW(0.0f))).w[0]);
                    if (cut) {
                        // Most cut children are hit: their disc (colour) is read by the shading next.
                        __builtin_prefetch(&bvh.reps[size_t(node) * K + size_t(c)]);
                        const float rr = r.radius[c] * repScale;
                        DiscIntersector::intersectDiscGroup(
                            Vec3f(r.c[0][c], r.c[1][c], r.c[2][c]), Vec3f(r.n[0][c], r.n[1][c], r.n[2][c]), rr * rr,
                            LoDWideBVH::repId(node, c), rays, hit, k0, laneMask<W>(cut));
                        if constexpr (AnyHit) {
                            retire();
                            if (!open) return;
                        }
                        m &= ~cut;
                        if (!m) continue;
                    }
                }
                prefetchEntry(bvh, n.child[c], n.count[c]);
                if constexpr (AnyHit) {
                    Entry& e = stack[sp++];
                    e.child = n.child[c];
                    e.count = n.count[c];
                    e.dist = 0.0f;
                    e.lanes = m;
                } else {
                    // The interval entry bounds the lanes' entries from below: it orders the
                    // children without a horizontal minimum per child.
                    Entry e;
                    e.child = n.child[c];
                    e.count = n.count[c];
                    e.dist = uniform ? entry[c] : hmin(select(tn <= ht, tn, inf));
                    e.lanes = m;
                    tn.store(e.tn);
                    pushSorted(stack, sp, base, e);  // far to near: the nearest ends on top
                }
            }
            // Pop the nearest entry that can still hold a closer hit; run leaves and hand
            // entries with few lanes to single rays.
            for (;;) {
                if (sp == 0) return;
                Entry& e = stack[--sp];  // popped: read before anything is pushed again
                if constexpr (AnyHit) {
                    e.lanes &= open;
                } else {
                    if (!(e.dist <= fr.tMaxHi)) continue;
                    e.lanes &= uint32_t(BitMask<W>(PW::load(e.tn) <= ht).w[0]);
                }
                if (!e.lanes) continue;
                const int lanesHit = __builtin_popcount(e.lanes);
                if (e.count == 0) {
                    if (lanesHit > singleLanes) {
                        node = e.child;
                        nodeLanes = e.lanes;
                        break;
                    }
                    for (uint32_t b = e.lanes; b; b &= b - 1)
                        singleLane<D, AnyHit>(bvh, rays, hit, k * W + __builtin_ctz(b), e.child);
                } else if (lanesHit <= singleLeafLanes) {
                    for (uint32_t b = e.lanes; b; b &= b - 1) {
                        const int i = k * W + __builtin_ctz(b);
                        const RayPacket<1> r = rays.lane(i);
                        Hit<1> h;
                        h.t = hit.t[i];
                        h.id = -1;
                        leaf<D, AnyHit>(bvh, e.child, e.count, r, h);
                        if (int32_t(h.id) == -1) continue;
                        hit.t[i] = float(h.t);
                        hit.id[i] = int32_t(h.id);
                    }
                } else {
                    const Mask<W> m = laneMask<W>(e.lanes);
                    const auto* blocks = bvh.blocks.data() + e.child;
                    for (int j = 0; j * kDiscLeafBlock < e.count; ++j) {
                        const auto& b = blocks[j];
                        const int cnt = std::min(kDiscLeafBlock, e.count - j * kDiscLeafBlock);
                        for (int i = 0; i < cnt; ++i)
                            DiscIntersector::intersectDiscGroup(Vec3f(b.c[0][i], b.c[1][i], b.c[2][i]),
                                                                Vec3f(b.n[0][i], b.n[1][i], b.n[2][i]), b.r2[i],
                                                                b.id[i], rays, hit, k0, m);
                    }
                }
                if constexpr (AnyHit) {
                    retire();
                    if (!open) return;
                } else {
                    fr.tMaxHi = hmax(ht);
                }
            }
        }
    }
};

static_assert(Intersector<LoDWideIntersector, LoDWideBVH>);

}  // namespace rtfact::points
