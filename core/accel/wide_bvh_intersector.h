// Single-ray traversal of a WideBVH<Elem, K>, calling a nested element intersector at
// the leaves. One ray is tested against the K child boxes of a node at once (one SIMD
// op per slab plane), the children hit are visited near to far and stack entries keep
// their entry distance so they are skipped once a closer hit is known. Incoherent rays
// (AO, diffuse bounces) gain nothing from packets; packets of N > 1 lanes are served
// by looping the single-ray path over the active lanes, so an integrator picks at
// compile time which structure serves which rays.
#pragma once
#include <cstring>
#include <type_traits>

#include "core/accel/wide_bvh.h"
#include "core/concepts/intersector.h"
#include "core/concepts/intersector_hooks.h"
#include "core/geometry/sphere.h"
#include "core/util/assert.h"

namespace rtfact {

template <class ElemIsect>
struct WideBVHIntersector {
    ElemIsect elem{};
    template <int N>
    using Hit = typename ElemIsect::template Hit<N>;

    template <bool CommonOrigin, HitData D, class Elem, int K, int N>
    void intersect(const WideBVH<Elem, K>& bvh, const RayPacket<N>& rays, Hit<N>& hit, const Mask<N>& active) const {
        if constexpr (N == 1) {
            hit.t = rays.tMax;
            hit.id = -1;
            if (active[0]) traverse<D, false>(bvh, rays, hit);
        } else {
            hit.t = rays.tMax;
            hit.id = Packet<N, int32_t>(-1);
            BitMask<N>(active).forEach([&](int i) {
                const RayPacket<1> r = rays.lane(i);
                Hit<1> h;
                h.t = r.tMax;
                h.id = -1;
                traverse<D, false>(bvh, r, h);
                if (int32_t(h.id) >= 0) setHitLane(hit, i, h);
            });
        }
    }

    template <bool CommonOrigin, class Elem, int K, int N>
    Mask<N> occluded(const WideBVH<Elem, K>& bvh, const RayPacket<N>& rays, const Mask<N>& active) const {
        Mask<N> occ(false);
        BitMask<N>(active).forEach([&](int i) {
            Hit<1> h;
            if constexpr (N == 1) {
                h.t = rays.tMax;
                h.id = -1;
                traverse<HitData::Distance, true>(bvh, rays, h);
            } else {
                const RayPacket<1> r = rays.lane(i);
                h.t = r.tMax;
                h.id = -1;
                traverse<HitData::Distance, true>(bvh, r, h);
            }
            if (int32_t(h.id) >= 0) occ.set(i, true);
        });
        return occ;
    }

   private:
    // Copies every field of a single-ray hit into lane i of a packet hit. Hit records
    // are structs of 4-byte packets (t, id, u, v, ...), so Hit<N> is Hit<1> with every
    // field widened to N lanes.
    template <int N>
    static void setHitLane(Hit<N>& dst, int i, const Hit<1>& src) {
        static_assert(sizeof(Hit<1>) % 4 == 0 && sizeof(Hit<N>) == sizeof(Hit<1>) * N,
                      "hit records must consist of 4-byte lane packets");
        constexpr int kFields = int(sizeof(Hit<1>) / 4);
        auto* d = reinterpret_cast<unsigned char*>(&dst);
        const auto* s = reinterpret_cast<const unsigned char*>(&src);
        for (int f = 0; f < kFields; ++f) std::memcpy(d + (size_t(f) * N + size_t(i)) * 4, s + size_t(f) * 4, 4);
    }

    template <HitData D, bool AnyHit, class Elem, int K>
    void traverse(const WideBVH<Elem, K>& bvh, const RayPacket<1>& ray, Hit<1>& hit) const {
        if (bvh.nodes.empty()) return;
        using P = Packet<K>;
        // Per axis: which bound array is the near plane, and the ray broadcast to K lanes.
        int nearIdx[3];
        P org[3], inv[3];
        for (int a = 0; a < 3; ++a) {
            const float id = ray.invDir[a][0];
            nearIdx[a] = id < 0.0f ? 1 : 0;
            inv[a] = P(id);
            org[a] = P(ray.org[a][0]);
        }
        const P tMin(float(ray.tMin));
        struct Entry {
            int32_t child, count;
            float dist;
        };
        // Each wide level pushes at most K entries and pops one; the wide tree is no
        // deeper than the binary one, whose traversal assumes depth < 128.
        Entry stack[(K - 1) * 128 + 1];
        int sp = 0;
        int32_t node = 0;
        for (;;) {
            // Inner node: test all K children.
            const WideBVHNode<K>& n = bvh.nodes[size_t(node)];
            const float* bnd[2][3] = {{n.lo[0], n.lo[1], n.lo[2]}, {n.hi[0], n.hi[1], n.hi[2]}};
            P tn = tMin, tf(float(hit.t));
            for (int a = 0; a < 3; ++a) {
                const P nearP = P::load(bnd[nearIdx[a]][a]), farP = P::load(bnd[1 - nearIdx[a]][a]);
                tn = max(tn, (nearP - org[a]) * inv[a]);
                tf = min(tf, (farP - org[a]) * inv[a]);
            }
            uint64_t bits = BitMask<K>(tn <= tf).w[0];
            const int cnt = __builtin_popcountll(bits);
            if (cnt > 0) {
                // Push hit children far to near (insertion by distance onto the stack top).
                const int base = sp;
                for (; bits; bits &= bits - 1) {
                    const int c = __builtin_ctzll(bits);
                    const Entry e{n.child[c], n.count[c], tn[c]};
                    RTFACT_ASSERT(sp < int(sizeof stack / sizeof stack[0]), "wide BVH deeper than the traversal stack");
                    int j = sp++;
                    while (j > base && stack[j - 1].dist < e.dist) {
                        stack[j] = stack[j - 1];
                        --j;
                    }
                    stack[j] = e;
                }
            }
            // Pop the nearest entry that can still hold a closer hit; run leaves.
            for (;;) {
                if (sp == 0) return;
                const Entry e = stack[--sp];
                if (!(e.dist <= float(hit.t))) continue;
                if (e.count == 0) {
                    node = e.child;
                    break;
                }
                // Element intersectors may test a whole leaf at once (SIMD over elements).
                if constexpr (LeafIntersector<ElemIsect, Elem>) {
                    elem.template intersectLeaf<D>(bvh.elems.data() + e.child, bvh.order.data() + e.child, e.count, ray,
                                                   hit);
                } else {
                    for (int i = 0; i < e.count; ++i) {
                        const uint32_t ei = uint32_t(e.child + i);
                        elem.template intersect<D>(bvh.elems[ei], bvh.order[ei], ray, hit, 0);
                    }
                }
                if constexpr (AnyHit) {
                    if (int32_t(hit.id) >= 0) return;
                }
            }
        }
    }
};

// Checked here with the core's own element (surfaces/mesh_scene.h checks triangles).
static_assert(Intersector<WideBVHIntersector<SphereIntersector>, WideBVH<Sphere, 4>>);
static_assert(Intersector<WideBVHIntersector<SphereIntersector>, WideBVH<Sphere, 16>>);

}  // namespace rtfact
