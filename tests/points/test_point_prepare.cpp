// Preparing clouds that real data produces but the spacing and normal estimates were not
// made for: masses of duplicate positions (merged scans, float coordinates quantised at
// UTM magnitudes) and tiny clouds of a few points, through the same pipeline as
// `rtfact points` (camera fitted to the bounds, normals and radii estimated, eyelight).
#include <gtest/gtest.h>

#include <cmath>

#include "core/render/eyelight_integrator.h"
#include "core/render/framebuffer.h"
#include "core/render/pinhole_camera.h"
#include "core/render/pixel_center_sampler.h"
#include "core/render/ray_tracing_renderer.h"
#include "core/render/tile_scheduler.h"
#include "points/point_prepare.h"
#include "points/point_scene.h"

using namespace rtfact;
using namespace rtfact::points;

namespace {

const float kCos1Deg = std::cos(1.0f * 3.14159265f / 180.0f);

// A 60 x 60 grid on the plane z = 0, spacing 0.1, every position twice (two merged scans),
// and grid position (30, 30) another `copies` times.
std::vector<Vec3f> duplicatedGrid(size_t copies) {
    std::vector<Vec3f> pts;
    for (int pass = 0; pass < 2; ++pass)
        for (int y = 0; y < 60; ++y)
            for (int x = 0; x < 60; ++x) pts.push_back({float(x) * 0.1f, float(y) * 0.1f, 0.0f});
    pts.insert(pts.end(), copies, Vec3f(3.0f, 3.0f, 0.0f));
    return pts;
}

}  // namespace

// k-NN searches visited every copy of a position once a query had found k of them
// (FLANN descends into subtrees not strictly farther than the k-th distance, 0 here):
// quadratic in the copies, 100,000 copies took 52 s. With a million copies a regression
// would take hours and run into the ctest TIMEOUT; the answers are checked here.
TEST(PreparePoints, MillionDuplicatesGiveGridNormalsAndSpacing) {
    constexpr size_t kCopies = 1000000;
    PointCloud cloud;
    cloud.positions = duplicatedGrid(kCopies);
    const size_t n = cloud.size();
    PrepareOptions po;
    po.viewpoint = Vec3f(3.0f, -2.0f, 5.0f);  // off-axis: a "face the viewer" fallback normal would fail the check
    po.threads = 2;
    const PrepareReport rep = preparePointCloud(cloud, po, "duplicates");
    EXPECT_TRUE(rep.estimatedNormals);
    EXPECT_TRUE(rep.estimatedRadii);
    ASSERT_EQ(cloud.normals.size(), n);
    ASSERT_EQ(cloud.radii.size(), n);
    for (size_t i = 0; i < n; ++i) {
        // The plane's normal, towards the viewpoint, for copies as for single points.
        ASSERT_GT(cloud.normals[i].z, kCos1Deg) << "point " << i;
        // The 4th nearest other position: 0.1 inside the grid, up to 0.2 at its corners;
        // copies of a position do not count (they made the spacing 0 before).
        ASSERT_GE(cloud.radii[i], 0.1f - 1e-4f) << "point " << i;
        ASSERT_LE(cloud.radii[i], 0.2f + 1e-4f) << "point " << i;
        const Vec3f p = cloud.positions[i];
        if (p.x > 0.05f && p.x < 5.85f && p.y > 0.05f && p.y < 5.85f) {
            ASSERT_NEAR(cloud.radii[i], 0.1f, 1e-4f) << "point " << i;
        }
    }
    // The public estimates agree with the prepared cloud, copy for copy.
    const std::vector<float> s = neighbourSpacing(cloud.positions, 4);
    EXPECT_EQ(s, cloud.radii);
    const std::vector<Vec3f> nrm = estimateNormals(cloud.positions, 24, *po.viewpoint, 2);
    ASSERT_EQ(nrm.size(), n);
    for (size_t i = 0; i < n; i += 997) EXPECT_GT(nrm[i].z, kCos1Deg) << "point " << i;
    EXPECT_EQ(nrm.back(), cloud.normals.back());
}

// A cloud with only copies of one position has no spacing and no plane.
TEST(PreparePoints, AllPointsIdentical) {
    const std::vector<Vec3f> pts(200000, Vec3f(1.5f, 2.5f, 3.5f));
    const std::vector<float> s = neighbourSpacing(pts, 4);
    for (float v : s) ASSERT_EQ(v, 0.0f);
    const Vec3f vp(1.5f, 2.5f, 10.0f);
    const std::vector<Vec3f> nrm = estimateNormals(pts, 24, vp, 2);
    for (const Vec3f& v : nrm) ASSERT_EQ(v, Vec3f(0, 0, 1));  // facing the viewpoint
}

namespace {

constexpr int kImage = 64;

struct TinyResult {
    std::vector<float> radii;
    int litPixels = 0;
    std::vector<bool> pointHit;       // the ray from the eye towards each point hits a disc no farther than it
    std::vector<float> radiusPixels;  // each disc's radius in pixels at its distance
};

// `rtfact points` with the defaults on a cloud given as positions.
TinyResult renderTiny(const std::vector<Vec3f>& positions) {
    PointCloud cloud;
    cloud.positions = positions;
    const CameraFrame frame = fitCamera(cloud.bounds(), 45.0f, 1.0f);
    PrepareOptions po;
    po.viewpoint = frame.eye;
    po.threads = 2;
    preparePointCloud(cloud, po, "tiny");
    TinyResult res;
    res.radii = cloud.radii;
    PointScene scene;
    scene.build(makeDiscs(cloud, ColorMode::Rgb));
    const PinholeCamera cam(frame, kImage, kImage);
    scene.setLoD(cam.cone(), 0.0f);
    const float pix = 2.0f * std::tan(0.5f * frame.fovDeg * 3.14159265f / 180.0f) / float(kImage);
    for (size_t i = 0; i < positions.size(); ++i) {
        const Vec3f to = positions[i] - frame.eye;
        const float dist = length(to);
        RayPacket<1> r;
        r.setLane(0, frame.eye, to * (1.0f / dist), 0.0f, kInfinity);
        r.finalize();
        const auto hit = scene.intersect<1>(r, Mask<1>(true));
        res.pointHit.push_back(hit.id[0] >= 0 && hit.t[0] <= dist * (1.0f + 1e-4f));
        res.radiusPixels.push_back(cloud.radii[i] / (dist * pix));
    }
    RGBAFramebuffer fb(kImage, kImage);
    const RayTracingRenderer<PixelCenterSampler, EyeLightIntegrator> renderer{{}, {}};
    RenderOptions ro;
    ro.progress = false;
    renderImage<16>(renderer, scene, cam, fb, ro);
    const auto img = fb.resolved(1);
    for (size_t p = 0; p < size_t(kImage) * kImage; ++p) res.litPixels += img[p * 4] > 0.2f;  // background is 0.05
    return res;
}

void expectVisibleDiscs(const std::vector<Vec3f>& positions) {
    const TinyResult r = renderTiny(positions);
    for (size_t i = 0; i < positions.size(); ++i) {
        EXPECT_TRUE(std::isfinite(r.radii[i]) && r.radii[i] > 0) << "point " << i << " radius " << r.radii[i];
        EXPECT_TRUE(r.pointHit[i]) << "point " << i;
        // A disc, not a speck: several pixels across (it was 0.06 pixels for two points).
        EXPECT_GE(r.radiusPixels[i], 2.0f) << "point " << i;
    }
    EXPECT_GE(r.litPixels, 12) << positions.size() << " points";
}

}  // namespace

TEST(PreparePoints, TinyCloudsRenderVisibleDiscs) {
    expectVisibleDiscs({{1, 2, 3}});
    expectVisibleDiscs({{0, 0, 0}, {1, 0, 0}});
    expectVisibleDiscs({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
    expectVisibleDiscs({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0.2f}});  // k = 4 points
    // Copies do not make a cloud bigger: four positions, three times each.
    std::vector<Vec3f> copies;
    for (int c = 0; c < 3; ++c) copies.insert(copies.end(), {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {2, 2, 0}});
    expectVisibleDiscs(copies);
}

TEST(PreparePoints, TinyCloudRadiusIsHalfTheNearestDistance) {
    // With no k-th neighbour, discs that touch: half the distance to the nearest other point.
    const std::vector<float> two = neighbourSpacing({{0, 0, 0}, {1, 0, 0}}, 4);
    EXPECT_EQ(two, (std::vector<float>{0.5f, 0.5f}));
    const std::vector<float> three = neighbourSpacing({{0, 0, 0}, {1, 0, 0}, {3, 0, 0}, {1, 0, 0}}, 4);
    EXPECT_EQ(three, (std::vector<float>{0.5f, 0.5f, 1.0f, 0.5f}));
    // Five positions have a 4th neighbour: the usual spacing.
    const std::vector<float> five = neighbourSpacing({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}, {4, 0, 0}}, 4);
    EXPECT_EQ(five, (std::vector<float>{4, 3, 2, 3, 4}));
}
