// LoDKdTreeBuilder: see lod_kdtree.h.
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>

#include "core/util/error.h"
#include "core/util/huge_pages.h"
#include "points/lod_kdtree.h"

namespace rtfact::points {

namespace {

// Area-weighted sums of a subtree, from which its representative disc is made.
struct Agg {
    double w = 0;
    double c[3] = {0, 0, 0};
    double n[3] = {0, 0, 0};
    double col[3] = {0, 0, 0};
    AABB box;        // bounds of all discs
    int height = 0;  // leaf = 1
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

// Radius of the sphere around c that holds the box b: the farthest corner. Often much
// tighter than covering the children's spheres, whose slack compounds level by level.
float boxCoverRadius(Vec3f c, const AABB& b) { return length(vmax(b.hi - c, c - b.lo)); }

Disc makeRep(const Agg& a, float radius) {
    Disc r;
    const double iw = a.w > 0 ? 1.0 / a.w : 0.0;
    r.center = Vec3f(float(a.c[0] * iw), float(a.c[1] * iw), float(a.c[2] * iw));
    Vec3f n(float(a.n[0]), float(a.n[1]), float(a.n[2]));
    const float len = length(n);
    r.normal = encodeNormal(len > 0 ? n / len : Vec3f(0, 0, 1));
    r.radius = radius;
    r.rgba = packRGBA(Vec3f(float(a.col[0] * iw), float(a.col[1] * iw), float(a.col[2] * iw)),
                      uint8_t(std::min(a.height, 255)));
    return r;
}

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

// Branch-free Lomuto partition: discs whose coordinate is below `pivot` to the front.
// Every step swaps unconditionally (a big disc with itself or with the first big one),
// so there is no data-dependent branch to mispredict; returns the number below.
size_t partitionBelow(Disc* d, size_t n, int axis, float pivot) {
    size_t j = 0;
    for (size_t i = 0; i < n; ++i) {
        const Disc x = d[i];
        const bool below = x.center[axis] < pivot;
        d[i] = d[j];
        d[j] = x;
        j += below;
    }
    return j;
}

// nth_element by coordinate with the postcondition of std::nth_element. std::nth_element's
// branchy partitions were ~80% of the build; here each round partitions around a pivot
// estimated from a stratified sample at the target rank (Floyd-Rivest style), so the
// range shrinks to about a tenth per pass and the passes are branch-free.
void selectByCoordinate(Disc* d, size_t n, size_t k, int axis) {
    auto less = [axis](const Disc& x, const Disc& y) { return x.center[axis] < y.center[axis]; };
    while (n > 12) {
        const size_t samples = std::min<size_t>(31, n / 4);
        float sample[31];
        for (size_t s = 0; s < samples; ++s) sample[s] = d[(2 * s + 1) * n / (2 * samples)].center[axis];
        std::sort(sample, sample + samples);
        // Pivot just above the target's estimated rank, so that k usually falls left.
        const size_t r = std::min(samples - 1, k * samples / n + (samples > 8 ? 2 : 1));
        const size_t j = partitionBelow(d, n, axis, sample[r]);
        if (k < j) {
            n = j;
        } else if (j > 0) {
            d += j;
            k -= j;
            n -= j;
        } else {
            break;  // no disc below the pivot (ties): let std::nth_element finish
        }
    }
    std::nth_element(d, d + k, d + n, less);
}

constexpr size_t kFastSelect = size_t(1) << 16;

Agg buildNode(Ctx& ctx, Disc* d, size_t n, AABB cell, uint32_t slot, uint32_t next) {
    LoDKdTree& t = *ctx.tree;
    Agg a;
    if (n <= ctx.leafSize) {
        t.nodes[slot] = KdNode::leaf(uint32_t(d - ctx.base), uint32_t(n));
        for (size_t i = 0; i < n; ++i) {
            const double w = double(d[i].radius) * d[i].radius + 1e-30;
            const Vec3f nn = d[i].n(), col = unpackRGB(d[i].rgba);  // decoded once: bounds from nn below
            for (int k = 0; k < 3; ++k) {
                a.c[k] += w * d[i].center[k];
                a.n[k] += w * nn[k];
                a.col[k] += w * col[k];
            }
            a.w += w;
            a.box.extend(Disc::bounds(d[i].center, d[i].radius, nn));
        }
        a.height = 1;
        Disc rep = makeRep(a, 0.0f);
        float r = 0;
        for (size_t i = 0; i < n; ++i) r = std::max(r, length(d[i].center - rep.center) + d[i].radius);
        r = std::min(r, boxCoverRadius(rep.center, a.box));
        rep.radius = r * 1.002f + 1e-7f;  // margin covers the padding of Disc::bounds()
        a.rep = rep;
        return a;
    }
    const int axis = cell.maxAxis();
    const size_t half = n / 2;
    // Below kFastSelect, std::nth_element as before: which of several discs with the same
    // coordinate go left is its arbitrary choice, and the scanned-cloud LoD references
    // (quantised coordinates, many ties) bake that choice in.
    if (n > kFastSelect)
        selectByCoordinate(d, n, half, axis);
    else
        std::nth_element(d, d + half, d + n,
                         [axis](const Disc& x, const Disc& y) { return x.center[axis] < y.center[axis]; });
    const float split = d[half].center[axis];
    AABB lcell = cell, rcell = cell;
    lcell.hi[axis] = split;
    rcell.lo[axis] = split;
    const uint32_t left = next;
    t.nodes[slot] = KdNode::inner(axis, split, left);
    const uint32_t lnext = next + 2, rnext = lnext + ctx.descendants(half);
    Agg la, ra;
    auto bl = [&] { la = buildNode(ctx, d, half, lcell, left, lnext); };
    auto br = [&] { ra = buildNode(ctx, d + half, n - half, rcell, left + 1, rnext); };
    if (n >= 8192)
        tbb::parallel_invoke(bl, br);
    else {
        bl();
        br();
    }
    LoDInner& in = t.inner[(left - 1) / 2];
    a.w = la.w + ra.w;
    for (int k = 0; k < 3; ++k) {
        a.c[k] = la.c[k] + ra.c[k];
        a.n[k] = la.n[k] + ra.n[k];
        a.col[k] = la.col[k] + ra.col[k];
    }
    a.box = merge(la.box, ra.box);
    a.height = std::max(la.height, ra.height) + 1;
    Disc rep = makeRep(a, 0.0f);
    const Disc &lr = la.rep, &rr = ra.rep;
    const float r =
        std::min(std::max(length(lr.center - rep.center) + lr.radius, length(rr.center - rep.center) + rr.radius),
                 boxCoverRadius(rep.center, a.box));
    rep.radius = r * 1.002f + 1e-7f;  // margin covers the padding of Disc::bounds()
    in.rep = rep;
    quantiseChildBox(in, 0, la.box);
    quantiseChildBox(in, 1, ra.box);
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
    resizeFreshHugePages(t.nodes, total);
    resizeFreshHugePages(t.inner, (total - 1) / 2);
    AABB cell;
    for (const Disc& d : discs) cell.extend(d.center);
    const Agg a = buildNode(ctx, discs.data(), discs.size(), cell, 0, 1);
    t.box = a.box;
    const Vec3f pad = Vec3f(1e-6f * (maxComponent(vmax(-a.box.lo, a.box.hi)) + maxComponent(a.box.extent())));
    t.box.lo -= pad;
    t.box.hi += pad;
    t.elems = std::move(discs);
    return t;
}

}  // namespace rtfact::points
