// LoDKdTreeBuilder: see lod_kdtree.h.
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>

#include "core/util/error.h"
#include "core/util/huge_pages.h"
#include "points/lod_kdtree.h"
#include "points/lod_rep.h"
#include "points/median_select.h"
#include "points/spread_axis.h"

namespace rtfact::points {

namespace {

// Area-weighted sums of a subtree and its representative disc.
struct Agg {
    LoDRepSum s;
    Disc rep;
};

struct Ctx {
    LoDKdTree* tree;
    Disc* base;
    size_t leafSize;
    std::vector<std::pair<size_t, uint32_t>> desc;  // subtree node counts (without the root) per size

    uint32_t descendants(size_t n) const {
        for (const auto& [k, v] : desc)
            if (k == n) return v;
        return 0;
    }
    uint32_t computeDesc(size_t n) {
        for (const auto& [k, v] : desc)
            if (k == n) return v;
        const uint32_t v = n <= leafSize ? 0u : 2u + computeDesc(n / 2) + computeDesc(n - n / 2);
        desc.emplace_back(n, v);
        return v;
    }
};

// Outward rounding with one step of margin: the decoder may round differently (FMA).
void quantiseChildBox(LoDInner& in, int child, const AABB& b) {
    const float step = in.rep.radius * (2.0f / 255.0f);
    const Vec3f base = in.rep.center - Vec3f(in.rep.radius);
    for (int a = 0; a < 3; ++a) {
        const float lo = std::floor((b.lo[a] - base[a]) / step) - 1.0f;
        const float hi = std::ceil((b.hi[a] - base[a]) / step) + 1.0f;
        in.childBox[child][a] = uint8_t(std::clamp(lo, 0.0f, 255.0f));
        in.childBox[child][3 + a] = uint8_t(std::clamp(hi, 0.0f, 255.0f));
    }
}

// selectedAxis >= 0: d is already split at its median along that axis (the root, split
// while the node arrays are first touched).
Agg buildNode(Ctx& ctx, Disc* d, size_t n, uint32_t slot, uint32_t next, int selectedAxis = -1) {
    LoDKdTree& t = *ctx.tree;
    Agg a;
    if (n <= ctx.leafSize) {
        t.nodes[slot] = KdNode::leaf(uint32_t(d - ctx.base), uint32_t(n));
        for (size_t i = 0; i < n; ++i) a.s.add(d[i]);
        a.s.height = 1;
        Disc rep = a.s.rep();
        float r = 0;
        for (size_t i = 0; i < n; ++i) r = std::max(r, length(d[i].center - rep.center) + d[i].radius);
        rep.radius = coverMargin(std::min(r, boxCoverRadius(rep.center, a.s.box)));
        a.rep = rep;
        return a;
    }
    const int axis = selectedAxis >= 0 ? selectedAxis : spreadAxis(d, n);
    const size_t half = n / 2;
    if (selectedAxis < 0) selectMedianByCoordinate(d, n, half, axis);
    const float split = d[half].center[axis];
    const uint32_t left = next;
    t.nodes[slot] = KdNode::inner(axis, split, left);
    const uint32_t lnext = next + 2, rnext = lnext + ctx.descendants(half);
    Agg la, ra;
    auto bl = [&] { la = buildNode(ctx, d, half, left, lnext); };
    auto br = [&] { ra = buildNode(ctx, d + half, n - half, left + 1, rnext); };
    if (n >= 8192)
        tbb::parallel_invoke(bl, br);
    else {
        bl();
        br();
    }
    LoDInner& in = t.inner[(left - 1) / 2];
    in.rightInner = n - half > ctx.leafSize ? (rnext - 1) / 2 : (left - 1) / 2;
    a.s.add(la.s);
    a.s.add(ra.s);
    a.s.height += 1;
    Disc rep = a.s.rep();
    const Disc &lr = la.rep, &rr = ra.rep;
    const float r =
        std::min(std::max(length(lr.center - rep.center) + lr.radius, length(rr.center - rep.center) + rr.radius),
                 boxCoverRadius(rep.center, a.s.box));
    rep.radius = coverMargin(r);
    in.rep = rep;
    quantiseChildBox(in, 0, la.s.box);
    quantiseChildBox(in, 1, ra.s.box);
    a.rep = rep;
    return a;
}

}  // namespace

LoDKdTree LoDKdTreeBuilder::build(std::vector<Disc> discs) const {
    LoDKdTree t;
    if (discs.empty()) throw Error("", "cannot build a point tree over no points");
    if (discs.size() >= (size_t(1) << 29)) throw Error("", "too many points for one tree (limit 2^29)");
    Ctx ctx{&t, discs.data(), size_t(std::max(1, maxLeafSize)), {}};
    const uint32_t total = 1 + ctx.computeDesc(discs.size());
    // The node arrays are value-initialised (fresh memory, slow to touch first on VMs whose
    // host reclaims freed pages) while the root's median selection, which touches only the
    // discs, runs beside it.
    const size_t n = discs.size();
    const int rootAxis = n > ctx.leafSize ? spreadAxis(discs.data(), n) : -1;
    tbb::parallel_invoke(
        [&] {
            resizeFreshHugePages(t.nodes, total);
            resizeFreshHugePages(t.inner, (total - 1) / 2);
        },
        [&] {
            if (rootAxis >= 0) selectMedianByCoordinate(discs.data(), n, n / 2, rootAxis);
        });
    const Agg a = buildNode(ctx, discs.data(), n, 0, 1, rootAxis);
    t.box = a.s.box;
    const Vec3f pad = Vec3f(1e-6f * (maxComponent(vmax(-a.s.box.lo, a.s.box.hi)) + maxComponent(a.s.box.extent())));
    t.box.lo -= pad;
    t.box.hi += pad;
    t.elems = std::move(discs);
    return t;
}

}  // namespace rtfact::points
