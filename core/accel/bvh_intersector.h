// Generic packet traversal of a BVH<Elem>, calling a nested element intersector at the
// leaves. One routine serves single rays (N = 1) and packets: each node remembers the
// first native chunk of the packet that still hits it, large coherent packets are
// culled with an interval-arithmetic frustum test, and any-hit queries stop as soon
// as every lane has found an occluder.
#pragma once
#include "core/accel/bvh.h"
#include "core/accel/ray_box.h"
#include "core/concepts/intersector.h"
#include "core/util/assert.h"

namespace rtfact {

template <class ElemIsect>
struct BVHIntersector {
    ElemIsect elem{};
    template <int N>
    using Hit = typename ElemIsect::template Hit<N>;

    template <bool CommonOrigin, HitData D, class Elem, int N>
    void intersect(const BVH<Elem>& bvh, const RayPacket<N>& rays, Hit<N>& hit, const Mask<N>& active) const {
        hit.t = select(active, rays.tMax, Packet<N>(-kInfinity));
        hit.id = Packet<N, int32_t>(-1);
        traverse<CommonOrigin, D, false>(bvh, rays, hit, active);
        hit.t = select(active, hit.t, rays.tMax);
    }

    template <bool CommonOrigin, class Elem, int N>
    Mask<N> occluded(const BVH<Elem>& bvh, const RayPacket<N>& rays, const Mask<N>& active) const {
        Hit<N> hit;
        hit.t = select(active, rays.tMax, Packet<N>(-kInfinity));
        hit.id = Packet<N, int32_t>(-1);
        traverse<CommonOrigin, HitData::Distance, true>(bvh, rays, hit, active);
        return active & (hit.id != Packet<N, int32_t>(-1));
    }

   private:
    static constexpr int kStackSize = 128;

    template <bool CommonOrigin, HitData D, bool AnyHit, class Elem, int N>
    void traverse(const BVH<Elem>& bvh, const RayPacket<N>& rays, Hit<N>& hit, const Mask<N>& active) const {
        if (bvh.nodes.empty()) return;
        constexpr int C = Packet<N>::C;
        constexpr int W = Packet<N>::W;
        PacketBounds pb;
        bool frustum = false;
        bool neg[3] = {false, false, false};
        if constexpr (C >= 4) {
            pb = rays.bounds(active);
            frustum = pb.uniformSigns;
            for (int a = 0; a < 3; ++a) neg[a] = pb.invDirHi[a] < 0.0f;
        }
        struct Entry {
            uint32_t node, first;
        };
        Entry stack[kStackSize];
        int sp = 0;
        stack[sp++] = {0u, 0u};
        while (sp > 0) {
            const Entry e = stack[--sp];
            const BVHNode& node = bvh.nodes[e.node];
            int k = int(e.first);
            // Sign-uniform packets know their near and far planes per axis.
            auto hits = [&](int kk) {
                if constexpr (C >= 4) {
                    if (frustum) return any(chunkHitsBoxSigned<CommonOrigin>(node.lo, node.hi, rays, hit.t, kk, neg));
                }
                return any(chunkHitsBox<CommonOrigin>(node.lo, node.hi, rays, hit.t, kk));
            };
            if (!hits(k)) {
                if (frustum && packetMissesBox(node.lo, node.hi, pb, pb.tMaxHi)) continue;
                for (++k; k < C; ++k)
                    if (hits(k)) break;
                if (k == C) continue;
            }
            if (node.isLeaf()) {
                for (int i = 0; i < node.count(); ++i) {
                    const uint32_t ei = uint32_t(node.ofs + i);
                    elem.template intersect<D>(bvh.elems[ei], bvh.order[ei], rays, hit, k);
                }
                if constexpr (AnyHit) {
                    // Lanes that found an occluder leave the traversal.
                    const Mask<N> found = hit.id != Packet<N, int32_t>(-1);
                    hit.t = select(found, Packet<N>(-kInfinity), hit.t);
                    if (all(found | ~active)) return;
                }
                if (frustum) pb.tMaxHi = hmax(hit.t);
                continue;
            }
            // Near child first, judged by the first lane of the first active chunk.
            uint32_t nearChild = uint32_t(node.ofs), farChild = nearChild + 1;
            if (frustum ? neg[node.axis()] : rays.dir[node.axis()][k * W] < 0.0f) std::swap(nearChild, farChild);
            RTFACT_ASSERT(sp + 2 <= kStackSize, "BVH deeper than the traversal stack (builders cap the depth at 64)");
            stack[sp++] = {farChild, uint32_t(k)};
            stack[sp++] = {nearChild, uint32_t(k)};
        }
    }
};

}  // namespace rtfact
