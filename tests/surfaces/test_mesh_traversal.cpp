// Mesh BVH and kd-tree traversal against brute force over all triangles, at packet
// sizes 1, native, 64 and 256, with common and distinct origins, nearest-hit and
// occlusion queries, and partly active packets.
#include <gtest/gtest.h>

#include <random>

#include "surfaces/mesh_scene.h"
#include "test_meshes.h"

using namespace rtfact;
using namespace rtfact::surfaces;

namespace {

std::shared_ptr<const Mesh> testMesh() {
    static std::shared_ptr<const Mesh> m = [] {
        Mesh a = test::heightField(20, 4);
        a.append(test::triangleSoup(500, 9));
        a.append(test::uvSphere({0.2f, 0.5f, -0.1f}, 0.35f, 12));
        return std::make_shared<const Mesh>(a);
    }();
    return m;
}

struct Brute {
    std::vector<Triangle> tris;
    explicit Brute(const Mesh& m) : tris(meshTriangles(m)) {}
    // Nearest t (inf if none) and id of one ray.
    std::pair<float, int> nearest(const RayPacket<1>& r) const {
        TriangleIntersector::Hit<1> h;
        h.t = r.tMax;
        h.id = -1;
        h.u = h.v = 0.0f;
        for (size_t i = 0; i < tris.size(); ++i)
            TriangleIntersector{}.intersect<HitData::Shading>(tris[i], uint32_t(i), r, h, 0);
        const int id = h.id;
        return {id >= 0 ? float(h.t) : kInfinity, id};
    }
};

template <class Structure, int N>
void check(bool commonOrigin) {
    if constexpr (!simd::ValidPacketSize<N>) {
        GTEST_SKIP() << "packet size " << N << " not supported by this build";
    } else {
        const auto mesh = testMesh();
        const MeshScene<Structure> scene(mesh);
        const Brute brute(*mesh);
        std::mt19937 rng(N * 3 + commonOrigin);
        std::uniform_real_distribution<float> u(-1.0f, 1.0f), u01(0.0f, 1.0f);
        const int packets = std::max(4, 1024 / N);
        int hits = 0, occChecked = 0;
        for (int p = 0; p < packets; ++p) {
            RayPacket<N> rays;
            const Vec3f eye{2.5f * u(rng), 1.5f + u01(rng), 2.5f * u(rng)};
            // Coherent packets look at a common target region; distinct ones are random.
            const Vec3f target{0.5f * u(rng), 0.0f, 0.5f * u(rng)};
            for (int i = 0; i < N; ++i) {
                const Vec3f o = commonOrigin ? eye : Vec3f{2.0f * u(rng), 2.0f * u(rng), 2.0f * u(rng)};
                const Vec3f t =
                    commonOrigin ? target + Vec3f(u(rng), u(rng), u(rng)) * 0.6f : Vec3f{u(rng), u(rng), u(rng)};
                rays.setLane(i, o, normalize(t - o), 0.0f, kInfinity);
            }
            rays.commonOrigin = commonOrigin;
            rays.finalize();
            Mask<N> active(true);
            if (p % 3 == 1)
                for (int i = 0; i < N; ++i) active.set(i, u01(rng) < 0.6f);
            const auto hit = scene.template intersect<N>(rays, active);
            for (int i = 0; i < N; ++i) {
                if (!active[i]) {
                    EXPECT_EQ(hit.id[i], -1) << "inactive lane " << i << " reported a hit";
                    continue;
                }
                const auto [bt, bid] = brute.nearest(rays.lane(i));
                if (bid < 0) {
                    EXPECT_EQ(hit.id[i], -1) << "packet " << p << " lane " << i;
                    continue;
                }
                ++hits;
                ASSERT_GE(hit.id[i], 0) << "packet " << p << " lane " << i << " missed (brute t=" << bt << ")";
                // Brute force uses the common-origin form of the test, the structure may not.
                EXPECT_NEAR(hit.t[i], bt, 1e-4f * std::max(1.0f, bt));
                // Ids may differ only when two triangles tie at the same distance.
                if (hit.id[i] != bid) {
                    EXPECT_NEAR(hit.t[i], bt, 1e-4f * std::max(1.0f, bt));
                }
            }
            // Occlusion with a segment ending before or after the nearest hit.
            RayPacket<N> seg = rays;
            for (int i = 0; i < N; ++i) seg.tMax[i] = 2.0f * u01(rng);
            const Mask<N> occ = scene.template occluded<N>(seg, active);
            for (int i = 0; i < N; ++i) {
                if (!active[i]) {
                    EXPECT_FALSE(occ[i]);
                    continue;
                }
                const auto [bt, bid] = brute.nearest(rays.lane(i));
                if (std::fabs(bt - seg.tMax[i]) < 1e-4f) continue;  // too close to call
                ++occChecked;
                EXPECT_EQ(occ[i], bt < seg.tMax[i])
                    << "packet " << p << " lane " << i << " t=" << bt << " tMax=" << seg.tMax[i];
            }
        }
        EXPECT_GT(hits, packets * N / 8);
        EXPECT_GT(occChecked, packets * N / 2);
    }
}

}  // namespace

#define RTFACT_TRAVERSAL_TESTS(Name, Structure)                                                \
    TEST(MeshTraversal, Name##Single) {                                                        \
        check<Structure, 1>(true);                                                             \
        check<Structure, 1>(false);                                                            \
    }                                                                                          \
    TEST(MeshTraversal, Name##NativeCommon) { check<Structure, simd::kNativeWidth>(true); }    \
    TEST(MeshTraversal, Name##NativeDistinct) { check<Structure, simd::kNativeWidth>(false); } \
    TEST(MeshTraversal, Name##Packet64Common) { check<Structure, 64>(true); }                  \
    TEST(MeshTraversal, Name##Packet64Distinct) { check<Structure, 64>(false); }               \
    TEST(MeshTraversal, Name##Packet256Common) { check<Structure, 256>(true); }                \
    TEST(MeshTraversal, Name##Packet256Distinct) { check<Structure, 256>(false); }

RTFACT_TRAVERSAL_TESTS(BVH, BVH<Triangle>)
RTFACT_TRAVERSAL_TESTS(KdTree, KdTree<Triangle>)
