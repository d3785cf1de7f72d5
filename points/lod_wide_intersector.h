// LoDWideIntersector: single-ray traversal of a LoDWideBVH with level-of-detail cuts.
// At each node one SIMD op per slab tests the ray against the K child boxes, as the core's
// WideBVHIntersector does; then one compare cuts every child hit whose representative
// disc is no larger than `quality` times the ray's footprint where the ray enters the
// child's box (the camera cone, width(t) = base + slope * t, unit directions), and one
// SIMD disc test intersects the ray with the cut children's representatives (hit at
// `repScale` of their covering radius, as the kd-tree's). The other children are visited
// near to far. Quality 0 is full detail. Packets go lane by lane: the cut then follows
// each ray's own footprint.
#pragma once
#include "core/concepts/camera.h"
#include "core/concepts/intersector.h"
#include "core/util/assert.h"
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

    template <bool CommonOrigin, HitData D, int N>
    void intersect(const LoDWideBVH& bvh, const RayPacket<N>& rays, Hit<N>& hit, const Mask<N>& active) const {
        hit.t = rays.tMax;
        hit.id = Packet<N, int32_t>(-1);
        if constexpr (N == 1) {
            if (active[0]) traverse<D, false>(bvh, rays, hit);
        } else {
            BitMask<N>(active).forEach([&](int i) {
                const RayPacket<1> r = rays.lane(i);
                Hit<1> h;
                h.t = r.tMax;
                h.id = -1;
                traverse<D, false>(bvh, r, h);
                hit.t[i] = float(h.t);
                hit.id[i] = int32_t(h.id);
            });
        }
    }

    template <bool CommonOrigin, int N>
    Mask<N> occluded(const LoDWideBVH& bvh, const RayPacket<N>& rays, const Mask<N>& active) const {
        Mask<N> occ(false);
        BitMask<N>(active).forEach([&](int i) {
            Hit<1> h;
            const RayPacket<1> r = rays.lane(i);
            h.t = r.tMax;
            h.id = -1;
            traverse<HitData::Distance, true>(bvh, r, h);
            if (int32_t(h.id) != -1) occ.set(i, true);
        });
        return occ;
    }

   private:
    static constexpr int K = LoDWideBVH::K;
    using P = Packet<K>;

    static RTFACT_INLINE void prefetchNode(const LoDWideBVH& bvh, int32_t n) {
        const char* p = reinterpret_cast<const char*>(bvh.nodes.data() + n);
        for (size_t o = 0; o < sizeof(WideBVHNode<K>); o += 64) __builtin_prefetch(p + o);
        // The radii decide the cut; the rest of the summaries only when a child is cut.
        __builtin_prefetch(bvh.childReps[size_t(n)].radius);
    }

    // The ray against the representatives of the children in `cut`; returns true when an
    // any-hit query is done.
    template <bool AnyHit>
    RTFACT_INLINE bool cutChildren(const LoDChildReps<K>& r, int32_t node, uint64_t cut, const RayPacket<1>& ray,
                                   Hit<1>& hit) const {
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
    void traverse(const LoDWideBVH& bvh, const RayPacket<1>& ray, Hit<1>& hit) const {
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
        int32_t node = 0;
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
                    if (cutChildren<AnyHit>(r, node, cut, ray, hit)) return;
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
                        if (n.count[c] == 0) prefetchNode(bvh, n.child[c]);
                        stack[sp++] = Entry{n.child[c], n.count[c], 0.0f};
                    }
                } else {
                    const int base = sp;
                    for (; bits; bits &= bits - 1) {
                        const int c = __builtin_ctzll(bits);
                        const Entry e{n.child[c], n.count[c], tn[c]};
                        if (e.count == 0) prefetchNode(bvh, e.child);
                        pushSorted(stack, sp, base, e);  // far to near: the nearest ends on top
                    }
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
};

static_assert(Intersector<LoDWideIntersector, LoDWideBVH>);

}  // namespace rtfact::points
