// The triangle intersector against a double-precision reference on random rays, and on
// rays through shared edges and vertices of a closed height field (no cracks), for
// single rays and native packets, common and distinct origins, and for the single-ray
// test of SIMD blocks of triangles (the wide BVH's leaves).
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>

#include "surfaces/triangle.h"
#include "test_meshes.h"

using namespace rtfact;
using namespace rtfact::surfaces;

namespace {

struct RefHit {
    bool hit = false;
    double t = 0, u = 0, v = 0, edge = 0;  // edge: smallest barycentric (distance to an edge)
};

// Möller-Trumbore in double precision, two-sided.
RefHit reference(const Triangle& tri, Vec3f of, Vec3f df) {
    auto sub = [](const double* a, const double* b, double* r) {
        for (int i = 0; i < 3; ++i) r[i] = a[i] - b[i];
    };
    auto crs = [](const double* a, const double* b, double* r) {
        r[0] = a[1] * b[2] - a[2] * b[1];
        r[1] = a[2] * b[0] - a[0] * b[2];
        r[2] = a[0] * b[1] - a[1] * b[0];
    };
    auto dt = [](const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
    const double v0[3] = {tri.v0.x, tri.v0.y, tri.v0.z}, v1[3] = {tri.v1.x, tri.v1.y, tri.v1.z},
                 v2[3] = {tri.v2.x, tri.v2.y, tri.v2.z}, o[3] = {of.x, of.y, of.z}, d[3] = {df.x, df.y, df.z};
    double e1[3], e2[3], p[3], s[3], q[3];
    sub(v1, v0, e1);
    sub(v2, v0, e2);
    crs(d, e2, p);
    const double det = dt(e1, p);
    RefHit r;
    if (std::fabs(det) < 1e-14) return r;
    sub(o, v0, s);
    r.u = dt(s, p) / det;
    crs(s, e1, q);
    r.v = dt(d, q) / det;
    r.t = dt(e2, q) / det;
    r.edge = std::min({r.u, r.v, 1.0 - r.u - r.v});
    r.hit = r.edge >= 0 && r.t > 0;
    return r;
}

template <int N>
void checkRandom(bool commonOrigin) {
    std::mt19937 rng(N * 7 + commonOrigin);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    const TriangleIntersector isect;
    int compared = 0, hits = 0;
    for (int iter = 0; iter < 400; ++iter) {
        const Triangle tri{{u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)}};
        RayPacket<N> rays;
        const Vec3f common{3.0f * u(rng), 3.0f * u(rng), 3.0f * u(rng)};
        for (int i = 0; i < N; ++i) {
            const Vec3f o = commonOrigin ? common : Vec3f{3.0f * u(rng), 3.0f * u(rng), 3.0f * u(rng)};
            // Aim near the triangle so about half the rays hit.
            const Vec3f target = (tri.v0 + tri.v1 + tri.v2) * (1.0f / 3.0f) + Vec3f(u(rng), u(rng), u(rng)) * 0.5f;
            rays.setLane(i, o, normalize(target - o));
        }
        rays.commonOrigin = commonOrigin;
        rays.finalize();
        TriangleIntersector::Hit<N> hit;
        hit.t = rays.tMax;
        hit.id = Packet<N, int32_t>(-1);
        hit.u = hit.v = Packet<N>(0.0f);
        isect.template intersect<HitData::Shading>(tri, 5, rays, hit, 0);
        for (int i = 0; i < N; ++i) {
            const RefHit r = reference(tri, rays.org.lane(i), rays.dir.lane(i));
            if (std::fabs(r.edge) < 1e-4) continue;  // too close to an edge to call
            ++compared;
            ASSERT_EQ(r.hit, hit.id[i] == 5) << "iter " << iter << " lane " << i;
            if (!r.hit) continue;
            ++hits;
            EXPECT_NEAR(hit.t[i], r.t, 1e-4 * std::max(1.0, r.t));
            EXPECT_NEAR(hit.u[i], r.u, 1e-3);
            EXPECT_NEAR(hit.v[i], r.v, 1e-3);
        }
    }
    EXPECT_GT(compared, 300 * N);
    EXPECT_GT(hits, 50 * N);
}

// The closed height field's triangles and points on their shared edges and vertices.
struct EdgeTargets {
    std::vector<Triangle> tris;
    std::vector<Vec3f> targets;
};
EdgeTargets heightFieldEdges() {
    const Mesh m = test::heightField(8, 3);
    EdgeTargets h;
    for (size_t t = 0; t < m.triangles(); ++t)
        h.tris.push_back(
            {m.positions[m.indices[3 * t]], m.positions[m.indices[3 * t + 1]], m.positions[m.indices[3 * t + 2]]});
    for (size_t t = 0; t < m.triangles(); ++t)
        for (int e = 0; e < 3; ++e) {
            const Vec3f a = m.positions[m.indices[3 * t + e]], b = m.positions[m.indices[3 * t + (e + 1) % 3]];
            for (float s : {0.0f, 0.25f, 0.5f, 0.7f, 1.0f / 3.0f}) {
                // Only interior edges and vertices are shared by two triangles.
                const Vec3f p = a + (b - a) * s;
                if (std::fabs(p.x) < 0.99f && std::fabs(p.z) < 0.99f) h.targets.push_back(p);
            }
        }
    return h;
}

// Rays through points on shared edges (and exactly through vertices) of a closed height
// field: at least one triangle must report the hit, at the right distance.
template <int N>
void checkEdges(bool commonOrigin) {
    const EdgeTargets h = heightFieldEdges();
    const std::vector<Triangle>& tris = h.tris;
    const std::vector<Vec3f>& targets = h.targets;
    std::mt19937 rng(11 + N);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    const TriangleIntersector isect;
    size_t misses = 0, rays = 0;
    for (size_t base = 0; base < targets.size(); base += N) {
        RayPacket<N> r;
        const Vec3f common{0.5f * u(rng), 3.0f, 0.5f * u(rng)};
        Vec3f exact[N];
        for (int i = 0; i < N; ++i) {
            const Vec3f p = targets[std::min(base + size_t(i), targets.size() - 1)];
            const Vec3f o = commonOrigin ? common : Vec3f{2.0f * u(rng), 2.0f + u(rng), 2.0f * u(rng)};
            r.setLane(i, o, p - o);  // unnormalised: the edge point is at t = 1
            exact[i] = p;
        }
        r.commonOrigin = commonOrigin;
        r.finalize();
        TriangleIntersector::Hit<N> hit;
        hit.t = r.tMax;
        hit.id = Packet<N, int32_t>(-1);
        hit.u = hit.v = Packet<N>(0.0f);
        for (size_t t = 0; t < tris.size(); ++t)
            isect.template intersect<HitData::Shading>(tris[t], uint32_t(t), r, hit, 0);
        for (int i = 0; i < N; ++i) {
            ++rays;
            if (hit.id[i] < 0) {
                ++misses;
                continue;
            }
            // The edge point is at t = 1; a hill in front may hide it, nothing may lie behind.
            EXPECT_LE(hit.t[i], 1.0f + 1e-4f) << "target " << exact[i].x << "," << exact[i].y << "," << exact[i].z;
        }
    }
    EXPECT_EQ(misses, 0u) << "rays through shared edges/vertices slipped through (cracks) out of " << rays;
}

}  // namespace

TEST(Triangle, RandomRaysSingleCommonOrigin) { checkRandom<1>(true); }
TEST(Triangle, RandomRaysSingleDistinctOrigin) { checkRandom<1>(false); }
TEST(Triangle, RandomRaysNativeCommonOrigin) { checkRandom<simd::kNativeWidth>(true); }
TEST(Triangle, RandomRaysNativeDistinctOrigin) { checkRandom<simd::kNativeWidth>(false); }
TEST(Triangle, SharedEdgesNoCracksSingle) {
    checkEdges<1>(true);
    checkEdges<1>(false);
}
TEST(Triangle, SharedEdgesNoCracksNative) {
    checkEdges<simd::kNativeWidth>(true);
    checkEdges<simd::kNativeWidth>(false);
}

// Shared edges are bit-exact negations of each other (the property that makes the test
// watertight), even with FMA contraction.
TEST(Triangle, EdgeFunctionAntisymmetric) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-10.0f, 10.0f);
    for (int i = 0; i < 10000; ++i) {
        const Vec3f p{u(rng), u(rng), u(rng)}, q{u(rng), u(rng), u(rng)}, d{u(rng), u(rng), u(rng)};
        const float a = dot(triangleEdge(p, q), d), b = dot(triangleEdge(q, p), d);
        ASSERT_EQ(a, -b);
    }
}

// A leaf's blocks tested together (AVX-512 pairs blocks of 8 into one 16-lane test,
// every build pairs blocks of 4) give bit for bit what testing the blocks one at a time
// gives: nearest hit (t, id, u, v; the first block's triangle on equal t) and any hit.
template <int L>
void checkBlocksMatchOneByOne() {
    std::mt19937 rng(11 + L);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    // Small triangles around the origin, some duplicated across blocks (equal t).
    std::vector<TriangleBlock<L>> blocks(4);
    std::vector<Triangle> tris;
    for (int i = 0; i < 4 * L; ++i) {
        const Vec3f c{u(rng), u(rng), u(rng)};
        tris.push_back(i % 7 == 6 ? tris[size_t(i - 5)]
                                  : Triangle{c, c + Vec3f{u(rng), u(rng), u(rng)} * 0.6f,
                                             c + Vec3f{u(rng), u(rng), u(rng)} * 0.6f});
    }
    for (int b = 0; b < 4; ++b) {
        uint32_t ids[L];
        for (int i = 0; i < L; ++i) ids[i] = uint32_t(b * L + i);
        blocks[size_t(b)].fill(ids, b == 3 ? L - 1 : L, [&](uint32_t k) { return tris[k]; });
    }
    const TriangleIntersector isect;
    int hits = 0;
    for (int r = 0; r < 4000; ++r) {
        const Vec3f o = Vec3f{u(rng), u(rng), u(rng)} * 3.0f;
        RayPacket<1> ray;
        ray.setLane(0, o, normalize(Vec3f{u(rng), u(rng), u(rng)} * 0.5f - o), 0.0f, r % 2 ? kInfinity : 3.0f);
        ray.finalize();
        for (int n = 1; n <= 4; ++n) {
            TriangleIntersector::Hit<1> all, one;
            all.t = one.t = ray.tMax;
            all.id = one.id = -1;
            all.u = all.v = one.u = one.v = 0.0f;
            isect.intersectBlocks<HitData::Shading>(blocks.data(), n, ray, all);
            for (int b = 0; b < n; ++b) isect.intersectBlocks<HitData::Shading>(blocks.data() + b, 1, ray, one);
            ASSERT_EQ(int32_t(all.id), int32_t(one.id)) << "ray " << r << " blocks " << n;
            ASSERT_EQ(float(all.t), float(one.t));
            ASSERT_EQ(float(all.u), float(one.u));
            ASSERT_EQ(float(all.v), float(one.v));
            hits += int32_t(all.id) >= 0;

            TriangleIntersector::Hit<1> anyAll, anyOne;
            anyAll.t = anyOne.t = ray.tMax;
            anyAll.id = anyOne.id = -1;
            const bool occAll = isect.occludedBlocks(blocks.data(), n, ray, anyAll);
            bool occOne = false;
            for (int b = 0; b < n && !occOne; ++b) occOne = isect.occludedBlocks(blocks.data() + b, 1, ray, anyOne);
            ASSERT_EQ(occAll, occOne) << "ray " << r << " blocks " << n;
            ASSERT_EQ(int32_t(anyAll.id), int32_t(anyOne.id));
            ASSERT_EQ(float(anyAll.t), float(anyOne.t));
        }
    }
    EXPECT_GT(hits, 1000);
}

TEST(Triangle, BlocksOf4MatchOneByOne) { checkBlocksMatchOneByOne<4>(); }
TEST(Triangle, BlocksOf8MatchOneByOne) { checkBlocksMatchOneByOne<8>(); }

// The single-ray block test (TriangleIntersector::intersectBlocks) against the
// double-precision reference: one triangle per block (the padding repeats it), random
// rays from every side, so every axis is the dominant one.
TEST(Triangle, BlockTestAgainstReference) {
    std::mt19937 rng(23);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    const TriangleIntersector isect;
    int compared = 0, hits = 0;
    int dominant[3] = {0, 0, 0};
    for (int iter = 0; iter < 3000; ++iter) {
        const Triangle tri{{u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)}};
        TriangleBlock<8> block;
        const uint32_t id = 5;
        block.fill(&id, 1, [&](uint32_t) { return tri; });
        const Vec3f o{3.0f * u(rng), 3.0f * u(rng), 3.0f * u(rng)};
        const Vec3f target = (tri.v0 + tri.v1 + tri.v2) * (1.0f / 3.0f) + Vec3f(u(rng), u(rng), u(rng)) * 0.5f;
        const Vec3f d = normalize(target - o);
        RayPacket<1> ray;
        ray.setLane(0, o, d);
        ray.finalize();
        const Vec3f ad(std::fabs(d.x), std::fabs(d.y), std::fabs(d.z));
        ++dominant[ad.x > ad.y ? (ad.x > ad.z ? 0 : 2) : (ad.y > ad.z ? 1 : 2)];
        TriangleIntersector::Hit<1> hit;
        hit.t = ray.tMax;
        hit.id = -1;
        hit.u = hit.v = 0.0f;
        isect.intersectBlocks<HitData::Shading>(&block, 1, ray, hit);
        TriangleIntersector::Hit<1> any;
        any.t = ray.tMax;
        any.id = -1;
        const bool occ = isect.occludedBlocks(&block, 1, ray, any);
        const RefHit r = reference(tri, o, d);
        if (std::fabs(r.edge) < 1e-4) continue;  // too close to an edge to call
        ++compared;
        ASSERT_EQ(r.hit, int32_t(hit.id) == 5) << "iter " << iter;
        ASSERT_EQ(r.hit, occ) << "iter " << iter;
        if (!r.hit) continue;
        ++hits;
        EXPECT_NEAR(float(hit.t), r.t, 1e-4 * std::max(1.0, r.t));
        EXPECT_NEAR(float(any.t), r.t, 1e-4 * std::max(1.0, r.t));
        EXPECT_NEAR(float(hit.u), r.u, 1e-3);
        EXPECT_NEAR(float(hit.v), r.v, 1e-3);
    }
    EXPECT_GT(compared, 2500);
    EXPECT_GT(hits, 600);
    for (int a = 0; a < 3; ++a) EXPECT_GT(dominant[a], 500) << "axis " << a;
}

// Rays through shared edges and vertices of the closed height field, against its
// triangles packed into SIMD blocks (neighbours in different blocks, paired and single
// tests mixed): the single-ray block test must have no cracks either, whichever axis
// dominates the ray.
template <int L>
void checkBlockEdges() {
    const EdgeTargets h = heightFieldEdges();
    const std::vector<Triangle>& tris = h.tris;
    const std::vector<Vec3f>& targets = h.targets;
    std::mt19937 rng(31 + L);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    // Blocks of a shuffled order, the last one partly filled.
    std::vector<uint32_t> order(tris.size());
    std::iota(order.begin(), order.end(), 0u);
    std::shuffle(order.begin(), order.end(), rng);
    std::vector<TriangleBlock<L>> blocks;
    for (size_t i = 0; i < order.size(); i += L) {
        blocks.emplace_back();
        blocks.back().fill(order.data() + i, int(std::min(order.size() - i, size_t(L))),
                           [&](uint32_t k) { return tris[k]; });
    }
    const TriangleIntersector isect;
    size_t misses = 0, anyMisses = 0, rays = 0;
    for (int pass = 0; pass < 4; ++pass)
        for (const Vec3f& p : targets) {
            // Origins all around (inside the closed surface too): the surface point at
            // t = 1 is reached whatever lies in front of it.
            const Vec3f o = pass == 0 ? Vec3f{0.5f * u(rng), 3.0f, 0.5f * u(rng)}
                                      : Vec3f{3.0f * u(rng), 3.0f * u(rng), 3.0f * u(rng)};
            RayPacket<1> r;
            r.setLane(0, o, p - o);  // unnormalised: the edge point is at t = 1
            r.finalize();
            ++rays;
            TriangleIntersector::Hit<1> hit;
            hit.t = r.tMax;
            hit.id = -1;
            hit.u = hit.v = 0.0f;
            // all blocks in one call (paired where the ISA allows), or one at a time
            const int n = int(blocks.size());
            if (pass % 2 == 0)
                isect.intersectBlocks<HitData::Shading>(blocks.data(), n, r, hit);
            else
                for (int b = 0; b < n; ++b) isect.intersectBlocks<HitData::Shading>(blocks.data() + b, 1, r, hit);
            if (int32_t(hit.id) < 0)
                ++misses;
            else
                EXPECT_LE(float(hit.t), 1.0f + 1e-4f) << "target " << p.x << "," << p.y << "," << p.z;
            TriangleIntersector::Hit<1> any;
            any.t = 1.0f + 1e-3f;
            any.id = -1;
            anyMisses += !isect.occludedBlocks(blocks.data(), n, r, any);
        }
    EXPECT_EQ(misses, 0u) << "rays through shared edges/vertices slipped through (cracks) out of " << rays;
    EXPECT_EQ(anyMisses, 0u) << "any-hit rays through shared edges/vertices slipped through out of " << rays;
}

TEST(Triangle, SharedEdgesNoCracksBlocksOf4) { checkBlockEdges<4>(); }
TEST(Triangle, SharedEdgesNoCracksBlocksOf8) { checkBlockEdges<8>(); }
