// Packet traversal of the blocked wide BVH (WideBVHPacketIntersector) against brute force
// over all triangles: arity K = 4, 8, 16; packet sizes 1, native, 64 and 256; coherent
// common-origin packets (camera-like, where the frustum culls), distinct origins
// (parallel-ish rays and random ones), partial packets; nearest hit with barycentrics
// and any hit; the chunk path alone, the single-ray hand-over alone and both mixed, each
// with chunks starting at the root and below the whole packet's top-level traversal.
// MeshScene routes primary and shadow rays through it and keeps the packet BVH's hits.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "core/accel/wide_bvh_builder.h"
#include "core/accel/wide_bvh_packet_intersector.h"
#include "surfaces/mesh_scene.h"
#include "test_meshes.h"

using namespace rtfact;
using namespace rtfact::surfaces;

namespace {

std::vector<Triangle> packetTestTriangles() {
    Mesh a = test::heightField(24, 4);
    a.append(test::triangleSoup(600, 9));
    a.append(test::uvSphere({0.2f, 0.5f, -0.1f}, 0.35f, 16));
    return meshTriangles(a);
}

template <int K>
BlockedWideBVH<TriangleBlock<8>, K> packetTree(const std::vector<Triangle>& tris) {
    WideSAHBVHBuilder b;
    b.leafBlock = 8;
    b.maxLeafSize = 32;
    std::vector<AABB> bounds(tris.size());
    for (size_t i = 0; i < tris.size(); ++i) bounds[i] = tris[i].bounds();
    WideBVHTopology<K> topo;
    b.build(std::span<const AABB>(bounds), topo);
    return packLeafBlocks<TriangleBlock<8>>(std::move(topo), [&](TriangleBlock<8>& blk, const uint32_t* ids, int n) {
        blk.fill(ids, n, [&](uint32_t i) { return tris[i]; });
    });
}

struct Brute {
    float t = kInfinity;
    int id = -1;
    float u = 0, v = 0;
};
Brute brute(const std::vector<Triangle>& tris, const RayPacket<1>& r) {
    TriangleIntersector::Hit<1> h;
    h.t = r.tMax;
    h.id = -1;
    for (size_t i = 0; i < tris.size(); ++i)
        TriangleIntersector{}.intersect<HitData::Shading>(tris[i], uint32_t(i), r, h, 0);
    if (int32_t(h.id) < 0) return {};
    return {float(h.t), int32_t(h.id), float(h.u), float(h.v)};
}

enum class Rays { Camera, Parallel, Random };

// Rays of one packet: a camera-like bundle from one eye (lanes in raster order over a
// small square of the image), parallel-ish rays with distinct origins, or random rays.
template <int N>
RayPacket<N> makeRays(Rays kind, std::mt19937& rng, float spread) {
    std::uniform_real_distribution<float> u(-1.0f, 1.0f), u01(0.0f, 1.0f);
    RayPacket<N> rays;
    const Vec3f eye{2.5f * u(rng), 1.2f + u01(rng), 2.5f * u(rng)};
    const Vec3f target = Vec3f{u(rng), u(rng), u(rng)} * 0.6f;
    const Vec3f fwd = normalize(target - eye);
    const Vec3f right = normalize(cross(fwd, Vec3f(0.0f, 1.0f, 0.0f)));
    const Vec3f up = cross(right, fwd);
    const int side = std::max(1, int(std::sqrt(float(N))));
    for (int i = 0; i < N; ++i) {
        const float x = (float(i % side) + 0.5f) / float(side) - 0.5f,
                    y = (float(i / side) + 0.5f) / float(side) - 0.5f;
        if (kind == Rays::Camera) {
            rays.setLane(i, eye, normalize(fwd + right * (x * spread) + up * (y * spread)));
        } else if (kind == Rays::Parallel) {
            rays.setLane(i, eye + right * (x * spread * 3.0f) + up * (y * spread * 3.0f),
                         normalize(fwd + right * (0.02f * u(rng))));
        } else {
            const Vec3f o{2.0f * u(rng), 2.0f * u(rng), 2.0f * u(rng)};
            rays.setLane(i, o, normalize(Vec3f{u(rng), u(rng), u(rng)} * 0.8f - o));
        }
    }
    rays.commonOrigin = kind == Rays::Camera;
    rays.finalize();
    return rays;
}

// singleRayFraction (nodes and leaves): 0 = chunks only, 1 = single rays only, in
// between = mixed. packetSplit: 0 = chunks start at the root, else the whole packet
// splits nodes with up to that many candidate children first (64: every inner level).
template <int K, int N>
void checkPacketTraversal(Rays kind, float singleRayFraction, int packetSplit) {
    if constexpr (!simd::ValidPacketSize<N>) {
        GTEST_SKIP() << "packet size " << N << " not supported by this build";
    } else {
        static const std::vector<Triangle> tris = packetTestTriangles();
        const auto tree = packetTree<K>(tris);
        WideBVHPacketIntersector<TriangleIntersector> isect;
        isect.singleRayFraction = isect.singleRayLeafFraction = singleRayFraction;
        isect.packetSplit = packetSplit;
        std::mt19937 rng(uint32_t(N * 7 + K * 3 + int(kind) + int(singleRayFraction * 8) + packetSplit));
        std::uniform_real_distribution<float> u01(0.0f, 1.0f);
        const int packets = std::max(6, 1536 / N);
        int hits = 0, occChecked = 0, occluded = 0, edgeCases = 0;
        for (int p = 0; p < packets; ++p) {
            // Wide and narrow bundles: whole-packet hits and sub-pixel footprints.
            RayPacket<N> rays = makeRays<N>(kind, rng, p % 2 ? 0.6f : 0.05f);
            Mask<N> active(true);
            if (p % 3 == 1)
                for (int i = 0; i < N; ++i) active.set(i, u01(rng) < 0.5f);
            if (p % 6 == 4)  // a packet with a single live lane
                for (int i = 0; i < N; ++i) active.set(i, i == N / 2);
            TriangleIntersector::Hit<N> hit;
            if (rays.commonOrigin)
                isect.template intersect<true, HitData::Shading>(tree, rays, hit, active);
            else
                isect.template intersect<false, HitData::Shading>(tree, rays, hit, active);
            std::vector<Brute> ref(static_cast<size_t>(N));
            for (int i = 0; i < N; ++i) {
                if (!active[i]) {
                    EXPECT_EQ(hit.id[i], -1) << "inactive lane " << i << " reported a hit";
                    EXPECT_EQ(hit.t[i], rays.tMax[i]);
                    continue;
                }
                const Brute b = ref[size_t(i)] = brute(tris, rays.lane(i));
                hits += b.id >= 0;
                const float t = hit.id[i] >= 0 ? float(hit.t[i]) : kInfinity;
                if (std::isinf(t) != std::isinf(b.t) || std::fabs(t - b.t) > 1e-5f * std::max(1.0f, b.t)) {
                    // Single rays test whole blocks with their own rounding: a ray through
                    // an edge or vertex may hit on one side only.
                    ++edgeCases;
                    continue;
                }
                if (hit.id[i] == b.id && b.id >= 0) {
                    EXPECT_NEAR(hit.u[i], b.u, 1e-3f);
                    EXPECT_NEAR(hit.v[i], b.v, 1e-3f);
                }
            }
            // Any hit on segments ending before or after the nearest hit.
            RayPacket<N> seg = rays;
            for (int i = 0; i < N; ++i) seg.tMax[i] = 4.0f * u01(rng);
            const Mask<N> occ = seg.commonOrigin ? isect.template occluded<true>(tree, seg, active)
                                                 : isect.template occluded<false>(tree, seg, active);
            for (int i = 0; i < N; ++i) {
                if (!active[i]) {
                    EXPECT_FALSE(occ[i]);
                    continue;
                }
                const float bt = ref[size_t(i)].t;
                if (std::fabs(bt - seg.tMax[i]) < 1e-4f) continue;  // too close to call
                ++occChecked;
                occluded += bt < seg.tMax[i];
                EXPECT_EQ(occ[i], bt < seg.tMax[i]) << "packet " << p << " lane " << i;
            }
        }
        EXPECT_LE(edgeCases, 1 + hits / 2000) << "lanes disagreeing with brute force";
        EXPECT_GT(hits, packets * N / 10);
        EXPECT_GT(occluded, occChecked / 20);
        EXPECT_GT(occChecked, packets * N / 3);
    }
}

template <int K, int N>
void checkAllModes() {
    for (Rays kind : {Rays::Camera, Rays::Parallel, Rays::Random})
        for (float f : {0.0f, 0.3f, 1.0f})
            for (int split : {0, 2, 64}) {
                SCOPED_TRACE(testing::Message()
                             << "rays " << int(kind) << " singleRayFraction " << f << " packetSplit " << split);
                checkPacketTraversal<K, N>(kind, f, split);
            }
}

}  // namespace

#define RTFACT_WIDE_PACKET_TESTS(K)                                            \
    TEST(WideBVHPacket, K##Single) { checkAllModes<K, 1>(); }                  \
    TEST(WideBVHPacket, K##Native) { checkAllModes<K, simd::kNativeWidth>(); } \
    TEST(WideBVHPacket, K##Packet64) { checkAllModes<K, 64>(); }               \
    TEST(WideBVHPacket, K##Packet256) { checkAllModes<K, 256>(); }

RTFACT_WIDE_PACKET_TESTS(4)
RTFACT_WIDE_PACKET_TESTS(8)
RTFACT_WIDE_PACKET_TESTS(16)

// An empty tree hits nothing; a one-triangle tree is hit by the lanes that cross it.
TEST(WideBVHPacket, EmptyAndSingleTriangle) {
    constexpr int N = simd::kNativeWidth;
    RayPacket<N> rays;
    for (int i = 0; i < N; ++i)
        rays.setLane(i, Vec3f(0.0f, 0.0f, -2.0f), normalize(Vec3f(0.05f * float(i), -0.1f, 1.0f)));
    rays.commonOrigin = true;
    rays.finalize();
    WideBVHPacketIntersector<TriangleIntersector> isect;
    isect.singleRayFraction = isect.singleRayLeafFraction = 0.0f;
    TriangleIntersector::Hit<N> hit;
    const auto none = packetTree<8>({});
    isect.intersect<true, HitData::Shading>(none, rays, hit, Mask<N>(true));
    EXPECT_TRUE(all(hit.id == Packet<N, int32_t>(-1)));
    EXPECT_FALSE(any(isect.occluded<true>(none, rays, Mask<N>(true))));
    const std::vector<Triangle> one{{Vec3f(-1.0f, -1.0f, 0.0f), Vec3f(1.0f, -1.0f, 0.0f), Vec3f(-1.0f, 1.0f, 0.0f)}};
    const auto tree = packetTree<8>(one);
    isect.intersect<true, HitData::Shading>(tree, rays, hit, Mask<N>(true));
    const Mask<N> occ = isect.occluded<true>(tree, rays, Mask<N>(true));
    for (int i = 0; i < N; ++i) {
        const Brute b = brute(one, rays.lane(i));
        EXPECT_EQ(hit.id[i], b.id) << "lane " << i;
        EXPECT_EQ(occ[i], b.id >= 0) << "lane " << i;
    }
    EXPECT_EQ(hit.id[0], 0);
}

// The tiled lane order is a permutation, and a chunk is a compact tile of the packet's
// row-major bw x bh pixels (not a strip of one row); so is a group of G lanes traced
// together (the LoD wide BVH's 16-lane groups of AVX2 chunks: 4 x 4, not 8 x 2), and the
// rows traceInChunkTiles copies are the permutation's.
template <int N, int G = Packet<N>::W>
void checkChunkTiles() {
    using T = PacketChunkTiles<N, G>;
    if constexpr (T::kEnabled) {
        std::vector<int> seen(static_cast<size_t>(N), 0);
        for (int i = 0; i < N; ++i) ++seen[size_t(T::perm[size_t(i)])];
        EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), N);
        auto extent = [](int first, int lanes, int& w, int& h) {
            int x0 = N, x1 = -1, y0 = N, y1 = -1;
            for (int l = 0; l < lanes; ++l) {
                const int p = T::perm[size_t(first + l)];
                x0 = std::min(x0, p % T::bw), x1 = std::max(x1, p % T::bw);
                y0 = std::min(y0, p / T::bw), y1 = std::max(y1, p / T::bw);
            }
            w = x1 - x0 + 1, h = y1 - y0 + 1;
        };
        for (int k = 0; k < N / T::W; ++k) {
            int w, h;
            extent(k * T::W, T::W, w, h);
            EXPECT_EQ(w, T::cw) << "chunk " << k;
            EXPECT_EQ(h, T::ch) << "chunk " << k;
            for (int y = 0; y < T::ch; ++y)
                for (int x = 0; x < T::cw; ++x)
                    EXPECT_EQ(T::perm[size_t(k * T::W + y * T::cw + x)], T::rowStart(k, y) + x) << "chunk " << k;
        }
        for (int g = 0; g < N / T::GL; ++g) {
            int w, h;
            extent(g * T::GL, T::GL, w, h);
            EXPECT_EQ(w * h, T::GL) << "group " << g;
            EXPECT_LE(std::max(w, h), 4 * std::min(w, h)) << "group " << g;
        }
    }
}
TEST(WideBVHPacket, ChunkTiles) {
    EXPECT_TRUE((WideBVHPacketIntersector<TriangleIntersector>::ChunkTiles<256>::kEnabled));
    checkChunkTiles<64>();
    checkChunkTiles<256>();
    checkChunkTiles<64, 16>();
    checkChunkTiles<256, 16>();
    // (checked at run time: a static_assert in a discarded branch outside a template still
    // fires, and did in the sse4 build)
    if constexpr (simd::kNativeWidth == 8) {
        EXPECT_EQ((PacketChunkTiles<64, 16>::cw), 4);
        EXPECT_EQ((PacketChunkTiles<64, 16>::gh), 4);
    }
}
