// Packet traversal of a BlockedWideBVH<Block, K> (coherent rays: primary rays, shadow
// rays from a light). A packet of N rays is traversed one native chunk of W lanes at a
// time; per node the K children are first culled against the whole chunk at once by
// interval arithmetic on the chunk's origins and reciprocal directions (its "frustum":
// one SIMD test over the K children), then the surviving children are tested lane by
// lane (one W-wide slab test each). Stack entries keep the lanes that hit them, and an
// entry reached by few lanes continues as single rays (WideBVHIntersector) from that
// node: the far view of sub-pixel triangles, where a chunk's rays no longer share
// nodes, costs what single rays cost. Leaves are tested per chunk against each element
// of a block (common-origin edge functions shared by the chunk) when most lanes reach
// them, else lane by lane against whole blocks (one SIMD test per block).
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>

#include "core/accel/wide_bvh.h"
#include "core/accel/wide_bvh_intersector.h"
#include "core/concepts/intersector.h"
#include "core/util/assert.h"

namespace rtfact {

// Block leaves against one native chunk k of a packet: the first n elements of the block
// (the rest are padding) update the lanes of chunk k with tMin < t < hit.t.
template <class I, class Block>
concept PacketBlockIntersector = BlockIntersector<I, Block> &&
    requires(const I& isect, const Block& b, int n, const RayPacket<simd::kNativeWidth>& rays,
             typename I::template Hit<simd::kNativeWidth>& hit) {
    isect.template intersectBlockChunk<HitData::Distance>(b, n, rays, hit, 0);
    isect.template intersectBlockChunk<HitData::Shading>(b, n, rays, hit, 0);
    // Lanes (bits of chunk 0) one by one against the whole block; returns the lanes hit.
    { isect.template intersectBlockLanes<HitData::Shading>(b, rays, hit, 0, 1u) } -> std::same_as<uint32_t>;
    { isect.template intersectBlockLanes<HitData::Distance>(b, rays, hit, 0, 1u) } -> std::same_as<uint32_t>;
};

// An interval "frustum" of rays: origins in [orgLo, orgHi], reciprocal directions in
// [invLo, invHi] of one sign per axis (uniform), distances in [tMinLo, tMaxHi].
struct WideFrustum {
    float orgLo[3], orgHi[3], invLo[3], invHi[3];
    float tMinLo = 0.0f, tMaxHi = kInfinity;
    int nearOff[3], farOff[3];  // near and far plane offsets into a node's bounds
    bool uniform = true;

    // org[a], inv[a]: the rays' origins and reciprocal directions on axis a.
    template <int K, int W, class V>
    void init(const V& org, const V& inv, const Packet<W>& tMin, const Mask<W>& active, bool commonOrigin) {
        const Packet<W> inf(kInfinity);
        uniform = true;
        for (int a = 0; a < 3; ++a) {
            invLo[a] = hmin(select(active, inv[a], inf));
            invHi[a] = hmax(select(active, inv[a], -inf));
            orgLo[a] = commonOrigin ? org[a][0] : hmin(select(active, org[a], inf));
            orgHi[a] = commonOrigin ? org[a][0] : hmax(select(active, org[a], -inf));
            uniform = uniform && (invLo[a] > 0.0f || invHi[a] < 0.0f);
            // Bounds are lo[3][K] then hi[3][K].
            nearOff[a] = (invHi[a] < 0.0f ? 3 * K : 0) + a * K;
            farOff[a] = (invHi[a] < 0.0f ? 0 : 3 * K) + a * K;
        }
        tMinLo = hmin(select(active, tMin, inf));
    }

    // The children of a node (bounds f) some ray of the frustum may hit (empty slots
    // never pass): one K-wide interval slab test; entry receives the entry distances.
    template <bool CommonOrigin, int K>
    RTFACT_INLINE uint64_t children(const float* f, Packet<K>& entry) const {
        using PK = Packet<K>;
        if (!uniform) {
            entry = PK(tMinLo);
            return BitMask<K>(PK::load(f) <= PK::load(f + 3 * K)).w[0];
        }
        entry = PK(tMinLo);
        PK exit(tMaxHi);
        for (int a = 0; a < 3; ++a) {
            const PK iL(invLo[a]), iH(invHi[a]);
            const PK nearP = PK::load(f + nearOff[a]), farP = PK::load(f + farOff[a]);
            if constexpr (CommonOrigin) {
                const PK dn = nearP - PK(orgLo[a]), df = farP - PK(orgLo[a]);
                entry = max(entry, min(dn * iL, dn * iH));
                exit = min(exit, max(df * iL, df * iH));
            } else {
                const PK dn0 = nearP - PK(orgLo[a]), dn1 = nearP - PK(orgHi[a]);
                const PK df0 = farP - PK(orgLo[a]), df1 = farP - PK(orgHi[a]);
                entry = max(entry, min(min(dn0 * iL, dn0 * iH), min(dn1 * iL, dn1 * iH)));
                exit = min(exit, max(max(df0 * iL, df0 * iH), max(df1 * iL, df1 * iH)));
            }
        }
        return BitMask<K>(entry <= exit).w[0];
    }
};

// Lane order in which each native chunk of an N-ray packet is a compact tile of the
// image. Packets from the renderer are bw x bh pixels in row-major order (bw the
// smallest divisor of N with bw * bw >= N, core/render's packetBlockWidth), so W
// consecutive lanes would be a thin strip (16 x 1 pixels for 256 rays on AVX-512);
// cw x ch tiles cross fewer small nodes. A traversal that takes G > W lanes (consecutive
// chunks) through the tree as one group gets compact groups too: the group's chunk tiles
// stacked into a 4 x (G / 4) tile (AVX2 chunks of 4 x 2 in 4 x 4 groups; rows of 4 x 2
// tiles paired side by side made 8 x 2 groups). Only speed depends on it: any packet is
// traced correctly in any order. perm[i] is the packet lane that regrouped lane i holds.
template <int N, int G = Packet<N>::W>
struct PacketChunkTiles {
    static constexpr int W = Packet<N>::W;
    static constexpr int bw = [] {
        for (int d = 1; d <= N; ++d)
            if (N % d == 0 && d * d >= N) return d;
        return N;
    }();
    static constexpr int bh = N / bw;
    static constexpr int cw = W >= 8 ? 4 : 2, ch = W / cw;
    // lanes a group (groups of chunks only where chunk tiles are 4 wide), its tile
    static constexpr int GL = G > W&& cw == 4 && G % W == 0 ? G : W;
    static constexpr int gh = GL / cw;
    static constexpr bool kEnabled = N > W&& W >= 4 && bw > cw&& bw % cw == 0 && bh % gh == 0;
    static constexpr int groupsX = bw / cw;
    static constexpr std::array<int16_t, N> perm = [] {
        std::array<int16_t, N> p{};
        for (int i = 0; i < N; ++i) {
            const int group = i / GL, l = i % GL;
            const int x = (group % groupsX) * cw + l % cw, y = (group / groupsX) * gh + l / cw;
            p[size_t(i)] = int16_t(y * bw + x);
        }
        return p;
    }();
    // The packet lane of the first lane of row y of chunk c's tile (a row is cw lanes
    // that are consecutive on both sides).
    static constexpr int rowStart(int c, int y) { return perm[size_t(c * W + y * cw)]; }
};

// Runs trace(r, h) on the packet regrouped in PacketChunkTiles order (groups of G lanes;
// 0: single chunks) when the packet has one (else on the packet as it is), then puts the
// hit records back in the packet's lane order. h starts with hit.t and id -1.
template <int G = 0, int N, class Hit, class Trace>
void traceInChunkTiles(const RayPacket<N>& rays, Hit& hit, const Trace& trace) {
    using T = PacketChunkTiles<N, G>;
    if constexpr (T::kEnabled) {
        // A tile row is cw consecutive lanes on both sides: the regrouping moves whole
        // rows (one 16-byte copy each) instead of single lanes.
        constexpr int kRow = T::cw * 4;
        auto rows = [](auto&& copy) __attribute__((always_inline)) {
            for (int tile = 0; tile < N / T::W; ++tile)
                for (int y = 0; y < T::ch; ++y) copy(tile * T::W + y * T::cw, T::rowStart(tile, y));
        };
        RayPacket<N> r;
        Hit h;
        r.commonOrigin = rays.commonOrigin;
        rows([&](int i, int j) __attribute__((always_inline)) {
            for (int a = 0; a < 3; ++a) {
                std::memcpy(&r.org[a][i], &rays.org[a][j], kRow);
                std::memcpy(&r.dir[a][i], &rays.dir[a][j], kRow);
                std::memcpy(&r.invDir[a][i], &rays.invDir[a][j], kRow);
            }
            std::memcpy(&r.tMin[i], &rays.tMin[j], kRow);
            std::memcpy(&r.tMax[i], &rays.tMax[j], kRow);
            std::memcpy(&h.t[i], &hit.t[j], kRow);
        });
        h.id = Packet<N, int32_t>(-1);
        trace(r, h);
        // Hit records are 4-byte lane packets (as WideBVHIntersector::setHitLane).
        static_assert(sizeof(Hit) % (4 * N) == 0, "hit records must consist of 4-byte lane packets");
        constexpr int kFields = int(sizeof(Hit) / (4 * N));
        auto* d = reinterpret_cast<unsigned char*>(&hit);
        const auto* src = reinterpret_cast<const unsigned char*>(&h);
        rows([&](int i, int j) __attribute__((always_inline)) {
            for (int f = 0; f < kFields; ++f)
                std::memcpy(d + (size_t(f) * N + size_t(j)) * 4, src + (size_t(f) * N + size_t(i)) * 4, kRow);
        });
    } else {
        hit.id = Packet<N, int32_t>(-1);
        trace(rays, hit);
    }
}

template <class ElemIsect>
struct WideBVHPacketIntersector {
    ElemIsect elem{};
    // Entries reached by at most this fraction of a chunk's lanes (at least one lane)
    // continue as single rays; 0: never, 1: always (tests use both ends).
    float singleRayFraction = 0.25f;
    // The same for leaves: a block costs one ray about what one element costs a chunk, so
    // single rays win there up to most of the chunk's lanes.
    float singleRayLeafFraction = 0.75f;
    // Packets of several chunks first go down the tree as a whole (one interval test of
    // a node's children for all lanes) while at most this many children of a node are
    // candidates; a node with more, or with a leaf among them, is where the packet's
    // footprint outgrows the nodes: each chunk traverses it on its own. 0: chunks start
    // at the root.
    int packetSplit = 2;
    template <int N>
    using Hit = typename ElemIsect::template Hit<N>;

    template <bool CommonOrigin, HitData D, class Tree, int N>
    void intersect(const Tree& bvh, const RayPacket<N>& rays, Hit<N>& hit, const Mask<N>& active) const {
        if constexpr (N == 1) {
            single().template intersect<CommonOrigin, D>(bvh, rays, hit, active);
        } else {
            traversePacket<CommonOrigin, D, false>(bvh, rays, hit, active);
            hit.t = select(active, hit.t, rays.tMax);
        }
    }

    template <bool CommonOrigin, class Tree, int N>
    Mask<N> occluded(const Tree& bvh, const RayPacket<N>& rays, const Mask<N>& active) const {
        if constexpr (N == 1) {
            return single().template occluded<CommonOrigin>(bvh, rays, active);
        } else {
            Hit<N> hit;
            traversePacket<CommonOrigin, HitData::Distance, true>(bvh, rays, hit, active);
            return active & (hit.id != Packet<N, int32_t>(-1));
        }
    }

    template <int N>
    using ChunkTiles = PacketChunkTiles<N>;

   private:
    // The active lanes chunk by chunk, in the tiled lane order when the packet has one.
    template <bool CommonOrigin, HitData D, bool AnyHit, class Tree, int N>
    void traversePacket(const Tree& bvh, const RayPacket<N>& rays, Hit<N>& hit, const Mask<N>& active) const {
        hit.t = select(active, rays.tMax, Packet<N>(-kInfinity));
        hit.id = Packet<N, int32_t>(-1);
        traceInChunkTiles(
            rays, hit, [&](const RayPacket<N>& r, Hit<N>& h) { traverseChunks<CommonOrigin, D, AnyHit>(bvh, r, h); });
    }
    // Lanes with hit.t > -inf are active.
    template <bool CommonOrigin, HitData D, bool AnyHit, class Tree, int N>
    void traverseChunks(const Tree& bvh, const RayPacket<N>& rays, Hit<N>& hit) const {
        if constexpr (Packet<N>::C >= 2) {
            if (packetSplit > 0 && !bvh.nodes.empty()) return traverseTop<CommonOrigin, D, AnyHit>(bvh, rays, hit);
        }
        chunksFrom<CommonOrigin, D, AnyHit>(bvh, rays, hit, 0);
    }
    // Every chunk with active lanes through the subtree of inner node `node`.
    template <bool CommonOrigin, HitData D, bool AnyHit, class Tree, int N>
    void chunksFrom(const Tree& bvh, const RayPacket<N>& rays, Hit<N>& hit, int32_t node) const {
        const BitMask<N> bits(hit.t > Packet<N>(-kInfinity));
        for (int k = 0; k < Packet<N>::C; ++k)
            if (const uint32_t lanes = bits.chunkBits(k))
                traverseChunk<CommonOrigin, D, AnyHit>(bvh, rays, hit, k, lanes, node);
    }

    // The whole packet down the top of the tree (sign-uniform packets): nodes whose
    // candidate children are few and inner are split at packet level, near to far; the
    // others go to the chunks (chunksFrom), which then skip the levels above them.
    template <bool CommonOrigin, HitData D, bool AnyHit, class Tree, int N>
    void traverseTop(const Tree& bvh, const RayPacket<N>& rays, Hit<N>& hit) const {
        constexpr int K = Tree::arity;
        using P = Packet<N>;
        const Mask<N> active = hit.t > P(-kInfinity);
        WideFrustum fr;
        fr.template init<K, N>(rays.org, rays.invDir, rays.tMin, active, CommonOrigin);
        if (!fr.uniform) return chunksFrom<CommonOrigin, D, AnyHit>(bvh, rays, hit, 0);
        fr.tMaxHi = hmax(hit.t);
        struct Entry {
            int32_t node;
            float dist;
        };
        Entry stack[(K - 1) * 128 + 1];
        int sp = 0;
        stack[sp++] = {0, fr.tMinLo};
        while (sp > 0) {
            const Entry e = stack[--sp];
            if (!(e.dist <= fr.tMaxHi)) continue;
            const WideBVHNode<K>& n = bvh.nodes[size_t(e.node)];
            Packet<K> entry;
            uint64_t cand = fr.template children<CommonOrigin, K>(n.lo[0], entry);
            bool split = __builtin_popcountll(cand) <= packetSplit;
            for (uint64_t c = cand; c && split; c &= c - 1) split = n.count[__builtin_ctzll(c)] == 0;
            if (!split) {
                chunksFrom<CommonOrigin, D, AnyHit>(bvh, rays, hit, e.node);
                if constexpr (AnyHit) {
                    if (none(hit.t > P(-kInfinity))) return;
                } else {
                    fr.tMaxHi = hmax(hit.t);
                }
                continue;
            }
            RTFACT_ASSERT(sp + K <= int(sizeof stack / sizeof stack[0]), "wide BVH deeper than the traversal stack");
            const int base = sp;
            for (; cand; cand &= cand - 1) {
                const int c = __builtin_ctzll(cand);
                pushSorted(stack, sp, base, Entry{n.child[c], entry[c]});  // the nearest ends on top
            }
        }
    }

    WideBVHIntersector<ElemIsect> single() const { return WideBVHIntersector<ElemIsect>{elem}; }

    // Lane i of chunk k as a single ray from `node` (an inner node, or a leaf given by
    // its first block and element count); the result goes back into the packet's hit.
    template <HitData D, bool AnyHit, class Tree, int N>
    RTFACT_INLINE void singleLane(const Tree& bvh, const RayPacket<N>& rays, Hit<N>& hit, int lane, int32_t child,
                                  int32_t count) const {
        const RayPacket<1> r = rays.lane(lane);
        Hit<1> h;
        h.t = hit.t[lane];
        h.id = -1;
        if (count == 0) {
            single().template traverseFrom<D, AnyHit>(bvh, r, h, child);
        } else {
            const auto* b = bvh.blocks.data() + child;
            const int nb = Tree::blockCount(count);
            if constexpr (AnyHit)
                elem.occludedBlocks(b, nb, r, h);
            else
                elem.template intersectBlocks<D>(b, nb, r, h);
        }
        if (int32_t(h.id) < 0) return;
        WideBVHIntersector<ElemIsect>::setHitLane(hit, lane, h);
        if constexpr (AnyHit) hit.t[lane] = -kInfinity;  // done: no box test passes any more
    }

    // Chunk k (active lanes `lanes`) through the tree.
    template <bool CommonOrigin, HitData D, bool AnyHit, class Tree, int N>
    void traverseChunk(const Tree& bvh, const RayPacket<N>& rays, Hit<N>& hit, int k, uint32_t lanes,
                       int32_t start) const {
        if (bvh.nodes.empty()) return;
        constexpr int K = Tree::arity;
        constexpr int W = Packet<N>::W;
        static_assert(W <= 32, "lane masks are 32 bits");
        using P = Packet<W>;
        using PK = Packet<K>;
        using Block = typename Tree::BlockType;
        static_assert(PacketBlockIntersector<ElemIsect, Block>, "the element intersector must test blocks per chunk");
        const int singleLanes = std::max(1, int(singleRayFraction * float(W)));
        const int singleLeafLanes =
            singleRayLeafFraction > 0.0f ? std::max(1, int(singleRayLeafFraction * float(W))) : 0;
        if (singleRayFraction > 0.0f && __builtin_popcount(lanes) <= singleLanes) {
            for (uint32_t b = lanes; b; b &= b - 1)
                singleLane<D, AnyHit>(bvh, rays, hit, k * W + __builtin_ctz(b), start, 0);
            return;
        }
        uint32_t open = lanes;  // lanes still searching (any hit: without an occluder)
        const Mask<W> chunkActive = hit.t.chunk(k) > P(-kInfinity);

        // The chunk's interval of origins and reciprocal directions (active lanes).
        P org[3], inv[3];
        for (int a = 0; a < 3; ++a) {
            inv[a] = rays.invDir[a].chunk(k);
            org[a] = CommonOrigin ? P(rays.org[a][0]) : rays.org[a].chunk(k);
        }
        const P& tMin = rays.tMin.chunk(k);
        WideFrustum fr;
        fr.template init<K, W>(org, inv, tMin, chunkActive, CommonOrigin);
        fr.tMaxHi = hmax(hit.t.chunk(k));
        const bool uniform = fr.uniform;
        const float* invHi = fr.invHi;
        const float* orgLo = fr.orgLo;
        const P inf(kInfinity);

        // Slab test of the chunk's lanes against child c of the node with bounds f, up to
        // each lane's current hit; tn receives the entry distances.
        auto laneHits = [&](const float* f, int c, P& tn) __attribute__((always_inline)) {
            P tf = hit.t.chunk(k);
            tn = tMin;
            for (int a = 0; a < 3; ++a) {
                float lo = f[a * K + c], hi = f[3 * K + a * K + c];
                if (uniform && invHi[a] < 0.0f) std::swap(lo, hi);
                P t0, t1;
                if constexpr (CommonOrigin) {
                    t0 = P(lo - orgLo[a]) * inv[a];
                    t1 = P(hi - orgLo[a]) * inv[a];
                } else {
                    t0 = (P(lo) - org[a]) * inv[a];
                    t1 = (P(hi) - org[a]) * inv[a];
                }
                if (uniform) {
                    tn = max(tn, t0);
                    tf = min(tf, t1);
                } else {
                    tn = max(tn, min(t0, t1));
                    tf = min(tf, max(t0, t1));
                }
            }
            return tn <= tf;
        };
        // An entry remembers its parent and slot, so its lanes are tested again against the
        // hits found since it was pushed; `leaves` counts the leaves run so far, an entry
        // popped with no leaf run since its push has nothing to test again.
        struct Entry {
            int32_t child, count;
            float dist;
            uint32_t lanes;
            int32_t parent, slot;
            uint32_t leaves;
        };
        uint32_t leaves = 0;
        Entry stack[(K - 1) * 128 + 1];
        int sp = 0;
        int32_t node = start;
        uint32_t nodeLanes = lanes;
        for (;;) {
            const WideBVHNode<K>& n = bvh.nodes[size_t(node)];
            const float* f = n.lo[0];
            // Children some lane of the chunk may hit (empty slots never pass).
            PK entry;
            uint64_t cand = fr.template children<CommonOrigin, K>(f, entry);
            // Each candidate against the chunk's lanes.
            const int base = sp;
            RTFACT_ASSERT(sp + K <= int(sizeof stack / sizeof stack[0]), "wide BVH deeper than the traversal stack");
            for (; cand; cand &= cand - 1) {
                const int c = __builtin_ctzll(cand);
                P tn;
                const Mask<W> m = laneHits(f, c, tn);
                const uint32_t hitLanes = uint32_t(BitMask<W>(m).w[0]) & nodeLanes;
                if (!hitLanes) continue;
                Entry e{n.child[c], n.count[c], 0.0f, hitLanes, node, c, leaves};
                if constexpr (AnyHit) {
                    stack[sp++] = e;
                } else {
                    // The interval entry bounds the lanes' entries from below: it orders the
                    // children without a horizontal minimum per child.
                    e.dist = uniform ? entry[c] : hmin(select(m, tn, inf));
                    pushSorted(stack, sp, base, e);  // far to near: the nearest ends on top
                }
            }
            // Pop the nearest entry that can still hold a closer hit; run leaves and
            // hand entries with few lanes to single rays.
            for (;;) {
                if (sp == 0) return;
                Entry e = stack[--sp];
                if constexpr (AnyHit) {
                    e.lanes &= open;
                    if (!e.lanes) continue;
                } else {
                    if (!(e.dist <= fr.tMaxHi)) continue;
                    // Lanes that found a hit in front of the entry leave it.
                    if (e.leaves != leaves) {
                        P tn;
                        e.lanes &= uint32_t(BitMask<W>(laneHits(bvh.nodes[size_t(e.parent)].lo[0], e.slot, tn)).w[0]);
                        if (!e.lanes) continue;
                    }
                }
                const int lanesHit = __builtin_popcount(e.lanes);
                const bool few =
                    e.count == 0 ? singleRayFraction > 0.0f && lanesHit <= singleLanes : lanesHit <= singleLeafLanes;
                if (e.count == 0 && !few) {
                    node = e.child;
                    nodeLanes = e.lanes;
                    break;
                }
                ++leaves;  // single rays from an inner node count too: they may find hits
                if (few && e.count == 0) {
                    for (uint32_t b = e.lanes; b; b &= b - 1)
                        singleLane<D, AnyHit>(bvh, rays, hit, k * W + __builtin_ctz(b), e.child, e.count);
                } else if (few) {
                    const Block* blocks = bvh.blocks.data() + e.child;
                    const int nb = Tree::blockCount(e.count);
                    uint32_t l = e.lanes;
                    for (int j = 0; j < nb && l; ++j) {
                        const uint32_t f = elem.template intersectBlockLanes<D>(blocks[j], rays, hit, k, l);
                        if constexpr (AnyHit) l &= ~f;
                    }
                } else {
                    const Block* blocks = bvh.blocks.data() + e.child;
                    const int nb = Tree::blockCount(e.count);
                    for (int j = 0; j < nb; ++j)
                        elem.template intersectBlockChunk<D>(
                            blocks[j], std::min(Tree::kBlock, e.count - j * Tree::kBlock), rays, hit, k);
                }
                if constexpr (AnyHit) {
                    // Lanes that found an occluder leave the traversal.
                    const Mask<W> found = hit.id.chunk(k) != Packet<W, int32_t>(-1);
                    hit.t.chunk(k) = select(found, P(-kInfinity), hit.t.chunk(k));
                    open &= ~uint32_t(BitMask<W>(found).w[0]);
                    if (!open) return;
                }
                fr.tMaxHi = hmax(hit.t.chunk(k));
            }
        }
    }
};

}  // namespace rtfact
