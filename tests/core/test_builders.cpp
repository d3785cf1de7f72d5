// Builder invariants: every element reachable exactly once (BVH) / at least once where
// it overlaps the cell (kd-tree), children inside parents, SAH no worse than a median split.
#include <gtest/gtest.h>

#include <cstring>
#include <functional>
#include <random>

#include "core/accel/box4.h"
#include "core/accel/median_bvh_builder.h"
#include "core/accel/sah_bvh_builder.h"
#include "core/accel/sah_kdtree_builder.h"
#include "core/geometry/sphere.h"

using namespace rtfact;

namespace {

std::vector<AABB> randomBoxes(int n, uint32_t seed, bool clustered) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<AABB> b(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) {
        Vec3f c{u(rng) * 100, u(rng) * 100, u(rng) * 100};
        if (clustered && i % 3) c = c * 0.05f + Vec3f(50.0f);
        const Vec3f e{u(rng) * 2 + 0.01f, u(rng) * 2 + 0.01f, u(rng) * 0.01f};
        b[size_t(i)] = {c - e, c + e};
    }
    return b;
}

void checkBVH(const BVHTopology& t, std::span<const AABB> boxes, int maxLeaf) {
    ASSERT_FALSE(t.nodes.empty());
    std::vector<int> seen(boxes.size(), 0);
    std::vector<bool> nodeSeen(t.nodes.size(), false);
    std::function<void(uint32_t, int)> walk = [&](uint32_t ni, int depth) {
        ASSERT_LT(ni, t.nodes.size());
        ASSERT_FALSE(nodeSeen[ni]) << "node reached twice";
        nodeSeen[ni] = true;
        ASSERT_LT(depth, 100);
        const BVHNode& n = t.nodes[ni];
        if (n.isLeaf()) {
            EXPECT_LE(n.count(), std::max(maxLeaf, 1) * 8);  // forced splits keep leaves small
            for (int i = 0; i < n.count(); ++i) {
                const uint32_t e = t.order[size_t(n.ofs + i)];
                seen[e]++;
                EXPECT_TRUE(n.box().contains(boxes[e], 1e-4f)) << "element outside its leaf";
            }
            return;
        }
        for (int c = 0; c < 2; ++c) {
            EXPECT_TRUE(n.box().contains(t.nodes[size_t(n.ofs + c)].box(), 1e-4f)) << "child outside parent";
            walk(uint32_t(n.ofs + c), depth + 1);
        }
    };
    walk(0, 0);
    for (size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], 1) << "element " << i;
    for (size_t i = 0; i < nodeSeen.size(); ++i) EXPECT_TRUE(nodeSeen[i]) << "unreachable node " << i;
}

}  // namespace

TEST(Builders, SAHBVHInvariantsAndQuality) {
    for (bool clustered : {false, true}) {
        const auto boxes = randomBoxes(20000, 5, clustered);
        BVHTopology sah, median;
        SAHBVHBuilder{4}.build(boxes, sah);
        MedianBVHBuilder{4}.build(boxes, median);
        checkBVH(sah, boxes, 4);
        checkBVH(median, boxes, 4);
        EXPECT_LE(sahCost(sah), sahCost(median)) << "SAH build worse than a median split";
    }
}

TEST(Builders, DegenerateInputs) {
    std::vector<AABB> same(1000, AABB{{1, 1, 1}, {2, 2, 2}});
    BVHTopology t;
    SAHBVHBuilder{4}.build(same, t);
    checkBVH(t, same, 4);
    std::vector<AABB> one{AABB{{0, 0, 0}, {0, 0, 0}}};
    SAHBVHBuilder{}.build(one, t);
    checkBVH(t, one, 1);
    std::vector<AABB> none;
    SAHBVHBuilder{}.build(none, t);
    EXPECT_TRUE(t.nodes.empty());
}

TEST(Builders, SAHKdTreeInvariants) {
    const auto boxes = randomBoxes(5000, 9, true);
    KdTopology t;
    SAHKdTreeBuilder{}.build(boxes, t);
    ASSERT_FALSE(t.nodes.empty());
    std::vector<int> seen(boxes.size(), 0);
    // Every element must be listed in every leaf whose cell its bounds overlap with
    // positive volume, and only in leaves it touches.
    std::function<void(uint32_t, AABB, int)> walk = [&](uint32_t ni, AABB cell, int depth) {
        ASSERT_LT(depth, 200);
        const KdNode& n = t.nodes[ni];
        if (n.isLeaf()) {
            std::vector<bool> inLeaf(boxes.size(), false);
            for (uint32_t i = 0; i < n.count; ++i) {
                const uint32_t e = t.indices[n.first() + i];
                inLeaf[e] = true;
                seen[e]++;
                const AABB x = intersection(cell, boxes[e]);
                EXPECT_FALSE(x.isEmpty()) << "element in a leaf it does not touch";
            }
            for (size_t e = 0; e < boxes.size(); ++e) {
                const AABB x = intersection(cell, boxes[e]);
                const Vec3f d = x.extent();
                if (!x.isEmpty() && d.x > 0 && d.y > 0 && d.z > 0) {
                    EXPECT_TRUE(inLeaf[e]) << "missing element " << e;
                }
            }
            return;
        }
        EXPECT_GT(n.split, cell.lo[n.axis()]);
        EXPECT_LT(n.split, cell.hi[n.axis()]);
        AABB l = cell, r = cell;
        l.hi[n.axis()] = n.split;
        r.lo[n.axis()] = n.split;
        walk(n.left(), l, depth + 1);
        walk(n.left() + 1, r, depth + 1);
    };
    walk(0, t.box, 0);
    for (size_t i = 0; i < seen.size(); ++i) EXPECT_GE(seen[i], 1) << "element " << i << " unreachable";
}

// The builders keep an element id in lo's fourth lane; the centroid they bin by must not
// carry it (ids read as denormals or NaNs: a slow path for the add, and garbage in lane 3).
TEST(Builders, DoubledCentroidIgnoresTheIdLane) {
    for (uint32_t id : {1u, 12345u, (1u << 23) - 1u, 0x7f800001u, 0xffffffffu}) {
        alignas(16) float lo[4] = {-1.5f, 2.0f, 1e-3f, 0.0f}, hi[4] = {0.5f, 3.0f, 4.0f, 0.0f};
        std::memcpy(&lo[3], &id, 4);
        alignas(16) float c[4];
        _mm_store_ps(c, doubledCentroid(_mm_load_ps(lo), _mm_load_ps(hi)));
        for (int a = 0; a < 3; ++a) EXPECT_EQ(c[a], lo[a] + hi[a]) << "id " << id;
        uint32_t bits;
        std::memcpy(&bits, &c[3], 4);
        EXPECT_EQ(bits, 0u) << "id " << id;
    }
}
