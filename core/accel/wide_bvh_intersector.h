// Single-ray traversal of a WideBVH<Elem, K> or a BlockedWideBVH<Block, K>, calling a
// nested element intersector at the leaves (per element, per leaf or per SIMD block). One ray is tested against the K
// child boxes of a node at once (one SIMD op per slab plane), the children hit are visited near to far and stack
// entries keep their entry distance so they are skipped once a closer hit is known. Incoherent rays (AO, diffuse
// bounces) gain nothing from packets; packets of N > 1 lanes are served by the single-ray path over the active
// lanes (interleaved, several rays in flight, on trees larger than the caches), so an integrator picks at compile
// time which structure serves which rays.
#pragma once
#include <algorithm>
#include <concepts>
#include <cstring>
#include <type_traits>

#include "core/accel/wide_bvh.h"
#include "core/concepts/intersector.h"
#include "core/concepts/intersector_hooks.h"
#include "core/geometry/sphere.h"
#include "core/util/assert.h"
#include "core/util/prefetch.h"

namespace rtfact {

// Block leaves (BlockedWideBVH): the element intersector tests n consecutive blocks.
template <class I, class Block>
concept BlockIntersector = requires(const I& isect, const Block* blocks, int n, const RayPacket<1>& ray,
                                    typename I::template Hit<1>& hit) {
    isect.template intersectBlocks<HitData::Distance>(blocks, n, ray, hit);
    isect.template intersectBlocks<HitData::Shading>(blocks, n, ray, hit);
    { isect.template occludedBlocks(blocks, n, ray, hit) } -> std::same_as<bool>;
};

template <class ElemIsect>
struct WideBVHIntersector {
    ElemIsect elem{};
    template <int N>
    using Hit = typename ElemIsect::template Hit<N>;

    template <bool CommonOrigin, HitData D, class Tree, int N>
    void intersect(const Tree& bvh, const RayPacket<N>& rays, Hit<N>& hit, const Mask<N>& active) const {
        if constexpr (N == 1) {
            hit.t = rays.tMax;
            hit.id = -1;
            if (active[0]) traverse<D, false>(bvh, rays, hit);
        } else {
            hit.t = rays.tMax;
            hit.id = Packet<N, int32_t>(-1);
            int lanes[N];
            int count = 0;
            BitMask<N>(active).forEach([&](int i) { lanes[count++] = i; });
            traverseLanesFrom<D, false>(bvh, rays, hit, lanes, count, 0);
        }
    }

    template <bool CommonOrigin, class Tree, int N>
    Mask<N> occluded(const Tree& bvh, const RayPacket<N>& rays, const Mask<N>& active) const {
        Mask<N> occ(false);
        if constexpr (N == 1) {
            Hit<1> h;
            h.t = rays.tMax;
            h.id = -1;
            if (active[0]) traverse<HitData::Distance, true>(bvh, rays, h);
            occ.set(0, int32_t(h.id) >= 0);
        } else {
            Hit<N> hit;
            hit.t = rays.tMax;
            hit.id = Packet<N, int32_t>(-1);
            int lanes[N];
            int count = 0;
            BitMask<N>(active).forEach([&](int i) { lanes[count++] = i; });
            traverseLanesFrom<HitData::Distance, true>(bvh, rays, hit, lanes, count, 0);
            occ = active & (hit.id != Packet<N, int32_t>(-1));
        }
        return occ;
    }

    // Continues a query at `root` (an inner node) with hit.t the distance to beat: packet
    // traversals hand lanes over to single rays here.
    template <HitData D, bool AnyHit, class Tree>
    void traverseFrom(const Tree& bvh, const RayPacket<1>& ray, Hit<1>& hit, int32_t root) const {
        traverse<D, AnyHit>(bvh, ray, hit, root);
    }

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

   private:
    // One leaf (first, count) against the ray; returns true when an any-hit query is done.
    template <HitData D, bool AnyHit, class Elem, int K>
    RTFACT_INLINE bool leaf(const WideBVH<Elem, K>& bvh, int32_t first, int32_t count, const RayPacket<1>& ray,
                            Hit<1>& hit) const {
        // Element intersectors may test a whole leaf at once (SIMD over elements).
        if constexpr (LeafIntersector<ElemIsect, Elem>) {
            elem.template intersectLeaf<D>(bvh.elems.data() + first, bvh.order.data() + first, count, ray, hit);
        } else {
            for (int i = 0; i < count; ++i) {
                const uint32_t ei = uint32_t(first + i);
                elem.template intersect<D>(bvh.elems[ei], bvh.order[ei], ray, hit, 0);
            }
        }
        if constexpr (AnyHit) return int32_t(hit.id) >= 0;
        return false;
    }
    template <HitData D, bool AnyHit, class Block, int K>
    RTFACT_INLINE bool leaf(const BlockedWideBVH<Block, K>& bvh, int32_t first, int32_t count, const RayPacket<1>& ray,
                            Hit<1>& hit) const {
        static_assert(BlockIntersector<ElemIsect, Block>, "the element intersector must test leaf blocks");
        const Block* b = bvh.blocks.data() + first;
        const int n = BlockedWideBVH<Block, K>::blockCount(count);
        if constexpr (AnyHit)
            return elem.occludedBlocks(b, n, ray, hit);
        else
            elem.template intersectBlocks<D>(b, n, ray, hit);
        return false;
    }

    template <int K>
    static RTFACT_INLINE void prefetchNode(const WideBVHNode<K>* n) {
        prefetchBytes(n, sizeof(WideBVHNode<K>));
    }

    // The first block of a leaf that will be visited (block leaves are read whole, and
    // the stack lets the load start before the leaf's turn).
    template <class Tree>
    static RTFACT_INLINE void prefetchLeaf(const Tree& bvh, int32_t first) {
        // Every line the block touches: a block need not start on a line.
        if constexpr (requires { bvh.blocks; })
            prefetchBytes(bvh.blocks.data() + first, sizeof(typename Tree::BlockType));
    }

    // One single-ray query as a resumable state: step() makes one node visit (the node
    // test, its pushes, then pops and leaves up to the next inner node), so independent
    // rays can be interleaved (traverseLanesFrom) and one ray's node load overlaps the work of
    // the others. Closest hit: children hit are visited near to far (three or more are
    // placed on the stack by rank, pushRanked) and a popped entry is skipped once a closer hit is
    // known. Any hit: no ordering at all, larger children first (the builder's slot order).
    // The child visited next (a single one, the nearer of two, any hit's first) is entered
    // or its leaf tested at once, not pushed and popped. Every inner child entered or pushed
    // is prefetched.
    template <HitData D, bool AnyHit, class Tree>
    struct Walk {
        static constexpr int K = Tree::arity;
        using P = Packet<K>;
        struct Entry {
            int32_t child, count;
            float dist;
        };
        // Origin and reciprocal direction as scalars, broadcast at use (AVX-512 folds the
        // broadcast into the arithmetic, and a group of walks stays small). The slabs keep
        // the form (plane - org) * inv: a ray lying in a slab plane gets t = 0 there, where
        // plane * inv - org * inv would give the rounding error of org * inv, of either sign.
        float org[3], inv[3];
        // Near and far plane of each axis, by the sign of the direction, as offsets into
        // the node's bounds (lo[3][K] then hi[3][K]): plain loads, no per-axis select.
        int nearOff[3], farOff[3];
        float tMin;
        int32_t node;
        int sp;
        // Each wide level pushes at most K entries and pops one; wide trees are no deeper
        // than the binary ones they may come from, whose traversal assumes depth < 128.
        Entry stack[(K - 1) * 128 + 1];

        // Leaves out of line at every width: inlined, their SIMD test takes the registers
        // and the node test's ray values are spilled and reloaded at every pop, visited leaf
        // or not; as a call they are saved only around the leaves visited. (AVX-512 inlined
        // them until session 21; out of line is no slower there, measured on Zen 4.)
        static __attribute__((noinline)) bool leafCall(const WideBVHIntersector& isect, const Tree& bvh, int32_t first,
                                                       int32_t count, const RayPacket<1>& ray, Hit<1>& hit) {
            return isect.template leaf<D, AnyHit>(bvh, first, count, ray, hit);
        }

        // Every inner child or leaf pushed is prefetched: its turn comes later.
        static RTFACT_INLINE void prefetchEntry(const Tree& bvh, const Entry& e) {
            if (e.count == 0)
                prefetchNode(bvh.nodes.data() + e.child);
            else
                prefetchLeaf(bvh, e.child);
        }
        RTFACT_INLINE void push(const Tree& bvh, const Entry& e) {
            prefetchEntry(bvh, e);
            stack[sp++] = e;
        }

        RTFACT_INLINE void start(const Tree& bvh, const RayPacket<1>& ray, int32_t root) {
            for (int a = 0; a < 3; ++a) {
                const float id = ray.invDir[a][0];
                nearOff[a] = (id < 0.0f ? 3 * K : 0) + a * K;
                farOff[a] = (id < 0.0f ? 0 : 3 * K) + a * K;
                inv[a] = id;
                org[a] = float(ray.org[a][0]);
            }
            tMin = float(ray.tMin);
            node = root;
            sp = 0;
            prefetchNode(bvh.nodes.data() + root);
        }

        // False once the query is done (hit holds the result).
        RTFACT_INLINE bool step(const WideBVHIntersector& isect, const Tree& bvh, const RayPacket<1>& ray,
                                Hit<1>& hit) {
            const WideBVHNode<K>* nodes = bvh.nodes.data();
            const WideBVHNode<K>& n = nodes[node];
            const float* f = n.lo[0];
            P tn(tMin), tf(float(hit.t));
            for (int a = 0; a < 3; ++a) {
                const P o(org[a]), i(inv[a]);
                tn = max(tn, (P::load(f + nearOff[a]) - o) * i);
                tf = min(tf, (P::load(f + farOff[a]) - o) * i);
            }
            uint64_t bits = BitMask<K>(tn <= tf).w[0];
            // The child visited next, taken at once below instead of pushed and popped.
            Entry next{};
            bool haveNext = false;
            if (bits) {
                RTFACT_ASSERT(sp + K <= int(sizeof stack / sizeof stack[0]),
                              "wide BVH deeper than the traversal stack");
                const int c0 = __builtin_ctzll(bits);
                const uint64_t rest = bits & (bits - 1);
                if constexpr (AnyHit) {
                    // No ordering: slot order. The first (largest) child is next, the others
                    // are pushed last slot first, so that they pop in slot order.
                    next = Entry{n.child[c0], n.count[c0], 0.0f};
                    for (uint64_t r = rest; r;) {
                        const int c = 63 - __builtin_clzll(r);
                        r &= ~(uint64_t(1) << c);
                        push(bvh, Entry{n.child[c], n.count[c], 0.0f});
                    }
                } else if (!(rest & (rest - 1))) {
                    // One or two children (the common cases, told apart without a branch): the
                    // far one is pushed (with one child, a copy of it is stored and not counted),
                    // the near one next, chosen by a select (the distances make a branch
                    // unpredictable).
                    const int c1 = rest ? __builtin_ctzll(rest) : c0;
                    const float d0 = tn[c0], d1 = tn[c1];
                    const bool swap = d1 <= d0;  // ties: the later slot first, as sorted
                    const int cn = swap ? c1 : c0, cf = swap ? c0 : c1;
                    next = Entry{n.child[cn], n.count[cn], swap ? d1 : d0};
                    const Entry farE{n.child[cf], n.count[cf], swap ? d0 : d1};
                    prefetchEntry(bvh, farE);
                    stack[sp] = farE;
                    sp += rest != 0;
                } else {
                    // Three or more: placed by rank (pushRanked), no insertion branches.
                    pushRanked(stack, sp, bits, tn, [&](int c) {
                        const Entry e{n.child[c], n.count[c], tn[c]};
                        prefetchEntry(bvh, e);
                        return e;
                    });
                }
                haveNext = AnyHit || !(rest & (rest - 1));
            }
            if (haveNext) {
                if (next.count == 0) {
                    node = next.child;
                    prefetchNode(nodes + node);
                    return true;
                }
                if (leafCall(isect, bvh, next.child, next.count, ray, hit)) return false;
            }
            // Pop the nearest entry that can still hold a closer hit; run leaves.
            for (;;) {
                if (sp == 0) return false;
                const Entry e = stack[--sp];
                if constexpr (!AnyHit) {
                    if (!(e.dist <= float(hit.t))) continue;
                }
                if (e.count == 0) {
                    node = e.child;
                    return true;
                }
                if (leafCall(isect, bvh, e.child, e.count, ray, hit)) return false;
            }
        }
    };

    template <HitData D, bool AnyHit, class Tree>
    void traverse(const Tree& bvh, const RayPacket<1>& ray, Hit<1>& hit, int32_t root = 0) const {
        if (bvh.nodes.empty()) return;
        Walk<D, AnyHit, Tree> w;
        w.start(bvh, ray, root);
        while (w.step(*this, bvh, ray, hit)) {
        }
    }

   public:
    // Packet queries trace their lanes as independent single rays, `group` of them in
    // flight at once (1..kMaxGroup): each advances one node visit in turn and a finished
    // one hands its slot to the next lane, so one ray's cache misses overlap the others'
    // work. That pays once the tree outgrows the caches; on a cache-resident tree the
    // interleaving costs more than it hides (MeshScene picks by tree size). Every ray
    // gets exactly the result of its own single-ray traversal.
    static constexpr int kMaxGroup = 4;
    int group = 1;

    // Lanes lanes[0..count) of a packet as single rays from `root` (an inner node), each
    // with hit.t[lane] as the distance to beat, `group` of them interleaved. A lane that
    // finds a hit gets it in hit (any hit: its t becomes -inf, no box test passes any
    // more); the others keep their hit record.
    template <HitData D, bool AnyHit, class Tree, int N>
    void traverseLanesFrom(const Tree& bvh, const RayPacket<N>& rays, Hit<N>& hitN, const int* lanes, int count,
                           int32_t root) const {
        if (bvh.nodes.empty()) return;
        const int G = std::clamp(group, 1, kMaxGroup);
        Walk<D, AnyHit, Tree> walk[kMaxGroup];
        RayPacket<1> ray[kMaxGroup];
        Hit<1> hit[kMaxGroup];
        int laneOf[kMaxGroup], slot[kMaxGroup];
        int next = 0, live = 0;
        // Starts the next lane in walk w; false when none is left.
        auto load = [&](int w) {
            if (next == count) return false;
            const int i = lanes[next++];
            laneOf[w] = i;
            ray[w] = rays.lane(i);
            hit[w].t = hitN.t[i];
            hit[w].id = -1;
            walk[w].start(bvh, ray[w], root);
            return true;
        };
        for (int w = 0; w < G && load(w); ++w) slot[live++] = w;
        while (live > 0) {
            for (int s = 0; s < live;) {
                const int w = slot[s];
                if (walk[w].step(*this, bvh, ray[w], hit[w])) {
                    ++s;
                    continue;
                }
                if (int32_t(hit[w].id) >= 0) {
                    setHitLane(hitN, laneOf[w], hit[w]);
                    if constexpr (AnyHit) hitN.t[laneOf[w]] = -kInfinity;
                }
                if (!load(w)) slot[s] = slot[--live];
            }
        }
    }
};

// Checked here with the core's own element (surfaces/mesh_scene.h checks triangles).
static_assert(Intersector<WideBVHIntersector<SphereIntersector>, WideBVH<Sphere, 4>>);
static_assert(Intersector<WideBVHIntersector<SphereIntersector>, WideBVH<Sphere, 16>>);

}  // namespace rtfact
