// Disc intersector against an analytic reference; LoD traversal at quality 0 and the
// full-detail wide BVH of disc blocks against brute force over all discs (single rays
// and packets), the wide BVH's blocks and boxes; representative discs cover
// their subtrees and are hit where full detail is; normal estimation on a plane and a sphere.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <tuple>

#include "core/render/pinhole_camera.h"
#include "points/median_select.h"
#include "points/point_prepare.h"
#include "points/point_scene.h"
#include "points/spread_axis.h"

using namespace rtfact;
using namespace rtfact::points;

namespace {

Vec3f randomUnit(std::mt19937& g) {
    std::normal_distribution<float> n;
    for (;;) {
        Vec3f v(n(g), n(g), n(g));
        if (length(v) > 1e-3f) return normalize(v);
    }
}

// Analytic reference in double: plane hit, inside test.
bool referenceHit(const Disc& d, Vec3f o, Vec3f dir, double& t) {
    const Vec3f n = d.n();
    const double den = double(dir.x) * n.x + double(dir.y) * n.y + double(dir.z) * n.z;
    if (den == 0) return false;
    t = ((double(d.center.x) - o.x) * n.x + (double(d.center.y) - o.y) * n.y + (double(d.center.z) - o.z) * n.z) / den;
    const double px = o.x + t * dir.x - d.center.x, py = o.y + t * dir.y - d.center.y,
                 pz = o.z + t * dir.z - d.center.z;
    return t > 0 && px * px + py * py + pz * pz <= double(d.radius) * d.radius;
}

template <int N>
void checkDiscIntersector(std::mt19937& g, int rounds) {
    std::uniform_real_distribution<float> u(-1, 1);
    int hits = 0, checked = 0;
    for (int r = 0; r < rounds; ++r) {
        Disc d;
        d.center = Vec3f(u(g), u(g), u(g)) * 0.3f;
        d.radius = 0.1f + 0.4f * (u(g) + 1);
        d.normal = encodeNormal(randomUnit(g));
        RayPacket<N> rays;
        for (int i = 0; i < N; ++i) {
            const Vec3f o = randomUnit(g) * 3.0f;
            const Vec3f target = d.center + Vec3f(u(g), u(g), u(g)) * d.radius;
            rays.setLane(i, o, normalize(target - o), 0.0f, kInfinity);
        }
        rays.finalize();
        DiscIntersector::Hit<N> hit;
        hit.t = rays.tMax;
        hit.id = Packet<N, int32_t>(-1);
        DiscIntersector{}.intersect<HitData::Shading>(d, 7u, rays, hit, 0);
        for (int i = 0; i < N; ++i) {
            double t;
            const Vec3f o = rays.org.lane(i), dir = rays.dir.lane(i);
            const bool ref = referenceHit(d, o, dir, t);
            // Skip rays grazing the rim, where float and double may disagree.
            const Vec3f n = d.n();
            const float tp = dot(d.center - o, n) / dot(dir, n);
            const float rim = length(o + dir * tp - d.center);
            if (std::fabs(rim - d.radius) < 1e-4f * d.radius || std::fabs(dot(dir, n)) < 1e-3f) continue;
            ++checked;
            ASSERT_EQ(ref, hit.id[i] == 7) << "lane " << i;
            if (ref) {
                ++hits;
                EXPECT_NEAR(hit.t[i], t, 1e-4 * std::max(1.0, t));
            }
        }
    }
    EXPECT_GT(hits, checked / 4);
}

}  // namespace

TEST(DiscIntersector, MatchesAnalyticReferenceSingleRay) {
    std::mt19937 g(1);
    checkDiscIntersector<1>(g, 3000);
}
TEST(DiscIntersector, MatchesAnalyticReferenceNativePacket) {
    std::mt19937 g(2);
    checkDiscIntersector<simd::kNativeWidth>(g, 300);
}
TEST(DiscIntersector, MatchesAnalyticReferencePacket64) {
    std::mt19937 g(3);
    checkDiscIntersector<64>(g, 100);
}

TEST(DiscEncoding, NormalsRoundTripWithinSmallAngle) {
    std::mt19937 g(4);
    for (int i = 0; i < 10000; ++i) {
        const Vec3f n = randomUnit(g);
        const Vec3f m = decodeNormal(encodeNormal(n));
        const double c = std::min(1.0, double(n.x) * m.x + double(n.y) * m.y + double(n.z) * m.z);
        EXPECT_LT(std::acos(c) * 180.0 / 3.141592653589793, 0.05);
    }
}

namespace {

// A random cloud: points on a sphere and in a box, mixed radii and normals.
std::vector<Disc> randomDiscs(int n, uint32_t seed) {
    std::mt19937 g(seed);
    std::uniform_real_distribution<float> u(0, 1);
    std::vector<Disc> d(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) {
        const Vec3f p = i % 2 ? randomUnit(g) : Vec3f(u(g), u(g), u(g)) * 2.0f - Vec3f(1.0f);
        d[size_t(i)].center = p;
        d[size_t(i)].radius = 0.01f + 0.06f * u(g);
        d[size_t(i)].normal = encodeNormal(i % 2 ? p : randomUnit(g));
        d[size_t(i)].rgba = packRGBA(Vec3f(u(g), u(g), u(g)), 0);
    }
    return d;
}

// n discs of radius r on the unit sphere, facing outwards (randomDiscs' colours), as scans
// are closed surfaces of overlapping discs.
std::vector<Disc> sphereDiscs(int n, uint32_t seed, float r) {
    std::vector<Disc> sphere = randomDiscs(n, seed);
    std::mt19937 g(seed + 1);
    for (Disc& d : sphere) {
        d.center = randomUnit(g);
        d.normal = encodeNormal(d.center);
        d.radius = r;
    }
    return sphere;
}

template <int N>
void checkAgainstBruteForce(const PointScene& scene, bool commonOrigin, uint32_t seed) {
    std::mt19937 g(seed);
    std::uniform_real_distribution<float> u(-1, 1);
    const auto& discs = scene.discs();
    int hits = 0;
    for (int round = 0; round < 40; ++round) {
        RayPacket<N> rays;
        const Vec3f eye = randomUnit(g) * 3.0f;
        for (int i = 0; i < N; ++i) {
            const Vec3f o = commonOrigin ? eye : Vec3f(u(g), u(g), u(g)) * 1.5f;
            const Vec3f d = commonOrigin ? normalize(Vec3f(u(g), u(g), u(g)) * 0.8f - eye) : randomUnit(g);
            rays.setLane(i, o, d, 0.0f, i % 5 == 4 ? 1.5f : kInfinity);
        }
        rays.commonOrigin = commonOrigin;
        rays.finalize();
        Mask<N> active(true);
        for (int i = 3; i < N; i += 7) active.set(i, false);  // some inactive lanes (none for N = 1)
        const auto hit = scene.intersect<N>(rays, active);
        const Mask<N> occ = scene.occluded<N>(rays, active);
        for (int i = 0; i < N; ++i) {
            if (!active[i]) continue;
            // Brute force with the same element test, single ray.
            RayPacket<1> r1 = rays.lane(i);
            r1.finalize();
            DiscIntersector::Hit<1> h1;
            h1.t = r1.tMax;
            h1.id = Packet<1, int32_t>(-1);
            for (size_t k = 0; k < discs.size(); ++k)
                DiscIntersector{}.intersect<HitData::Shading>(discs[k], uint32_t(k), r1, h1, 0);
            const bool bf = int32_t(h1.id) >= 0;
            ASSERT_EQ(bf, hit.id[i] >= 0) << "lane " << i << " round " << round;
            EXPECT_EQ(bf, bool(occ[i])) << "occlusion lane " << i;
            if (bf) {
                ++hits;
                EXPECT_EQ(float(h1.t), hit.t[i]);
            }
        }
    }
    EXPECT_GT(hits, 0);
}

}  // namespace

class LoDTraversal : public ::testing::TestWithParam<int> {};

TEST_P(LoDTraversal, QualityZeroEqualsBruteForce) {
    PointScene scene;
    LoDKdTreeBuilder b;
    b.maxLeafSize = GetParam();
    scene.accel = PointAccel::KdTree;
    scene.build(randomDiscs(3000, 11), b);
    scene.setLoD(RayCone{0.0f, 0.01f}, 0.0f);
    checkAgainstBruteForce<1>(scene, false, 21);
    checkAgainstBruteForce<1>(scene, true, 22);
    checkAgainstBruteForce<simd::kNativeWidth>(scene, true, 23);
    checkAgainstBruteForce<simd::kNativeWidth>(scene, false, 24);
    checkAgainstBruteForce<64>(scene, true, 25);
    checkAgainstBruteForce<64>(scene, false, 26);
}
INSTANTIATE_TEST_SUITE_P(LeafSizes, LoDTraversal, ::testing::Values(1, 4, 8, 16));

namespace {

// Rays from distinct origins (AO rays from hit points) through the LoD kd-tree, packed
// so that every fourth lane (lane 0 among them) starts far from the sphere of discs and
// the others just outside it, all aimed inside: lane for lane against the same ray alone.
struct CutVsAlone {
    int lanes = 0, aloneFull = 0, aloneRep = 0, coarser = 0;
};

template <int N>
void checkKdCutNoCoarserThanAlone(const PointScene& scene, uint32_t seed, CutVsAlone& st) {
    std::mt19937 g(seed);
    for (int round = 0; round < 48; ++round) {
        RayPacket<N> rays;
        for (int i = 0; i < N; ++i) {
            const Vec3f o = randomUnit(g) * (i % 4 == 0 ? 3.0f : 1.05f);
            rays.setLane(i, o, normalize(randomUnit(g) * 0.5f - o), 0.0f, kInfinity);
        }
        rays.commonOrigin = false;
        rays.finalize();
        Mask<N> active(true);
        for (int i = 3; i < N; i += 7) active.set(i, false);
        const auto hit = scene.intersect<N>(rays, active);
        for (int i = 0; i < N; ++i) {
            if (!active[i]) continue;
            const auto one = scene.intersect<1>(rays.lane(i), Mask<1>(true));
            ++st.lanes;
            if (int32_t(one.id[0]) >= 0) {
                ++st.aloneFull;
                st.coarser += hit.id[i] <= -2;
            } else if (int32_t(one.id[0]) <= -2) {
                ++st.aloneRep;
            }
        }
    }
}

}  // namespace

// A packet without a common origin is cut where its nearest live lane would be, so no
// lane gets a representative where alone it sees full detail. (The first lane's origin
// used to stand for the packet: the near lanes then hit coarse representatives right in
// front of them, the black pixels AO images of scans had at depth edges, more of them the
// larger the packet.)
TEST(LoDTraversal, DistinctOriginsAreNeverCutCoarserThanAlone) {
    PointScene scene;
    scene.accel = PointAccel::KdTree;
    scene.build(sphereDiscs(20000, 81, 0.03f));
    // cut where r <= 0.1 dist: near lanes (~0.05 away) see full detail, far ones (~2) not
    scene.setLoD(RayCone{0.0f, 0.05f}, 4.0f);
    CutVsAlone st;
    checkKdCutNoCoarserThanAlone<simd::kNativeWidth>(scene, 83, st);
    checkKdCutNoCoarserThanAlone<16>(scene, 84, st);
    checkKdCutNoCoarserThanAlone<64>(scene, 85, st);
    checkKdCutNoCoarserThanAlone<256>(scene, 86, st);
    EXPECT_GT(st.aloneFull, st.lanes / 2) << "the near lanes must see full detail alone";
    EXPECT_GT(st.aloneRep, st.lanes / 10) << "the far lanes must be cut alone";
    // Only a representative reaching outside its box may come first in another visiting
    // order: at most 0.5% of the lanes.
    EXPECT_LE(st.coarser, st.aloneFull / 200) << st.coarser << " of " << st.aloneFull;
}

// Full detail through the wide BVH of disc blocks (PointAccel::Wide): the same
// hits as brute force at every packet width.
TEST(DiscWideBVH, FullDetailEqualsBruteForce) {
    for (int n : {1, 7, 8, 9, 17, 3000})  // one partial block, one full, a block and one, three, many
        for (LoDWideSplit split : {LoDWideSplit::Sah, LoDWideSplit::Median}) {
            SCOPED_TRACE(n);
            SCOPED_TRACE(split == LoDWideSplit::Sah ? "sah" : "median");
            PointScene scene;
            scene.accel = PointAccel::Wide;
            scene.wideSplit = split;
            std::vector<Disc> discs = randomDiscs(n, 12 + uint32_t(n));
            if (n < 100)
                for (Disc& d : discs) d.radius = 0.6f;  // few discs: large, so that random rays hit some
            scene.build(discs);
            scene.setLoD(RayCone{0.0f, 0.01f}, 0.0f);
            ASSERT_TRUE(scene.isWide());
            ASSERT_FALSE(scene.wide.nodes.empty());
            checkAgainstBruteForce<1>(scene, false, 31);
            checkAgainstBruteForce<1>(scene, true, 32);
            checkAgainstBruteForce<simd::kNativeWidth>(scene, true, 33);
            checkAgainstBruteForce<simd::kNativeWidth>(scene, false, 34);
            checkAgainstBruteForce<64>(scene, true, 35);
            checkAgainstBruteForce<64>(scene, false, 36);
            checkAgainstBruteForce<256>(scene, true, 37);
            checkAgainstBruteForce<256>(scene, false, 38);
        }
}

// Builder invariants: every disc sits in exactly one block lane (padding lanes repeat the
// block's last disc), with its decoded normal and squared radius, inside the box its
// parent stores for the leaf; inner children's boxes contain their nodes' boxes.
class DiscWideBVHSplit : public ::testing::TestWithParam<LoDWideSplit> {};

TEST_P(DiscWideBVHSplit, BlocksHoldEveryDiscOnceInsideTheirBoxes) {
    const std::vector<Disc> input = randomDiscs(5000, 41);
    const LoDWideBVH w = buildLoDWideBVH(input, GetParam());
    const std::vector<Disc>& discs = w.elems;  // reordered: the same multiset
    auto key = [](const Disc& d) { return std::make_tuple(d.center.x, d.center.y, d.center.z, d.radius, d.normal); };
    std::vector<std::tuple<float, float, float, float, uint32_t>> a, b;
    for (const Disc& d : input) a.push_back(key(d));
    for (const Disc& d : discs) b.push_back(key(d));
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    EXPECT_EQ(a, b);
    if (GetParam() == LoDWideSplit::Median) {  // every leaf one block, all full but the last
        EXPECT_EQ(w.blocks.size(), (discs.size() + DiscWideBVH::kBlock - 1) / DiscWideBVH::kBlock);
    }
    constexpr int K = DiscWideBVH::arity, S = DiscWideBVH::kBlock;
    std::vector<int> seen(discs.size(), 0);
    std::vector<std::pair<int32_t, AABB>> work{{0, w.box}};
    size_t leaves = 0;
    while (!work.empty()) {
        const auto [ni, box] = work.back();
        work.pop_back();
        const auto& node = w.nodes[size_t(ni)];
        for (int c = 0; c < K; ++c) {
            if (node.isEmpty(c)) continue;
            const AABB cb = node.box(c);
            for (int a = 0; a < 3; ++a) {
                EXPECT_GE(cb.lo[a], box.lo[a]);
                EXPECT_LE(cb.hi[a], box.hi[a]);
            }
            if (!node.isLeaf(c)) {
                work.push_back({node.child[c], cb});
                continue;
            }
            ++leaves;
            const int cnt = node.count[c];
            for (int e = 0; e < cnt; ++e) {
                const auto& b = w.blocks[size_t(node.child[c] + e / S)];
                const int lane = e % S;
                const int32_t id = b.id[lane];
                ASSERT_GE(id, 0);
                ASSERT_LT(size_t(id), discs.size());
                ++seen[size_t(id)];
                const Disc& d = discs[size_t(id)];
                const Vec3f nn = d.n();
                for (int a = 0; a < 3; ++a) {
                    EXPECT_EQ(b.c[a][lane], d.center[a]);
                    EXPECT_EQ(b.n[a][lane], nn[a]);
                }
                EXPECT_EQ(b.r2[lane], d.radius * d.radius);
                const AABB db = d.bounds();
                const float eps = 1e-6f * (1.0f + maxComponent(vmax(-db.lo, db.hi)));  // last-bit rounding
                for (int a = 0; a < 3; ++a) {
                    EXPECT_GE(db.lo[a], cb.lo[a] - eps);
                    EXPECT_LE(db.hi[a], cb.hi[a] + eps);
                }
            }
            if (cnt % S) {  // padding lanes repeat the last disc
                const auto& b = w.blocks[size_t(node.child[c] + (cnt - 1) / S)];
                for (int lane = cnt % S; lane < S; ++lane) EXPECT_EQ(b.id[lane], b.id[cnt % S - 1]);
            }
        }
    }
    EXPECT_GT(leaves, discs.size() / (4 * size_t(S)));
    for (size_t i = 0; i < seen.size(); ++i) ASSERT_EQ(seen[i], 1) << "disc " << i;
}

TEST(LoDTree, RepresentativeDiscsCoverTheirSubtrees) {
    const std::vector<Disc> input = randomDiscs(5000, 31);
    PointScene scene;
    scene.accel = PointAccel::KdTree;
    scene.build(input);
    const LoDKdTree& t = scene.tree;
    ASSERT_EQ(t.elems.size(), input.size());
    EXPECT_TRUE(t.indices.empty());
    std::vector<int> seen(t.elems.size(), 0);
    // Walk the tree collecting each node's element range, then check cover and extents.
    struct Range {
        uint32_t first, count;
    };
    std::vector<Range> range(t.nodes.size());
    std::function<Range(uint32_t)> walk = [&](uint32_t node) -> Range {
        const KdNode& n = t.nodes[node];
        if (n.isLeaf()) {
            for (uint32_t i = 0; i < n.count; ++i) ++seen[n.first() + i];
            return range[node] = {n.first(), n.count};
        }
        const Range a = walk(n.left()), b = walk(n.left() + 1);
        EXPECT_EQ(a.first + a.count, b.first);  // subtrees are contiguous in leaf order
        const LoDInner& in = t.inner[LoDKdTree::innerIndex(n)];
        // The quantised child boxes contain their discs.
        for (uint32_t i = a.first; i < a.first + a.count; ++i)
            EXPECT_TRUE(in.box(0).contains(t.elems[i].bounds())) << node;
        for (uint32_t i = b.first; i < b.first + b.count; ++i)
            EXPECT_TRUE(in.box(1).contains(t.elems[i].bounds())) << node;
        const Disc& rep = in.rep;
        for (uint32_t i = a.first; i < b.first + b.count; ++i) {
            const Disc& d = t.elems[i];
            EXPECT_LE(length(d.center - rep.center) + d.radius, rep.radius) << "node " << node;
            EXPECT_TRUE(t.box.contains(d.bounds()));
        }
        EXPECT_GE(rep.level(), 2);
        return range[node] = {a.first, a.count + b.count};
    };
    walk(0);
    for (int s : seen) EXPECT_EQ(s, 1);
    // Input discs survive (reordered): same multiset of centres.
    auto key = [](const Disc& d) { return std::make_tuple(d.center.x, d.center.y, d.center.z, d.radius); };
    std::vector<std::tuple<float, float, float, float>> a, b;
    for (const Disc& d : input) a.push_back(key(d));
    for (const Disc& d : t.elems) b.push_back(key(d));
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    EXPECT_EQ(a, b);
    EXPECT_LE(t.bytesPerPoint(), 40.0);
}

namespace {

// Every inner node splits its discs at the median along its axis: the left subtree holds
// n/2 discs, none right of the split plane; the right subtree none left of it.
void checkMedianSplits(const std::vector<Disc>& input, int leafSize) {
    LoDKdTreeBuilder b;
    b.maxLeafSize = leafSize;
    const LoDKdTree t = b.build(input);
    ASSERT_EQ(t.elems.size(), input.size());
    std::vector<int> seen(t.elems.size(), 0);
    struct Range {
        uint32_t first, count;
    };
    std::function<Range(uint32_t)> walk = [&](uint32_t node) -> Range {
        const KdNode& n = t.nodes[node];
        if (n.isLeaf()) {
            EXPECT_LE(n.count, uint32_t(leafSize));
            for (uint32_t i = 0; i < n.count; ++i) ++seen[n.first() + i];
            return {n.first(), n.count};
        }
        const Range a = walk(n.left()), c = walk(n.left() + 1);
        EXPECT_EQ(a.count, (a.count + c.count) / 2) << "node " << node;
        // The prefetch hints: the left child's summary follows this one's, the right's is named.
        const KdNode& l = t.nodes[n.left()];
        const KdNode& r = t.nodes[n.left() + 1];
        if (!l.isLeaf()) {
            EXPECT_EQ(LoDKdTree::innerIndex(l), LoDKdTree::innerIndex(n) + 1) << "node " << node;
        }
        if (!r.isLeaf()) {
            EXPECT_EQ(t.inner[LoDKdTree::innerIndex(n)].rightInner, LoDKdTree::innerIndex(r)) << "node " << node;
        }
        for (uint32_t i = a.first; i < a.first + a.count; ++i) EXPECT_LE(t.elems[i].center[n.axis()], n.split);
        for (uint32_t i = c.first; i < c.first + c.count; ++i) EXPECT_GE(t.elems[i].center[n.axis()], n.split);
        return {a.first, a.count + c.count};
    };
    const Range all = walk(0);
    EXPECT_EQ(all.count, input.size());
    for (int s : seen) ASSERT_EQ(s, 1);
}

}  // namespace

TEST(LoDTree, SplitsAtTheMedianWithDistinctAndTiedCoordinates) {
    // Large and small ranges (the selection's sampled pivots, then std::nth_element).
    checkMedianSplits(randomDiscs(150000, 41), 8);
    checkMedianSplits(randomDiscs(777, 42), 1);
    // Coordinates on a coarse lattice: long runs of equal keys in every selection.
    std::vector<Disc> tied = randomDiscs(150000, 43);
    for (Disc& d : tied) d.center = Vec3f(std::round(d.center.x * 2), std::round(d.center.y * 2), d.center.z);
    checkMedianSplits(tied, 8);
    // All on one point: no split separates anything.
    std::vector<Disc> same = randomDiscs(500, 44);
    for (Disc& d : same) d.center = Vec3f(0.25f, 0.5f, 0.75f);
    checkMedianSplits(same, 4);
}

namespace {
// The discs as a sorted list of (centre, colour): equal lists, the same multiset.
std::vector<std::tuple<float, float, float, uint32_t>> sortedKeys(const std::vector<Disc>& d) {
    std::vector<std::tuple<float, float, float, uint32_t>> k;
    k.reserve(d.size());
    for (const Disc& x : d) k.emplace_back(x.center.x, x.center.y, x.center.z, x.rgba);
    std::sort(k.begin(), k.end());
    return k;
}
}  // namespace

// The parallel partition against the serial one: the same split point, everything below
// the pivot before it and nothing below after it, the same multiset of discs; with small
// chunks (so that misplaced runs span chunks and ranks) and ties, and its order
// independent of the threads (same result twice).
TEST(LoDTree, ParallelPartitionMatchesSerial) {
    for (int n : {1, 999, 100000})
        for (size_t chunk : {size_t(1), size_t(7), size_t(1000)})
            for (float pivot : {0.0f, 0.3f, 0.5f, 2.0f}) {
                std::vector<Disc> d = randomDiscs(n, uint32_t(n) + 3);
                for (size_t i = 0; i < d.size(); i += 5) d[i].center.x = 0.5f;  // ties at the pivot
                std::vector<Disc> a = d, b = d, c = d;
                const size_t j = partitionBelow(a.data(), a.size(), 0, pivot);
                ASSERT_EQ(partitionBelowParallel(b.data(), b.size(), 0, pivot, chunk), j) << n << " " << chunk;
                ASSERT_EQ(partitionBelowParallel(c.data(), c.size(), 0, pivot, chunk), j);
                for (size_t i = 0; i < b.size(); ++i) {
                    ASSERT_EQ(b[i].center.x < pivot, i < j) << n << " " << chunk << " at " << i;
                    ASSERT_EQ(b[i].center, c[i].center);
                }
                ASSERT_EQ(sortedKeys(b), sortedKeys(d));
            }
}

// The small-range rank sort against std::stable_sort (ties keep their input order) at
// every size it serves, with negative, tied and signed-zero coordinates; orderedKey
// orders like the floats.
TEST(LoDTree, RankSortMatchesStableSort) {
    std::mt19937 rng(46);
    const float special[] = {-0.0f, 0.0f, -1.5f, 1.5f, -1e30f, 1e30f, 1e-40f, -1e-40f};
    for (float a : special)
        for (float b : special)
            if (a < b) {
                ASSERT_LT(orderedKey(a), orderedKey(b)) << a << " " << b;
            }
    for (int n = 0; n <= int(kRankSortMax); ++n)
        for (int ties : {0, 4, 1}) {
            std::vector<Disc> d = randomDiscs(std::max(n, 1), uint32_t(100 + n + ties));
            d.resize(size_t(n));
            for (size_t i = 0; i < d.size(); ++i) {
                d[i].rgba = uint32_t(i);  // input position, to check the order of ties
                d[i].center.z = ties ? special[rng() % uint32_t(ties)] : d[i].center.z - 0.5f;
            }
            std::vector<Disc> want = d, got = d;
            std::stable_sort(want.begin(), want.end(), [](const Disc& x, const Disc& y) {
                return orderedKey(x.center.z) < orderedKey(y.center.z);
            });
            rankSortByCoordinate(got.data(), got.size(), 2);
            for (int i = 0; i < n; ++i) {
                ASSERT_EQ(got[size_t(i)].rgba, want[size_t(i)].rgba) << n << " " << ties << " at " << i;
                ASSERT_EQ(got[size_t(i)].center, want[size_t(i)].center);
            }
        }
}

// The selection's pivot sample sort (by rank up to 128 floats, std::sort beyond) against
// std::sort at every sample size, with tied and signed-zero values.
TEST(LoDTree, SampleSortMatchesStdSort) {
    std::mt19937 rng(47);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    const float special[] = {-0.0f, 0.0f, 2.0f, -2.0f};
    for (int n = 1; n <= 255; ++n)
        for (int ties : {0, 4, 1}) {
            std::vector<float> f(static_cast<size_t>(n));
            for (float& x : f) x = ties ? special[rng() % uint32_t(ties)] : u(rng);
            std::vector<float> want = f;
            std::sort(want.begin(), want.end());
            sortSample(f.data(), f.size());
            for (int i = 0; i < n; ++i) ASSERT_EQ(f[size_t(i)], want[size_t(i)]) << n << " " << ties << " at " << i;
        }
}

// The selection against std::nth_element: the k-th coordinate at k, nothing greater
// before it, nothing smaller after it; the same multiset of discs; with distinct,
// tied (few values) and all-equal coordinates, at every size class.
TEST(LoDTree, SelectByCoordinateMatchesNthElement) {
    std::mt19937 rng(45);
    for (int n : {1, 2, 13, 25, 100, 1000, 5000, 70000, int(kParallelPartition) + 4321})
        for (int ties : {0, 3, 1}) {
            if (n > 70000 && ties == 3)
                continue;  // (time) above the parallel threshold: the median, distinct and all-equal
            std::vector<Disc> d = randomDiscs(n, uint32_t(n + ties));
            if (ties > 0)
                for (Disc& x : d) x.center.y = float(rng() % uint32_t(ties));
            for (size_t k : {size_t(0), size_t(n / 2), size_t(n - 1)}) {
                if (n > 70000 && k != size_t(n / 2)) continue;
                std::vector<Disc> a = d;
                selectByCoordinate(a.data(), a.size(), k, 1);
                std::vector<float> want(d.size());
                for (size_t i = 0; i < d.size(); ++i) want[i] = d[i].center.y;
                std::nth_element(want.begin(), want.begin() + long(k), want.end());
                ASSERT_EQ(a[k].center.y, want[k]) << n << " " << ties << " " << k;
                for (size_t i = 0; i < k; ++i) ASSERT_LE(a[i].center.y, a[k].center.y);
                for (size_t i = k + 1; i < a.size(); ++i) ASSERT_GE(a[i].center.y, a[k].center.y);
                ASSERT_EQ(sortedKeys(a), sortedKeys(d));
            }
        }
}

// The median splits' axis: the widest spread of the range's own centres (exact up to
// kSpreadAxisSamples discs, from evenly strided ones beyond), whatever the order.
TEST(LoDTree, SpreadAxisIsTheRangesWidestSpread) {
    std::mt19937 rng(46);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int axis = 0; axis < 3; ++axis)
        for (size_t n : {size_t(2), size_t(50), kSpreadAxisSamples, size_t(100000)}) {
            // a slab: 10 wide along `axis`, 1 and 0.1 along the others
            std::vector<Disc> d(n);
            for (Disc& x : d)
                for (int a = 0; a < 3; ++a)
                    x.center[a] = u(rng) * (a == axis ? 10.0f : a == (axis + 1) % 3 ? 1.0f : 0.1f);
            // two discs at the wide axis' ends, the rest in the middle: small ranges see them
            if (n <= kSpreadAxisSamples) {
                for (Disc& x : d) x.center[axis] = 5.0f;
                d.front().center[axis] = 0.0f;
                d.back().center[axis] = 10.0f;
            }
            EXPECT_EQ(spreadAxis(d.data(), d.size()), axis) << n;
        }
    // one disc: no spread, any axis in range
    const Disc one{};
    const int a = spreadAxis(&one, 1);
    EXPECT_TRUE(a >= 0 && a < 3);
}

namespace {

struct RepHitStats {
    int repHits = 0;
    int sameSubtree = 0;  // full detail hits a disc of the representative's subtree
    int fullHits = 0;     // full detail hits anything
    int withinBound = 0;  // ... within (1 + repScale) R of the representative hit
};

// A 32 x 32 view at LoD quality 8 against the same rays at full detail: where the
// representative discs are hit.
RepHitStats checkRepresentativeHits(const std::vector<Disc>& discs) {
    PointScene scene;
    scene.accel = PointAccel::KdTree;
    scene.build(discs);
    const LoDKdTree& t = scene.tree;
    // Element range of the subtree under each inner node, by inner index.
    struct Range {
        uint32_t first = 0, count = 0;
    };
    std::vector<Range> sub(t.inner.size());
    std::function<Range(uint32_t)> walk = [&](uint32_t node) -> Range {
        const KdNode& n = t.nodes[node];
        if (n.isLeaf()) return {n.first(), n.count};
        const Range a = walk(n.left()), b = walk(n.left() + 1);
        return sub[LoDKdTree::innerIndex(n)] = {a.first, a.count + b.count};
    };
    walk(0);
    const PinholeCamera cam(fitCamera(scene.bounds(), 45.0f, 1.0f), 32, 32);
    const float repScale = 0.7f;
    RepHitStats st;
    RayPacket<64> rays;
    Mask<64> active(true);
    for (int y = 0; y < 32; y += 8)
        for (int x = 0; x < 32; x += 8) {
            Packet<64> px, py;
            for (int i = 0; i < 64; ++i) px[i] = float(x + i % 8) + 0.5f, py[i] = float(y + i / 8) + 0.5f;
            cam.generate<64>(px, py, rays);
            scene.setLoD(cam.cone(), 8.0f, repScale);
            const auto coarse = scene.intersect<64>(rays, active);
            scene.setLoD(cam.cone(), 0.0f, repScale);
            const auto full = scene.intersect<64>(rays, active);
            for (int i = 0; i < 64; ++i) {
                if (coarse.id[i] > -2) continue;
                ++st.repHits;
                const uint32_t idx = uint32_t(-coarse.id[i] - 2);
                const Disc& rep = t.inner[idx].rep;
                const float R = rep.radius;
                // On the representative disc, as the intersector scales it.
                const Vec3f p = rays.org.lane(i) + rays.dir.lane(i) * coarse.t[i];
                EXPECT_NEAR(dot(p - rep.center, rep.n()), 0.0f, 1e-4f * std::max(1.0f, R)) << "off the disc plane";
                EXPECT_LE(length(p - rep.center), repScale * R * (1.0f + 1e-4f)) << "outside the scaled disc";
                // The node's discs lie in its covering sphere (centre rep.center, radius R) and
                // the representative hit within repScale R of that centre: when full detail hits
                // one of those discs, the two hits are at most (1 + repScale) R apart on the ray.
                const float bound = (1.0f + repScale) * R * (1.0f + 1e-4f);
                const int32_t f = full.id[i];
                if (f < 0) continue;
                ++st.fullHits;
                st.withinBound += std::fabs(coarse.t[i] - full.t[i]) <= bound;
                if (uint32_t(f) >= sub[idx].first && uint32_t(f) < sub[idx].first + sub[idx].count) {
                    ++st.sameSubtree;
                    EXPECT_LE(std::fabs(coarse.t[i] - full.t[i]), bound)
                        << "representative hit at " << coarse.t[i] << ", full detail at " << full.t[i] << ", R " << R;
                }
            }
        }
    return st;
}

}  // namespace

TEST(LoDTree, CoarseQualityAnswersWithRepresentatives) {
    // Discs scattered through a volume: representatives are hit, on their discs, and
    // within the bound wherever full detail hits the same subtree.
    const RepHitStats vol = checkRepresentativeHits(randomDiscs(4000, 41));
    EXPECT_GT(vol.repHits, 0);
    EXPECT_GT(vol.sameSubtree, 0);
    // A closed surface, as scans are (discs on the unit sphere overlapping their
    // neighbours): a representative stands for the surface where full detail finds it.
    const RepHitStats surf = checkRepresentativeHits(sphereDiscs(4000, 42, 0.06f));
    EXPECT_GT(surf.repHits, 100);
    EXPECT_GE(surf.fullHits, surf.repHits * 9 / 10) << "representatives where full detail sees nothing";
    // Measured 237 of 246: the others see through a gap between representatives.
    EXPECT_GE(surf.withinBound, surf.fullHits * 9 / 10) << surf.withinBound << " of " << surf.fullHits;
}

namespace {

// Slots (node * K + child) on the path from the root to each disc of a LoD wide BVH.
std::vector<std::vector<uint32_t>> wideSlotsOfDiscs(const LoDWideBVH& w) {
    constexpr int K = LoDWideBVH::K, S = DiscWideBVH::kBlock;
    std::vector<std::vector<uint32_t>> slots(w.elems.size());
    std::function<void(int32_t, std::vector<uint32_t>&)> walk = [&](int32_t ni, std::vector<uint32_t>& path) {
        const auto& node = w.nodes[size_t(ni)];
        for (int c = 0; c < K; ++c) {
            if (node.isEmpty(c)) continue;
            path.push_back(uint32_t(ni) * K + uint32_t(c));
            if (node.isLeaf(c)) {
                for (int e = 0; e < node.count[c]; ++e)
                    slots[size_t(w.blocks[size_t(node.child[c] + e / S)].id[e % S])] = path;
            } else {
                walk(node.child[c], path);
            }
            path.pop_back();
        }
    };
    std::vector<uint32_t> path;
    walk(0, path);
    return slots;
}

// Camera rays through pixels [first, first + N) of the 32 x 32 image; with distinct
// origins, moved along the rays (distinct, same footprints roughly).
template <int N>
RayPacket<N> cameraPacket(const PinholeCamera& cam, int first, bool commonOrigin, std::mt19937& g) {
    std::uniform_real_distribution<float> u(-0.5f, 0.5f);
    Packet<N> px, py;
    for (int i = 0; i < N; ++i) px[i] = float((first + i) % 32) + 0.5f, py[i] = float((first + i) / 32 % 32) + 0.5f;
    RayPacket<N> rays;
    cam.generate<N>(px, py, rays);
    if (!commonOrigin) {
        for (int i = 0; i < N; ++i)
            rays.setLane(i, rays.org.lane(i) + rays.dir.lane(i) * (0.3f + u(g)), rays.dir.lane(i), 0.0f, kInfinity);
        rays.commonOrigin = false;
        rays.finalize();
    }
    return rays;
}

// sphereDiscs in a wide BVH.
PointScene wideSphere(int n, uint32_t seed, float r, LoDWideSplit split) {
    PointScene scene;
    scene.accel = PointAccel::Wide;
    scene.wideSplit = split;
    scene.build(sphereDiscs(n, seed, r));
    return scene;
}

// At a coarse quality, lane by lane through packets of N: nearest and any hit agree
// (the cut does not depend on the hit so far), representatives are hit on their scaled
// discs, and within (1 + repScale) R of full detail where that hits their subtree.
template <int N>
RepHitStats checkWideRepresentativeHits(const PointScene& scene, bool commonOrigin, uint32_t seed) {
    const LoDWideBVH& w = scene.wide;
    const auto slots = wideSlotsOfDiscs(w);
    const float repScale = 0.7f;
    const PinholeCamera cam(fitCamera(scene.bounds(), 45.0f, 1.0f), 32, 32);
    std::mt19937 g(seed);
    RepHitStats st;
    PointScene& sc = const_cast<PointScene&>(scene);
    for (int first = 0; first < 1024; first += N) {
        const RayPacket<N> rays = cameraPacket<N>(cam, first, commonOrigin, g);
        Mask<N> active(true);
        for (int i = 5; i < N; i += 9) active.set(i, false);
        sc.setLoD(cam.cone(), 8.0f, repScale);
        const auto coarse = scene.intersect<N>(rays, active);
        const Mask<N> occ = scene.occluded<N>(rays, active);
        sc.setLoD(cam.cone(), 0.0f, repScale);
        const auto full = scene.intersect<N>(rays, active);
        for (int i = 0; i < N; ++i) {
            if (!active[i]) continue;
            EXPECT_EQ(bool(occ[i]), coarse.id[i] != -1) << "lane " << i;
            if (coarse.id[i] > -2) continue;
            ++st.repHits;
            const uint32_t slot = uint32_t(-coarse.id[i] - 2);
            const Disc rep = w.rep(slot);
            const float R = rep.radius;
            const Vec3f p = rays.org.lane(i) + rays.dir.lane(i) * coarse.t[i];
            EXPECT_NEAR(dot(p - rep.center, rep.n()), 0.0f, 1e-4f * std::max(1.0f, R)) << "off the disc plane";
            EXPECT_LE(length(p - rep.center), repScale * R * (1.0f + 1e-4f)) << "outside the scaled disc";
            const int32_t f = full.id[i];
            if (f < 0) continue;
            ++st.fullHits;
            const float bound = (1.0f + repScale) * R * (1.0f + 1e-4f);
            st.withinBound += std::fabs(coarse.t[i] - full.t[i]) <= bound;
            const auto& path = slots[size_t(f)];
            if (std::find(path.begin(), path.end(), slot) != path.end()) {
                ++st.sameSubtree;
                EXPECT_LE(std::fabs(coarse.t[i] - full.t[i]), bound);
            }
        }
    }
    return st;
}

}  // namespace

// Builder invariants of the LoD summaries: each child's representative covers every disc
// of the child's subtree, the SoA copy in the parent matches it, its level is the
// subtree's height, and empty slots are never cut.
// The median build splits into complete subtrees and one rest: every node is full but at
// most one per level (the rest's), so the tree has about one node per K-1 blocks. 600000
// discs take the parallel median splits inside a node (ranges of 2^18 and more).
TEST(DiscWideBVHMedian, NodesAreFullButOnePerLevel) {
    constexpr int K = DiscWideBVH::arity;
    for (int n : {129, 5000, 40000, 600000}) {
        SCOPED_TRACE(n);
        const LoDWideBVH w = buildLoDWideBVH(randomDiscs(n, 51 + uint32_t(n)), LoDWideSplit::Median);
        std::vector<int> partialPerLevel;
        std::vector<std::pair<int32_t, int>> work{{0, 0}};
        while (!work.empty()) {
            const auto [ni, level] = work.back();
            work.pop_back();
            if (size_t(level) >= partialPerLevel.size()) partialPerLevel.resize(size_t(level) + 1, 0);
            const auto& node = w.nodes[size_t(ni)];
            int kids = 0;
            for (int c = 0; c < K; ++c) {
                if (node.isEmpty(c)) continue;
                ++kids;
                if (!node.isLeaf(c)) work.push_back({node.child[c], level + 1});
            }
            partialPerLevel[size_t(level)] += kids < K;
        }
        for (size_t l = 0; l < partialPerLevel.size(); ++l) EXPECT_LE(partialPerLevel[l], 1) << "level " << l;
        EXPECT_LE(w.nodes.size(), w.blocks.size() / (K - 1) + partialPerLevel.size() + 1);
    }
}

// The parallel splits work on disjoint ranges, so the build does not depend on how the
// tasks were scheduled: two builds of 600000 discs order them identically.
TEST(DiscWideBVHMedian, ParallelBuildIsDeterministic) {
    const std::vector<Disc> discs = randomDiscs(600000, 7);
    const LoDWideBVH a = buildLoDWideBVH(discs, LoDWideSplit::Median), b = buildLoDWideBVH(discs, LoDWideSplit::Median);
    ASSERT_EQ(a.elems.size(), b.elems.size());
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    size_t differ = 0;
    for (size_t i = 0; i < a.elems.size(); ++i)
        differ += a.elems[i].center != b.elems[i].center || a.elems[i].radius != b.elems[i].radius;
    EXPECT_EQ(differ, 0u);
}

TEST_P(DiscWideBVHSplit, ChildRepresentativesCoverTheirSubtrees) {
    const PointScene scene = [] {
        PointScene s;
        s.accel = PointAccel::Wide;
        s.wideSplit = GetParam();
        s.build(randomDiscs(5000, 51));
        return s;
    }();
    const LoDWideBVH& w = scene.wide;
    constexpr int K = LoDWideBVH::K;
    ASSERT_EQ(w.childReps.size(), w.nodes.size());
    ASSERT_EQ(w.reps.size(), w.nodes.size() * K);
    const auto slots = wideSlotsOfDiscs(w);
    std::vector<int> covered(w.reps.size(), 0);
    for (size_t i = 0; i < w.elems.size(); ++i) {
        ASSERT_FALSE(slots[i].empty()) << "disc " << i << " in no leaf";
        const Disc& d = w.elems[i];
        for (uint32_t slot : slots[i]) {
            // The farthest point of the disc from the representative's centre.
            const Disc rep = w.rep(slot);
            const Vec3f off = d.center - rep.center, nn = d.n();
            const float along = dot(off, nn), across = length(off - nn * along);
            EXPECT_LE(std::sqrt(along * along + (across + d.radius) * (across + d.radius)), rep.radius * (1.0f + 1e-5f))
                << "slot " << slot;
            ++covered[slot];
        }
        EXPECT_EQ(w.rep(slots[i].back()).level(), 1);  // a leaf child
    }
    for (size_t ni = 0; ni < w.nodes.size(); ++ni)
        for (int c = 0; c < K; ++c) {
            const size_t slot = ni * K + size_t(c);
            const auto& cr = w.childReps[ni];
            if (w.nodes[ni].isEmpty(c)) {
                EXPECT_EQ(cr.radius[c], kInfinity);
                EXPECT_EQ(covered[slot], 0);
                continue;
            }
            EXPECT_GT(covered[slot], 0);
            // Centre and radius come from the summaries; the normal the traversal tests is
            // the one the shading decodes from the representative's octahedral form.
            const Disc rep = w.rep(slot);
            EXPECT_TRUE(std::isfinite(rep.radius) && rep.radius > 0.0f);
            const Vec3f nn = rep.n();
            for (int a = 0; a < 3; ++a) EXPECT_EQ(cr.n[a][c], nn[a]);
            if (!w.nodes[ni].isLeaf(c)) {
                EXPECT_GE(rep.level(), 2);
            }
        }
}

TEST_P(DiscWideBVHSplit, CoarseQualityAnswersWithRepresentatives) {
    PointScene vol;
    vol.accel = PointAccel::Wide;
    vol.wideSplit = GetParam();
    vol.build(randomDiscs(4000, 41));
    PointScene surf = wideSphere(4000, 42, 0.06f, GetParam());
    for (bool common : {true, false}) {
        SCOPED_TRACE(common);
        const RepHitStats a = checkWideRepresentativeHits<1>(vol, common, 61);
        EXPECT_GT(a.repHits, 0);
        EXPECT_GT(a.sameSubtree, 0);
        checkWideRepresentativeHits<simd::kNativeWidth>(vol, common, 62);
        checkWideRepresentativeHits<64>(vol, common, 63);
        checkWideRepresentativeHits<256>(vol, common, 64);
        const RepHitStats b = checkWideRepresentativeHits<64>(surf, common, 65);
        EXPECT_GT(b.repHits, 100);
        EXPECT_GE(b.fullHits, b.repHits * 9 / 10) << "representatives where full detail sees nothing";
        EXPECT_GE(b.withinBound, b.fullHits * 9 / 10) << b.withinBound << " of " << b.fullHits;
    }
}

// Packets go through the wide BVH a native chunk (LoD on AVX2: a group of 16 lanes) at
// a time, sharing the levels above the cut, yet every ray keeps its own cut (its footprint
// at its own entry into a child's box): lane for lane, a packet finds what the ray finds
// alone, nearest and any hit, full detail and coarse cuts, common and distinct origins,
// partial packets. The one legitimate difference: a representative disc may reach outside
// its child's box, so which of two overlapping representatives is found first can depend
// on the visiting order. A cut per chunk (one footprint for all its rays) would change
// which representative answers far more lanes and fail here.
struct PacketVsSingle {
    int lanes = 0, same = 0, repOnly = 0, reps = 0;
};

template <int N>
void checkPacketsAsSingleRays(PointScene& scene, float quality, bool commonOrigin, uint32_t seed, PacketVsSingle& st) {
    const PinholeCamera cam(fitCamera(scene.bounds(), 45.0f, 1.0f), 32, 32);
    scene.setLoD(cam.cone(), quality);
    std::mt19937 g(seed);
    for (int first = 0; first < 32 * 32; first += N) {
        const RayPacket<N> rays = cameraPacket<N>(cam, first, commonOrigin, g);
        Mask<N> active(true);
        for (int i = 3; i < N; i += 7) active.set(i, false);
        const auto hit = scene.intersect<N>(rays, active);
        const Mask<N> occ = scene.occluded<N>(rays, active);
        for (int i = 0; i < N; ++i) {
            if (!active[i]) {
                EXPECT_EQ(hit.id[i], -1);
                EXPECT_FALSE(occ[i]);
                continue;
            }
            const auto one = scene.intersect<1>(rays.lane(i), Mask<1>(true));
            const int32_t id1 = int32_t(one.id[0]);
            ++st.lanes;
            st.reps += hit.id[i] <= -2;
            EXPECT_EQ(bool(occ[i]), hit.id[i] != -1) << "lane " << i;
            if (id1 == hit.id[i]) {
                ++st.same;
                if (id1 != -1) {
                    EXPECT_NEAR(hit.t[i], float(one.t[0]), 1e-5f * std::max(1.0f, hit.t[i]));
                }
            } else if (id1 <= -2 && hit.id[i] <= -2) {
                ++st.repOnly;
            }
        }
    }
}

TEST_P(DiscWideBVHSplit, PacketsAnswerAsSingleRays) {
    PointScene scene = wideSphere(20000, 71, 0.03f, GetParam());
    for (float q : {0.0f, 4.0f, 16.0f}) {
        SCOPED_TRACE(q);
        PacketVsSingle st;
        for (bool common : {true, false}) {
            checkPacketsAsSingleRays<simd::kNativeWidth>(scene, q, common, 73, st);
            checkPacketsAsSingleRays<16>(scene, q, common, 76, st);  // the engine's point packets
            checkPacketsAsSingleRays<64>(scene, q, common, 74, st);
            checkPacketsAsSingleRays<256>(scene, q, common, 75, st);
        }
        // Rim cases in the last bits of the SIMD arithmetic: at most 0.1% of the lanes;
        // representatives found in another order: at most 1%.
        const int other = st.lanes - st.same - st.repOnly;
        EXPECT_LE(other, st.lanes / 1000) << other << " of " << st.lanes;
        EXPECT_LE(st.repOnly, st.lanes / 100) << st.repOnly << " of " << st.lanes;
        if (q == 0.0f) {
            EXPECT_EQ(st.reps, 0);
        } else {
            EXPECT_GT(st.reps, st.lanes / 10) << "the cut must answer many lanes";
        }
    }
}

INSTANTIATE_TEST_SUITE_P(Splits, DiscWideBVHSplit, ::testing::Values(LoDWideSplit::Sah, LoDWideSplit::Median));

TEST(NormalEstimation, PlaneWithinOneDegree) {
    std::mt19937 g(5);
    std::uniform_real_distribution<float> u(-1, 1);
    std::vector<Vec3f> pts;
    const Vec3f n = normalize(Vec3f(-0.3f, -0.2f, 1.0f));  // plane z = 0.3x + 0.2y
    for (int i = 0; i < 4000; ++i) {
        const float x = u(g), y = u(g);
        pts.push_back({x, y, 0.3f * x + 0.2f * y});
    }
    const Vec3f vp(0, 0, 5);
    const auto normals = estimateNormals(pts, 16, vp, 2);
    for (size_t i = 0; i < pts.size(); ++i) {
        EXPECT_GT(dot(normals[i], n), std::cos(1.0f * 3.14159265f / 180.0f)) << i;
        EXPECT_GE(dot(normals[i], vp - pts[i]), 0.0f);
    }
}

TEST(NormalEstimation, SphereWithinThreeDegrees) {
    std::mt19937 g(6);
    std::vector<Vec3f> pts;
    for (int i = 0; i < 20000; ++i) pts.push_back(randomUnit(g));
    const Vec3f vp(0, 0, 0);  // inside: every normal must face the centre
    const auto normals = estimateNormals(pts, 16, vp, 2);
    for (size_t i = 0; i < pts.size(); ++i) {
        EXPECT_GT(std::fabs(dot(normals[i], pts[i])), std::cos(3.0f * 3.14159265f / 180.0f)) << i;
        EXPECT_LT(dot(normals[i], pts[i]), 0.0f);
    }
}

TEST(Spacing, GridSpacingIsFound) {
    std::vector<Vec3f> pts;
    for (int y = 0; y < 50; ++y)
        for (int x = 0; x < 50; ++x) pts.push_back({float(x) * 0.1f, float(y) * 0.1f, 0.0f});
    const auto s = neighbourSpacing(pts, 4);
    for (size_t i = 0; i < pts.size(); ++i) {
        const int x = int(i % 50), y = int(i / 50);
        if (x > 0 && x < 49 && y > 0 && y < 49) {
            EXPECT_NEAR(s[i], 0.1f, 1e-4f);
        }
    }
}
