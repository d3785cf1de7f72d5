// BVH and kd-tree traversal against brute force, for single rays and packets, nearest
// hit and occlusion, common and distinct origins.
#include <gtest/gtest.h>

#include <random>

#include "core/accel/bvh_intersector.h"
#include "core/accel/kdtree_intersector.h"
#include "core/accel/median_bvh_builder.h"
#include "core/accel/sah_bvh_builder.h"
#include "core/accel/sah_kdtree_builder.h"
#include "core/accel/wide_bvh.h"
#include "core/geometry/sphere.h"

using namespace rtfact;

namespace {

std::vector<Sphere> randomSpheres(int n, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> pos(-10.0f, 10.0f), rad(0.05f, 0.8f);
    std::vector<Sphere> s(n);
    for (auto& x : s) x = {{pos(rng), pos(rng), pos(rng)}, rad(rng)};
    return s;
}

// Nearest hit by testing every sphere with the single-ray intersector.
std::pair<float, int> bruteForce(const std::vector<Sphere>& spheres, const RayPacket<1>& ray) {
    SphereIntersector::Hit<1> hit;
    hit.t = ray.tMax;
    hit.id = -1;
    for (size_t i = 0; i < spheres.size(); ++i)
        SphereIntersector{}.intersect<HitData::Shading>(spheres[i], uint32_t(i), ray, hit, 0);
    return {float(hit.t), int(hit.id)};
}

template <int N>
RayPacket<N> makeRays(std::mt19937& rng, bool commonOrigin, bool coherent) {
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    RayPacket<N> r;
    const Vec3f o0{u(rng) * 15, u(rng) * 15, 25.0f};
    const Vec3f target{u(rng) * 8, u(rng) * 8, u(rng) * 8};
    for (int i = 0; i < N; ++i) {
        const Vec3f o = commonOrigin ? o0 : Vec3f{u(rng) * 15, u(rng) * 15, u(rng) * 15 + 12.0f};
        const Vec3f d = coherent ? normalize(target + Vec3f(u(rng), u(rng), u(rng)) * 2.0f - o)
                                 : normalize(Vec3f{u(rng), u(rng), u(rng)});
        r.setLane(i, o, d, 0.0f, u(rng) > 0.8f ? 20.0f : kInfinity);
    }
    r.commonOrigin = commonOrigin;
    r.finalize();
    return r;
}

template <int N, class Accel, class Isect>
void checkAgainstBruteForce(const Accel& accel, const Isect& isect, const std::vector<Sphere>& spheres) {
    std::mt19937 rng(1234 + N);
    int hits = 0;
    for (int iter = 0; iter < 60; ++iter) {
        const bool co = iter % 2 == 0, coherent = iter % 3 != 0;
        const RayPacket<N> rays = co ? makeRays<N>(rng, true, coherent) : makeRays<N>(rng, false, coherent);
        Mask<N> active(true);
        for (int i = 0; i < N; ++i)
            if ((iter + i) % 7 == 3) active.set(i, false);
        typename Isect::template Hit<N> hit;
        if (co)
            isect.template intersect<true, HitData::Shading>(accel, rays, hit, active);
        else
            isect.template intersect<false, HitData::Shading>(accel, rays, hit, active);
        const Mask<N> occ = co ? isect.template occluded<true>(accel, rays, active)
                               : isect.template occluded<false>(accel, rays, active);
        for (int i = 0; i < N; ++i) {
            if (!active[i]) {
                EXPECT_EQ(hit.id[i], -1);
                EXPECT_FALSE(occ[i]);
                continue;
            }
            const auto [t, id] = bruteForce(spheres, rays.lane(i));
            // Coincident elements may tie: then any of them is right, at the same distance.
            ASSERT_EQ(hit.id[i] >= 0, id >= 0) << "lane " << i << " iter " << iter;
            if (id >= 0) {
                EXPECT_NEAR(hit.t[i], t, 1e-4f * std::max(1.0f, t));
                if (hit.id[i] != id) {
                    EXPECT_EQ(spheres[hit.id[i]].center, spheres[id].center);
                }
                ++hits;
            }
            EXPECT_EQ(occ[i], id >= 0) << "lane " << i << " iter " << iter;
        }
    }
    EXPECT_EQ(hits > 0, !spheres.empty());
}

template <class Accel, class Isect>
void checkAllSizes(const Accel& accel, const Isect& isect, const std::vector<Sphere>& s) {
    checkAgainstBruteForce<1>(accel, isect, s);
    checkAgainstBruteForce<simd::kNativeWidth>(accel, isect, s);
    checkAgainstBruteForce<64>(accel, isect, s);
    checkAgainstBruteForce<256>(accel, isect, s);
}

}  // namespace

TEST(Traversal, SAHBVHMatchesBruteForce) {
    const auto s = randomSpheres(3000, 1);
    const auto bvh = buildBVH<Sphere>(SAHBVHBuilder{4}, s);
    checkAllSizes(bvh, BVHIntersector<SphereIntersector>{}, s);
}

TEST(Traversal, MedianBVHMatchesBruteForce) {
    const auto s = randomSpheres(500, 2);
    const auto bvh = buildBVH<Sphere>(MedianBVHBuilder{}, s);
    checkAllSizes(bvh, BVHIntersector<SphereIntersector>{}, s);
}

TEST(Traversal, KdTreeMatchesBruteForce) {
    const auto s = randomSpheres(2000, 3);
    const auto tree = buildKdTree<Sphere>(SAHKdTreeBuilder{}, s);
    checkAllSizes(tree, KdTreeIntersector<SphereIntersector>{}, s);
}

TEST(Traversal, EmptyAndSingleElement) {
    std::vector<Sphere> none;
    const auto bvh = buildBVH<Sphere>(SAHBVHBuilder{}, none);
    const auto tree = buildKdTree<Sphere>(SAHKdTreeBuilder{}, none);
    checkAgainstBruteForce<1>(bvh, BVHIntersector<SphereIntersector>{}, none);
    checkAgainstBruteForce<64>(tree, KdTreeIntersector<SphereIntersector>{}, none);
    std::vector<Sphere> one{{{0, 0, 0}, 5.0f}};
    const auto bvh1 = buildBVH<Sphere>(SAHBVHBuilder{}, one);
    const auto tree1 = buildKdTree<Sphere>(SAHKdTreeBuilder{}, one);
    checkAllSizes(bvh1, BVHIntersector<SphereIntersector>{}, one);
    checkAllSizes(tree1, KdTreeIntersector<SphereIntersector>{}, one);
}

TEST(Traversal, IdenticalElements) {
    // Many coincident spheres: builders must terminate and traversal still finds them.
    std::vector<Sphere> s(300, Sphere{{1, 2, 3}, 1.0f});
    s.push_back({{-4, 0, 0}, 0.5f});
    const auto bvh = buildBVH<Sphere>(SAHBVHBuilder{}, s);
    const auto tree = buildKdTree<Sphere>(SAHKdTreeBuilder{}, s);
    checkAgainstBruteForce<16>(bvh, BVHIntersector<SphereIntersector>{}, s);
    checkAgainstBruteForce<16>(tree, KdTreeIntersector<SphereIntersector>{}, s);
}

// pushRanked (a node's children placed on the stack by rank) leaves the stack exactly as
// pushSorted in slot order does, ties included, on top of entries already there; any
// subset of K slots, distances drawn from a few values so that ties are common.
template <int K>
void checkPushRankedMatchesPushSorted() {
    struct Entry {
        int32_t child;
        float dist;
    };
    std::mt19937 rng(42 + K);
    std::uniform_int_distribution<int> value(0, 3), below(0, 5);
    for (int round = 0; round < 2000; ++round) {
        Packet<K> dist;
        for (int c = 0; c < K; ++c) dist[c] = float(value(rng)) * 0.5f;
        const uint64_t bits = uint64_t(rng()) & ((uint64_t(1) << K) - 1);
        Entry sorted[K + 6], ranked[K + 6];
        const int base = below(rng);
        for (int i = 0; i < base; ++i) sorted[i] = ranked[i] = Entry{-1 - i, 9.0f};
        int sp = base, rp = base;
        for (uint64_t b = bits; b; b &= b - 1) {
            const int c = __builtin_ctzll(b);
            pushSorted(sorted, sp, base, Entry{c, dist[c]});
        }
        pushRanked(ranked, rp, bits, dist, [&](int c) { return Entry{c, dist[c]}; });
        ASSERT_EQ(rp, sp) << "K " << K << " round " << round;
        for (int i = 0; i < sp; ++i) {
            ASSERT_EQ(ranked[i].child, sorted[i].child) << "K " << K << " round " << round << " slot " << i;
            ASSERT_EQ(ranked[i].dist, sorted[i].dist);
        }
    }
}

TEST(Traversal, PushRankedMatchesPushSorted) {
    checkPushRankedMatchesPushSorted<4>();
    checkPushRankedMatchesPushSorted<8>();
    checkPushRankedMatchesPushSorted<16>();
}
