// Image regression of the integrators on a small mesh scene (a height field with a
// sphere above it), against reference PNGs in tests/surfaces/data. Metric (see
// tests/common/image_compare.h): 8-bit sRGB, at most 0.5% of the pixels may differ by
// more than 8/255 in a channel, PSNR >= 35 dB; on failure actual, reference and diff
// images go to <build>/test-output. RTFACT_UPDATE_REFERENCES=1 regenerates them.
// Also: BVH and kd-tree, and all packet sizes, give the same picture.
#include <gtest/gtest.h>

#include "core/render/ao_integrator.h"
#include "core/render/direct_light_integrator.h"
#include "core/render/eyelight_integrator.h"
#include "core/render/framebuffer.h"
#include "core/render/jittered_sampler.h"
#include "core/render/pinhole_camera.h"
#include "core/render/ray_tracing_renderer.h"
#include "core/render/tile_scheduler.h"
#include "surfaces/mesh_scene.h"
#include "surfaces/whitted_integrator.h"
#include "test_meshes.h"
#include "tests/common/image_compare.h"

using namespace rtfact;
using namespace rtfact::surfaces;

namespace {

constexpr int kW = 96, kH = 72;

// illum: 2 diffuse orange sphere, 3 mirror, 7 glass (for Whitted).
std::shared_ptr<const Mesh> makeSceneMesh(int illum) {
    Mesh a = test::heightField(24, 4);
    Mesh s = test::uvSphere({0.1f, 0.55f, 0.0f}, 0.35f, 16);
    s.materials = {MeshMaterial{}};
    s.materials[0].kd = {0.9f, 0.4f, 0.2f};
    s.materials[0].illum = illum;
    s.materials[0].ks = Vec3f(0.9f);
    s.materialIds.assign(s.triangles(), 0);
    a.append(s);
    return std::make_shared<const Mesh>(a);
}
std::shared_ptr<const Mesh> sceneMesh() {
    static std::shared_ptr<const Mesh> m = makeSceneMesh(2);
    return m;
}

template <class Structure, int N, class Integ>
std::vector<float> render(const Integ& integ, int spp = 1, std::shared_ptr<const Mesh> mesh = nullptr) {
    static const MeshScene<Structure> defaultScene(sceneMesh());
    const MeshScene<Structure> other = mesh ? MeshScene<Structure>(mesh) : MeshScene<Structure>();
    const MeshScene<Structure>& scene = mesh ? other : defaultScene;
    CameraFrame f;
    f.eye = {1.6f, 1.7f, 2.2f};
    f.at = {0.0f, 0.2f, 0.0f};
    f.fovDeg = 45.0f;
    const PinholeCamera cam(f, kW, kH);
    RGBAFramebuffer fb(kW, kH);
    RayTracingRenderer<JitteredSampler, Integ> r{{}, integ};
    RenderOptions o;
    o.progress = false;
    o.tileSize = 16;
    o.spp = spp;
    renderImage<N>(r, scene, cam, fb, o);
    return fb.resolved(spp);
}

DirectLightIntegrator direct() {
    DirectLightIntegrator d;
    d.lights.push_back(PointLight{{-1.5f, 3.0f, 1.0f}, Vec3f(25.0f)});
    d.lights.push_back(DirectionalLight{{0.3f, -1.0f, -0.4f}, Vec3f(0.6f)});
    return d;
}

AOIntegrator ao() {
    AOIntegrator a;
    a.samples = 8;
    return a;
}

std::string ref(const std::string& name) { return std::string(RTFACT_TEST_DATA) + "/" + name; }

}  // namespace

TEST(MeshRender, EyeLightMatchesReference) {
    test::expectMatchesReference(ref("mesh_eyelight.png"), kW, kH, render<BVH<Triangle>, 64>(EyeLightIntegrator{}));
}
TEST(MeshRender, DirectLightMatchesReference) {
    test::expectMatchesReference(ref("mesh_direct.png"), kW, kH, render<BVH<Triangle>, 64>(direct()));
}
TEST(MeshRender, AmbientOcclusionMatchesReference) {
    test::expectMatchesReference(ref("mesh_ao.png"), kW, kH, render<BVH<Triangle>, 16>(ao()));
}

TEST(MeshRender, KdTreeAndPacketSizesGiveTheSameImage) {
    const auto a = render<BVH<Triangle>, 64>(direct());
    for (const auto& b :
         {render<KdTree<Triangle>, 64>(direct()), render<BVH<Triangle>, 1>(direct()),
          render<BVH<Triangle>, 256>(direct()), render<KdTree<Triangle>, simd::kNativeWidth>(direct())}) {
        const auto d = test::compareRGBA(a, b, kW, kH, 2);
        EXPECT_LE(d.differentFraction, 0.002);
    }
}

// The regression metric notices a different picture (a moved light).
TEST(MeshRender, MetricDetectsChanges) {
    DirectLightIntegrator moved = direct();
    moved.lights[0] = PointLight{{1.5f, 3.0f, -1.0f}, Vec3f(25.0f)};
    const auto d = test::compareRGBA(render<BVH<Triangle>, 64>(direct()), render<BVH<Triangle>, 64>(moved), kW, kH, 8);
    EXPECT_GT(d.differentFraction, 0.05);
}

// Whitted: a mirror sphere and a glass sphere over the height field, direct light with
// shadows on diffuse surfaces, depth limit 5.
TEST(MeshRender, WhittedMirrorMatchesReference) {
    const auto mesh = makeSceneMesh(3);
    WhittedIntegrator w;
    w.lights = direct().lights;
    w.materials = PathIntegrator::fromMesh(*mesh);
    test::expectMatchesReference(ref("mesh_whitted_mirror.png"), kW, kH, render<BVH<Triangle>, 64>(w, 1, mesh));
}
TEST(MeshRender, WhittedGlassMatchesReference) {
    const auto mesh = makeSceneMesh(7);
    WhittedIntegrator w;
    w.lights = direct().lights;
    w.materials = PathIntegrator::fromMesh(*mesh);
    test::expectMatchesReference(ref("mesh_whitted_glass.png"), kW, kH, render<BVH<Triangle>, 64>(w, 1, mesh));
}
