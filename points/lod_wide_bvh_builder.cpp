// buildLoDWideBVH: see lod_wide_bvh.h.
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <array>
#include <limits>

#include "core/accel/wide_bvh_builder.h"
#include "core/util/assert.h"
#include "core/util/error.h"
#include "points/lod_rep.h"
#include "points/lod_wide_bvh.h"
#include "points/median_select.h"
#include "points/spread_axis.h"

namespace rtfact::points {

namespace {

constexpr int K = LoDWideBVH::K;
static_assert(WideSAHBVHBuilder::kMaxDepth <= LoDWideBVH::kMaxDepth, "the traversal stack assumes this depth");

struct Sum {
    LoDRepSum s;
    Disc rep;  // covering radius set
};

constexpr int S = DiscWideBVH::kBlock;

// Lanes summed in double (the sums up the tree are double).
template <int N>
double laneSum(const Packet<N>& p) {
    double s = 0;
    for (int i = 0; i < N; ++i) s += p[i];
    return s;
}

// The leaf of up to S discs at elems[first, first + n): block first / S, filled first (the
// normals decoded once), then its sum and representative from the block's lanes, S discs
// per SIMD op: LoDRepSum::add per disc, decoding every normal again, was an eighth of a
// median build. Unused lanes repeat the last disc: they weigh nothing in the sums and
// change no bound.
Sum leafBlock(LoDWideBVH& t, uint32_t first, uint32_t n) {
    using P = Packet<S>;
    using PI = Packet<S, int32_t>;
    const Disc* d = t.elems.data() + first;
    DiscBlock<S>& b = t.blocks[first / S];
    std::array<uint32_t, S> ids;
    for (int i = 0; i < S; ++i) ids[size_t(i)] = first + uint32_t(i);
    b.fill(ids.data(), int(n), [&](uint32_t i) -> const Disc& { return t.elems[i]; });

    alignas(64) int32_t rgba[S];
    for (int i = 0; i < S; ++i) rgba[i] = int32_t(d[std::min(i, int(n) - 1)].rgba);
    const PI c8 = PI::load(rgba);
    const P r2 = P::load(b.r2), r = sqrt(r2);
    const P w = select(P::ramp(0.0f) < P(float(n)), r2 + P(1e-30f), P(0.0f));
    Sum k;
    k.s.w = laneSum(w);
    for (int a = 0; a < 3; ++a) {
        const P c = P::load(b.c[a]), nn = P::load(b.n[a]);
        k.s.c[a] = laneSum(w * c);
        k.s.n[a] = laneSum(w * nn);
        k.s.col[a] = laneSum(w * toFloat((c8 >> (8 * a)) & PI(255)) * P(1.0f / 255.0f));
        const P e = discReach(r, nn);
        k.s.box.lo[a] = hmin(c - e);
        k.s.box.hi[a] = hmax(c + e);
    }
    k.s.height = 1;
    k.rep = k.s.rep();
    P dist2(0.0f);
    for (int a = 0; a < 3; ++a) {
        const P off = P::load(b.c[a]) - P(k.rep.center[a]);
        dist2 = dist2 + off * off;
    }
    const float cover = hmax(sqrt(dist2) + r);
    k.rep.radius = coverMargin(std::min(cover, boxCoverRadius(k.rep.center, k.s.box)));
    return k;
}

// Child c of node ni's representative (null: an empty slot, +inf radius, never cut): its
// centre, radius and decoded normal in the node's child summaries, its octahedral normal
// and colour in reps.
void setRep(LoDWideBVH& t, size_t ni, int c, const Disc* rep) {
    LoDChildReps<K>& cr = t.childReps[ni];
    LoDRepLook& look = t.reps[ni * K + size_t(c)];
    if (!rep) {
        cr.radius[c] = std::numeric_limits<float>::infinity();
        for (int a = 0; a < 3; ++a) cr.c[a][c] = cr.n[a][c] = 0.0f;
        look = LoDRepLook{};
        return;
    }
    const Vec3f nn = rep->n();
    cr.radius[c] = rep->radius;
    for (int a = 0; a < 3; ++a) {
        cr.c[a][c] = rep->center[a];
        cr.n[a][c] = nn[a];
    }
    look = LoDRepLook{rep->normal, rep->rgba};
}

// How a range of `count` discs is cut into the (at most K) children of a wide node. The
// children are complete subtrees of `cap` = S K^j discs (the largest such below count),
// the last one holding the rest: a part of more than cap discs is halved at a multiple of
// cap, the largest first, until none is left. Nodes are then full (K children) but along
// the right edge, the tree has ~1/(K-1) nodes per block, and every part starts at a
// multiple of S (leaves are exactly one block). The plan depends on the count only, so
// node slots are known before the discs are sorted; siblings stay in memory order.
struct Plan {
    int parts = 1;
    uint32_t first[K] = {0}, count[K] = {0};
    int steps = 0;
    uint32_t stepFirst[K - 1], stepCount[K - 1], half[K - 1];  // range halved by each step, and where
};
Plan makePlan(uint32_t count) {
    Plan p;
    p.count[0] = count;
    uint64_t cap = S;
    while (cap * K < count) cap *= K;
    for (int step = 0; p.parts < K; ++step) {
        int best = -1;
        for (int i = 0; i < p.parts; ++i)
            if (p.count[i] > cap && (best < 0 || p.count[i] > p.count[best])) best = i;
        if (best < 0) break;
        const uint32_t h = uint32_t((p.count[best] + cap - 1) / cap / 2 * cap);
        p.stepFirst[step] = p.first[best];
        p.stepCount[step] = p.count[best];
        p.half[step] = h;
        for (int i = p.parts; i > best + 1; --i) p.first[i] = p.first[i - 1], p.count[i] = p.count[i - 1];
        p.first[best + 1] = p.first[best] + h;
        p.count[best + 1] = p.count[best] - h;
        p.count[best] = h;
        p.steps = step + 1;
        ++p.parts;
    }
    return p;
}

// Wide nodes in the subtree of a range of `count` discs (memoised: few distinct counts).
struct NodeCounts {
    std::vector<std::pair<uint32_t, uint32_t>> memo;
    uint32_t operator()(uint32_t count) {
        for (const auto& [c, v] : memo)
            if (c == count) return v;
        const Plan p = makePlan(count);
        uint32_t v = 1;
        for (int i = 0; i < p.parts; ++i)
            if (p.count[i] > uint32_t(S)) v += (*this)(p.count[i]);
        memo.emplace_back(count, v);
        return v;
    }
};

struct Ctx {
    LoDWideBVH* t;
    NodeCounts* counts;  // read only during the build (every count was seen up front)
};

// The plan step that halves [f, f + c), or -1 when that range is one of the parts.
int planStep(const Plan& p, uint32_t f, uint32_t c) {
    for (int s = 0; s < p.steps; ++s)
        if (p.stepFirst[s] == f && p.stepCount[s] == c) return s;
    return -1;
}

// Applies the plan's steps inside d[f, f + c). Sibling ranges are disjoint, so the discs
// end in the same order as a serial replay of the steps.
void splitRange(const Plan& p, Disc* d, uint32_t f, uint32_t c) {
    const int s = planStep(p, f, c);
    if (s < 0) return;
    const uint32_t h = p.half[s];
    selectMedianByCoordinate(d + f, c, h, spreadAxis(d + f, c));
    auto left = [&] { splitRange(p, d, f, h); };
    auto right = [&] { splitRange(p, d, f + h, c - h); };
    if (c >= (1u << 18)) {
        tbb::parallel_invoke(left, right);
    } else {
        left();
        right();
    }
}

// Node `ni` over elems[first, first + count): median splits along the axis of widest
// spread as planned, children built (the large ones in parallel), their boxes and
// representatives stored in the node; returns the node's sum. Subtrees take the slots
// after their parent, depth first.
Sum buildNode(Ctx& ctx, uint32_t ni, uint32_t first, uint32_t count, int depth, bool split = true) {
    LoDWideBVH& t = *ctx.t;
    RTFACT_ASSERT(depth < LoDWideBVH::kMaxDepth, "wide LoD tree deeper than its traversal stack");
    const Plan p = makePlan(count);
    // Replay the plan on the discs: each step selects the median of one range; the
    // halves of a step are independent, so large ones are split in parallel. (split
    // false: done by the caller.)
    if (split) splitRange(p, t.elems.data() + first, 0, count);
    // Slots: children's subtrees follow this node in part order.
    uint32_t slot[K];
    uint32_t next = ni + 1;
    for (int i = 0; i < p.parts; ++i) {
        slot[i] = next;
        if (p.count[i] > uint32_t(S)) next += (*ctx.counts)(p.count[i]);
    }
    Sum kids[K];
    auto child = [&](int i) {
        if (p.count[i] <= uint32_t(S))
            kids[i] = leafBlock(t, first + p.first[i], p.count[i]);
        else
            kids[i] = buildNode(ctx, slot[i], first + p.first[i], p.count[i], depth + 1);
    };
    if (count >= 32768)
        tbb::parallel_for(0, p.parts, child);
    else
        for (int i = 0; i < p.parts; ++i) child(i);
    WideBVHNode<K>& node = t.nodes[ni];
    Sum out;
    for (int c = 0; c < K; ++c) {
        if (c >= p.parts) {
            node.clear(c);
            setRep(t, size_t(ni), c, nullptr);
            continue;
        }
        const bool leaf = p.count[c] <= uint32_t(S);
        node.set(c, kids[c].s.box, int32_t(leaf ? (first + p.first[c]) / S : slot[c]), leaf ? int32_t(p.count[c]) : 0);
        setRep(t, size_t(ni), c, &kids[c].rep);
        out.s.add(kids[c].s);
    }
    out.s.height += 1;
    out.rep = out.s.rep();
    float r = 0;
    for (int c = 0; c < p.parts; ++c) r = std::max(r, length(kids[c].rep.center - out.rep.center) + kids[c].rep.radius);
    out.rep.radius = coverMargin(std::min(r, boxCoverRadius(out.rep.center, out.s.box)));
    return out;
}

// SAH split: the representatives of node `ni`'s children from the built topology, stored
// in its slots; returns the node's sum. The top levels run in parallel (disjoint slots).
Sum summarise(LoDWideBVH& t, int32_t ni, int depth) {
    const WideBVHNode<K>& node = t.nodes[size_t(ni)];
    Sum kids[K];
    auto child = [&](int c) {
        if (node.isEmpty(c)) return;
        Sum& k = kids[c];
        if (node.isLeaf(c)) {
            const int cnt = node.count[c];
            const auto* blocks = t.blocks.data() + node.child[c];
            for (int e = 0; e < cnt; ++e) k.s.add(t.elems[size_t(blocks[e / S].id[e % S])]);
            k.s.height = 1;
            k.rep = k.s.rep();
            float r = 0;
            for (int e = 0; e < cnt; ++e) {
                const Disc& d = t.elems[size_t(blocks[e / S].id[e % S])];
                r = std::max(r, length(d.center - k.rep.center) + d.radius);
            }
            k.rep.radius = coverMargin(std::min(r, boxCoverRadius(k.rep.center, k.s.box)));
        } else {
            k = summarise(t, node.child[c], depth + 1);
        }
    };
    if (depth < 3)
        tbb::parallel_for(0, K, child);
    else
        for (int c = 0; c < K; ++c) child(c);
    Sum out;
    for (int c = 0; c < K; ++c) {
        if (node.isEmpty(c)) {
            setRep(t, size_t(ni), c, nullptr);
            continue;
        }
        setRep(t, size_t(ni), c, &kids[c].rep);
        out.s.add(kids[c].s);
    }
    out.s.height += 1;
    out.rep = out.s.rep();
    float r = 0;
    for (int c = 0; c < K; ++c)
        if (!node.isEmpty(c)) r = std::max(r, length(kids[c].rep.center - out.rep.center) + kids[c].rep.radius);
    out.rep.radius = coverMargin(std::min(r, boxCoverRadius(out.rep.center, out.s.box)));
    return out;
}

// The core's wide SAH builder (Embree-medium-like binned SAH, parallel) on the discs'
// tight bounds, leaves costed in blocks of 8; discs stay in input order.
LoDWideBVH buildSah(std::vector<Disc> discs) {
    LoDWideBVH t;
    std::vector<AABB> bounds(discs.size());
    tbb::parallel_for(size_t(0), discs.size(), [&](size_t i) { bounds[i] = discs[i].bounds(); });
    WideSAHBVHBuilder b;
    b.leafBlock = kDiscLeafBlock;
    b.maxLeafSize = 2 * kDiscLeafBlock;
    WideBVHTopology<K> topo;
    b.build(std::span<const AABB>(bounds), topo);
    using Block = DiscBlock<kDiscLeafBlock>;
    static_cast<DiscWideBVH&>(t) =
        packLeafBlocks<Block>(std::move(topo), [&](Block& blk, const uint32_t* ids, int cnt) {
            blk.fill(ids, cnt, [&](uint32_t i) -> const Disc& { return discs[i]; });
        });
    t.elems = std::move(discs);
    t.order = {};  // blocks carry the ids
    resizeHugePages(t.childReps, t.nodes.size());
    resizeHugePages(t.reps, t.nodes.size() * size_t(K));
    summarise(t, 0, 0);
    return t;
}

}  // namespace

LoDWideBVH buildLoDWideBVH(std::vector<Disc> discs, LoDWideSplit split) {
    if (discs.empty()) throw Error("", "cannot build a point tree over no points");
    if (discs.size() >= (size_t(1) << 29)) throw Error("", "too many points for one tree (limit 2^29)");
    if (split == LoDWideSplit::Sah) return buildSah(std::move(discs));
    LoDWideBVH t;
    const uint32_t n = uint32_t(discs.size());
    t.elems = std::move(discs);
    NodeCounts counts;
    const uint32_t nodes = counts(n);
    resizeHugePages(t.blocks, (n + S - 1) / S);  // left uninitialised: leafBlock fills them
    // The nodes, child summaries and representatives are value-initialised (fresh memory: on
    // VMs whose host reclaims freed pages, ~0.2 s a thread per 100 MB for the first touch)
    // while the root's median splits, which read and write only the discs, run beside it:
    // the other thread no longer waits for the first touch.
    tbb::parallel_invoke(
        [&] {
            resizeFreshHugePages(t.nodes, nodes);
            resizeFreshHugePages(t.childReps, nodes);
            resizeFreshHugePages(t.reps, size_t(nodes) * K);
        },
        [&] { splitRange(makePlan(n), t.elems.data(), 0, n); });
    Ctx ctx{&t, &counts};
    const Sum root = buildNode(ctx, 0, 0, n, 0, false);
    t.box = root.s.box;
    return t;
}

}  // namespace rtfact::points
