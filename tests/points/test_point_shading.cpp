// The core's Whitted and path integrators on point clouds, from the same code that
// renders meshes: a synthetic splat sphere (Fibonacci points, outward normals) lit,
// mirrored, refracted and path traced. Checks real properties: which side a ray arrives
// from, Whitted's diffuse lanes equal the direct-light integrator, lossless glass and a
// white furnace neither create nor (much) lose energy, packet sizes agree.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "common/image_compare.h"
#include "core/render/direct_light_integrator.h"
#include "core/render/framebuffer.h"
#include "core/render/path_integrator.h"
#include "core/render/pinhole_camera.h"
#include "core/render/pixel_center_sampler.h"
#include "core/render/ray_tracing_renderer.h"
#include "core/render/tile_scheduler.h"
#include "core/render/whitted_integrator.h"
#include "points/point_scene.h"

using namespace rtfact;
using namespace rtfact::points;

namespace {

constexpr int kSize = 48;

// n splats on a sphere of radius 1 at the origin, overlapping their neighbours.
PointScene sphereCloud(int n, Vec3f color) {
    std::vector<Disc> discs(static_cast<size_t>(n));
    const float golden = 3.14159265f * (3.0f - std::sqrt(5.0f));
    const float spacing = std::sqrt(4.0f * 3.14159265f / float(n));
    for (int i = 0; i < n; ++i) {
        const float z = 1.0f - 2.0f * (float(i) + 0.5f) / float(n), r = std::sqrt(1.0f - z * z);
        const Vec3f p(r * std::cos(golden * float(i)), r * std::sin(golden * float(i)), z);
        discs[size_t(i)] = Disc{p, 0.9f * spacing, encodeNormal(p), packRGBA(color, 0)};
    }
    PointScene s;
    s.build(std::move(discs));
    return s;
}

struct Shot {
    std::vector<float> rgba;
    std::vector<float> depth;
    // Mean of the red channel over pixels that hit (or all pixels).
    double mean(bool hitsOnly) const {
        double sum = 0;
        int count = 0;
        for (size_t i = 0; i < depth.size(); ++i) {
            if (hitsOnly && !(depth[i] < kInfinity)) continue;
            sum += rgba[4 * i];
            ++count;
        }
        return count ? sum / count : 0.0;
    }
    int hits() const {
        int h = 0;
        for (float d : depth) h += d < kInfinity;
        return h;
    }
};

template <int N = 64, class Integrator>
Shot render(const PointScene& scene, const Integrator& integ, int spp = 1) {
    const PinholeCamera cam(fitCamera(scene.bounds(), 40.0f, 1.0f, {0.3f, 0.5f, 1.0f}), kSize, kSize);
    const_cast<PointScene&>(scene).setLoD(cam.cone(), 0.0f);  // full detail: the same discs at every width
    RGBAFramebuffer fb(kSize, kSize, true);
    const RayTracingRenderer<PixelCenterSampler, Integrator> r{{}, integ};
    RenderOptions ro;
    ro.progress = false;
    ro.threads = 2;
    ro.spp = spp;
    renderImage<N>(r, scene, cam, fb, ro);
    return {fb.resolved(spp), fb.depth()};
}

WhittedIntegrator whitted(PathMaterial::Kind kind, Vec3f background) {
    WhittedIntegrator w;
    w.background = background;
    w.maxDepth = 12;
    PathMaterial m;
    m.kind = kind;
    m.albedo = Vec3f(1.0f);
    w.materials = {m};
    return w;
}

}  // namespace

// The disc normal tells entering from leaving, which glass needs.
TEST(PointShading, SurfaceReportsTheSideTheRayArrivesFrom) {
    const PointScene scene = sphereCloud(4000, Vec3f(1.0f));
    auto arrive = [&](Vec3f org) {
        RayPacket<1> ray;
        ray.setLane(0, org, {0.0f, 0.0f, -1.0f});
        ray.finalize();
        const auto hit = scene.intersect<1>(ray, Mask<1>(true));
        EXPECT_GE(hit.id[0], 0);
        const SurfacePoint<1> sp = scene.surface<1>(ray, hit, Mask<1>(true));
        EXPECT_LT(dot(sp.n.lane(0), ray.dir.lane(0)), 0.0f);  // the shading normal faces the ray
        return sp.front[0];
    };
    EXPECT_TRUE(arrive({0.0f, 0.0f, 5.0f}));   // from outside
    EXPECT_FALSE(arrive({0.0f, 0.0f, 0.0f}));  // from the centre
}

// Lambert lanes of the Whitted integrator are the direct-light integrator's shading.
TEST(PointShading, WhittedLambertCloudEqualsDirectLight) {
    const PointScene scene = sphereCloud(6000, Vec3f(0.9f, 0.6f, 0.3f));
    DirectLightIntegrator direct;
    direct.lights.push_back(PointLight{{3.0f, 4.0f, 5.0f}, Vec3f(40.0f)});
    direct.lights.push_back(DirectionalLight{{0.3f, -1.0f, -0.4f}, Vec3f(0.5f)});
    WhittedIntegrator w;
    w.lights = direct.lights;
    w.background = direct.background;
    const Shot a = render(scene, direct), b = render(scene, w);
    ASSERT_GT(a.hits(), kSize * kSize / 8);  // the sphere fills a good part of the image
    EXPECT_EQ(a.hits(), b.hits());
    int lit = 0;
    for (size_t i = 0; i < a.depth.size(); ++i) {
        if (!(a.depth[i] < kInfinity)) continue;
        // The same sum through shadeDirect; the two integrators are separate functions the
        // compiler may contract into FMAs differently, so equal up to float rounding.
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(a.rgba[4 * i + c], b.rgba[4 * i + c], 1e-6f * std::max(1.0f, a.rgba[4 * i + c]))
                << "pixel " << i;
        lit += a.rgba[4 * i] > 0.2f;
    }
    EXPECT_GT(lit, a.hits() / 4);  // not just the ambient term
}

// Under a uniform background, a lossless mirror or glass sphere shows that background:
// reflection and refraction split the light without creating any, and only paths cut
// by the depth limit go dark.
TEST(PointShading, WhittedMirrorAndGlassCloudsConserveEnergy) {
    const PointScene scene = sphereCloud(6000, Vec3f(1.0f));
    for (PathMaterial::Kind kind : {PathMaterial::Mirror, PathMaterial::Glass}) {
        const Shot img = render(scene, whitted(kind, Vec3f(0.5f)));
        ASSERT_GT(img.hits(), kSize * kSize / 8);
        float worst = 0;
        for (size_t i = 0; i < img.depth.size(); ++i) worst = std::max(worst, img.rgba[4 * i]);
        EXPECT_LE(worst, 0.5f * 1.001f) << "kind " << kind;
        EXPECT_GT(img.mean(true), 0.45) << "kind " << kind;
    }
}

// White furnace: a white Lambert cloud under a white sky reflects all light, so every
// pixel converges to 1; with half the albedo the (convex) sphere shows about 1/2.
TEST(PointShading, PathTracedCloudWhiteFurnace) {
    PathIntegrator pt;
    pt.background = Vec3f(1.0f);
    pt.maxDepth = 16;
    const Shot white = render(sphereCloud(6000, Vec3f(1.0f)), pt, 32);
    ASSERT_GT(white.hits(), kSize * kSize / 8);
    EXPECT_NEAR(white.mean(true), 1.0, 0.03);
    const Shot half = render(sphereCloud(6000, Vec3f(0.5f)), pt, 32);
    EXPECT_NEAR(half.mean(true), 0.5, 0.04);
    for (size_t i = 0; i < half.depth.size(); ++i)
        if (!(half.depth[i] < kInfinity)) {
            EXPECT_EQ(half.rgba[4 * i], 1.0f);  // the sky where nothing is hit
        }
}

// Path traced glass and Whitted glass give the same image for every packet size
// (random numbers hash pixel and sample, the discs are the same at full detail).
TEST(PointShading, PacketSizesAgreeForWhittedAndPath) {
    const PointScene scene = sphereCloud(6000, Vec3f(0.8f, 0.7f, 0.6f));
    PathIntegrator pt;
    pt.background = Vec3f(1.0f);
    PathMaterial glass;
    glass.kind = PathMaterial::Glass;
    glass.albedo = Vec3f(1.0f);
    PathIntegrator ptGlass = pt;
    ptGlass.materials = {glass};
    const WhittedIntegrator w = whitted(PathMaterial::Glass, Vec3f(0.3f, 0.5f, 0.7f));
    auto agree = [&](const auto& integ, int spp) {
        const Shot one = render<1>(scene, integ, spp);
        ASSERT_GT(one.hits(), kSize * kSize / 8);
        for (const Shot& other : {render<simd::kNativeWidth>(scene, integ, spp), render<256>(scene, integ, spp)}) {
            const test::ImageDiff d = test::compareRGBA(one.rgba, other.rgba, kSize, kSize, 1);
            EXPECT_LE(d.differentFraction, 0.001);
            EXPECT_GE(d.psnr, 50.0);
        }
    };
    agree(pt, 4);
    agree(ptGlass, 4);
    agree(w, 1);
}
