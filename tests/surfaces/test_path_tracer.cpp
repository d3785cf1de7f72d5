// Path tracer: white furnace (energy conservation of every material: a convex object
// under a uniform environment of radiance 1 must look exactly as bright as its albedo,
// 1 for mirror and glass), and convergence on a Cornell-like box (RMSE against a
// high-spp reference falls like 1/sqrt(spp)).
#include <gtest/gtest.h>

#include "core/render/framebuffer.h"
#include "core/render/jittered_sampler.h"
#include "core/render/pinhole_camera.h"
#include "core/render/ray_tracing_renderer.h"
#include "core/render/tile_scheduler.h"
#include "surfaces/mesh_scene.h"
#include "surfaces/path_integrator.h"
#include "test_meshes.h"
#include "tests/common/image_compare.h"

using namespace rtfact;
using namespace rtfact::surfaces;

namespace {

template <int N>
std::vector<float> render(const MeshScene<BVH<Triangle>>& scene, const PathIntegrator& integ, const CameraFrame& f,
                          int w, int h, int spp) {
    const PinholeCamera cam(f, w, h);
    RGBAFramebuffer fb(w, h);
    RayTracingRenderer<JitteredSampler, PathIntegrator> r{{}, integ};
    RenderOptions o;
    o.progress = false;
    o.tileSize = 16;
    o.spp = spp;
    renderImage<N>(r, scene, cam, fb, o);
    return fb.resolved(spp);
}

// A cube with separate vertices per face, so shading normals equal face normals and no
// path can return to the object (it is convex).
Mesh flatCube() {
    Mesh m;
    const Vec3f c[8] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                        {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
    const int f[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {2, 3, 7, 6}, {1, 2, 6, 5}, {0, 4, 7, 3}};
    for (const auto& q : f) {
        const uint32_t b = uint32_t(m.positions.size());
        for (int k = 0; k < 4; ++k) m.positions.push_back(c[q[k]]);
        m.indices.insert(m.indices.end(), {b, b + 1, b + 2, b, b + 2, b + 3});
    }
    m.computeNormals();
    return m;
}

void furnace(PathMaterial::Kind kind, float albedo, float expected) {
    auto m = std::make_shared<Mesh>(flatCube());
    m->materials = {MeshMaterial{}};
    m->materials[0].kd = Vec3f(albedo);
    if (kind == PathMaterial::Mirror) {
        m->materials[0].illum = 3;
        m->materials[0].ks = Vec3f(albedo);
    }
    if (kind == PathMaterial::Glass) {
        m->materials[0].dissolve = 0.0f;
        m->materials[0].ior = 1.5f;
    }
    m->materialIds.assign(m->triangles(), 0);
    const MeshScene<BVH<Triangle>> scene(m);
    PathIntegrator integ;
    integ.background = Vec3f(1.0f);
    integ.maxDepth = 64;
    integ.rouletteDepth = 1000;  // no roulette: every path ends in the environment
    integ.materials = PathIntegrator::fromMesh(*m);
    CameraFrame f;
    f.eye = {3.0f, 2.5f, 3.5f};
    f.at = {0, 0, 0};
    f.fovDeg = 18.0f;
    const int w = 32, h = 32;
    const auto img = render<64>(scene, integ, f, w, h, 4);
    // Only pixels well inside the silhouette (no partial coverage).
    double sum = 0, worst = 0;
    int n = 0;
    for (int y = 8; y < 24; ++y)
        for (int x = 8; x < 24; ++x) {
            const float v = img[(size_t(y) * w + x) * 4];
            worst = std::max(worst, std::fabs(double(v) - expected));
            sum += v;
            ++n;
        }
    EXPECT_NEAR(sum / n, expected, 2e-3) << "mean radiance";
    // Lambert and mirror paths all carry exactly the albedo; glass ones only lose what
    // exceeds the depth limit.
    EXPECT_LT(worst, kind == PathMaterial::Glass ? 0.05 : 2e-3);
}

// A closed box with a ceiling light and a block: a Cornell-like scene.
std::shared_ptr<Mesh> cornell() {
    auto m = std::make_shared<Mesh>();
    auto quad = [&](Vec3f a, Vec3f b, Vec3f c, Vec3f d, int mat) {
        const uint32_t base = uint32_t(m->positions.size());
        m->positions.insert(m->positions.end(), {a, b, c, d});
        m->indices.insert(m->indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
        m->materialIds.insert(m->materialIds.end(), {mat, mat});
    };
    MeshMaterial white, red, green, light;
    white.kd = Vec3f(0.75f);
    red.kd = {0.75f, 0.15f, 0.15f};
    green.kd = {0.15f, 0.75f, 0.15f};
    light.kd = Vec3f(0.0f);
    light.ke = Vec3f(12.0f);
    m->materials = {white, red, green, light};
    quad({-1, -1, -1}, {1, -1, -1}, {1, -1, 1}, {-1, -1, 1}, 0);                                      // floor
    quad({-1, 1, -1}, {-1, 1, 1}, {1, 1, 1}, {1, 1, -1}, 0);                                          // ceiling
    quad({-1, -1, -1}, {-1, 1, -1}, {1, 1, -1}, {1, -1, -1}, 0);                                      // back
    quad({-1, -1, -1}, {-1, -1, 1}, {-1, 1, 1}, {-1, 1, -1}, 1);                                      // left
    quad({1, -1, -1}, {1, 1, -1}, {1, 1, 1}, {1, -1, 1}, 2);                                          // right
    quad({-0.3f, 0.99f, -0.3f}, {-0.3f, 0.99f, 0.3f}, {0.3f, 0.99f, 0.3f}, {0.3f, 0.99f, -0.3f}, 3);  // lamp
    // A block.
    const float x0 = -0.5f, x1 = 0.0f, z0 = -0.6f, z1 = -0.1f, y0 = -1.0f, y1 = -0.2f;
    quad({x0, y1, z0}, {x0, y1, z1}, {x1, y1, z1}, {x1, y1, z0}, 0);
    quad({x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1}, 0);
    quad({x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}, {x1, y0, z1}, 0);
    quad({x0, y0, z0}, {x0, y1, z0}, {x0, y1, z1}, {x0, y0, z1}, 0);
    m->computeNormals();
    return m;
}

}  // namespace

TEST(PathTracer, WhiteFurnaceLambert) { furnace(PathMaterial::Lambert, 1.0f, 1.0f); }
TEST(PathTracer, WhiteFurnaceLambertHalfAlbedo) { furnace(PathMaterial::Lambert, 0.5f, 0.5f); }
TEST(PathTracer, WhiteFurnaceMirror) { furnace(PathMaterial::Mirror, 1.0f, 1.0f); }
TEST(PathTracer, WhiteFurnaceGlass) { furnace(PathMaterial::Glass, 1.0f, 1.0f); }

TEST(PathTracer, ConvergesAsOneOverSqrtSpp) {
    auto m = cornell();
    const MeshScene<BVH<Triangle>> scene(m);
    PathIntegrator integ;
    integ.materials = PathIntegrator::fromMesh(*m);
    integ.maxDepth = 5;
    CameraFrame f;
    f.eye = {0, 0, 3.2f};
    f.at = {0, 0, 0};
    f.fovDeg = 40.0f;
    const int w = 24, h = 24;
    const auto ref = render<16>(scene, integ, f, w, h, 1024);
    auto rmse = [&](int spp) {
        // Different sample indices than the first ones of the reference would be
        // better; the reference has 16x to 256x more samples, which dominates.
        const auto img = render<16>(scene, integ, f, w, h, spp);
        double se = 0;
        for (size_t i = 0; i < img.size(); ++i)
            if (i % 4 != 3) se += double(img[i] - ref[i]) * double(img[i] - ref[i]);
        return std::sqrt(se / (3.0 * w * h));
    };
    const double e4 = rmse(4), e16 = rmse(16), e64 = rmse(64);
    // 4x the samples halves the error (allowing for noise in the estimate itself and
    // for the reference sharing the first samples).
    EXPECT_GT(e4 / e16, 1.5) << e4 << " " << e16;
    EXPECT_LT(e4 / e16, 2.8) << e4 << " " << e16;
    EXPECT_GT(e16 / e64, 1.5) << e16 << " " << e64;
    EXPECT_LT(e16 / e64, 2.8) << e16 << " " << e64;
    // The box is lit: the mean is far from black.
    double mean = 0;
    for (size_t i = 0; i < ref.size(); i += 4) mean += ref[i];
    EXPECT_GT(mean / (w * h), 0.1);
}

// Image regression of the path tracer (deterministic per-pixel random numbers): the
// Cornell-like box at 64 spp against tests/surfaces/data/mesh_path_cornell.png, same
// metric and tolerance as the other integrators (tests/common/image_compare.h).
TEST(PathTracer, CornellMatchesReference) {
    auto m = cornell();
    const MeshScene<BVH<Triangle>> scene(m);
    PathIntegrator integ;
    integ.materials = PathIntegrator::fromMesh(*m);
    integ.maxDepth = 5;
    CameraFrame f;
    f.eye = {0, 0, 3.2f};
    f.at = {0, 0, 0};
    f.fovDeg = 40.0f;
    test::expectMatchesReference(std::string(RTFACT_TEST_DATA) + "/mesh_path_cornell.png", 48, 48,
                                 render<64>(scene, integ, f, 48, 48, 64));
}

// Glass needs the side a ray arrives from; meshes report it from the triangle winding
// (outward for closed meshes), so the integrators never look at the mesh themselves.
TEST(PathTracer, MeshReportsTheSideTheRayArrivesFrom) {
    const MeshScene<BVH<Triangle>> scene(std::make_shared<const Mesh>(flatCube()));
    auto arrive = [&](Vec3f org) {
        RayPacket<1> ray;
        ray.setLane(0, org, {0.0f, 0.0f, -1.0f});
        ray.finalize();
        const auto hit = scene.intersect<1>(ray, Mask<1>(true));
        EXPECT_GE(hit.id[0], 0);
        return scene.surface<1>(ray, hit, Mask<1>(true)).front[0];
    };
    EXPECT_TRUE(arrive({0.1f, 0.2f, 5.0f}));   // from outside
    EXPECT_FALSE(arrive({0.1f, 0.2f, 0.0f}));  // from inside
}
