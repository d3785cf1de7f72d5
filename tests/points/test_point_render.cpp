// Image regression on the shipped real scan (Stanford Bunny range scan bun000): the full
// pipeline (the engine's PLY load, PCL normals, spacing radii, LoD tree; eyelight) against a
// reference PNG. Metric (tests/common/image_compare.h): 8-bit sRGB; at most 0.5% of
// pixels may differ by more than 8/255 in a channel and PSNR must be >= 35 dB.
// Also: LoD at quality 4 stays >= 30 dB PSNR from full detail on the same view; packet
// sizes 1, native and 256 agree at full detail within the core's tolerance.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "common/image_compare.h"
#include "core/render/ao_integrator.h"
#include "core/render/direct_light_integrator.h"
#include "core/render/eyelight_integrator.h"
#include "core/render/framebuffer.h"
#include "core/render/pinhole_camera.h"
#include "core/render/pixel_center_sampler.h"
#include "core/render/ray_tracing_renderer.h"
#include "core/render/tile_scheduler.h"
#include "engine/built_scene.h"
#include "points/point_scene.h"

using namespace rtfact;
using namespace rtfact::points;
namespace fs = std::filesystem;

namespace {

constexpr int kSize = 160;

// The scan is tracked in datasets/: missing, it is a failure (callers ASSERT_TRUE).
// Loaded, prepared and built by the engine, as `rtfact points` does.
[[nodiscard]] bool loadBunny(std::shared_ptr<PointScene>& scene, CameraFrame& frame, ColorMode mode = ColorMode::Rgb) {
    const fs::path f = fs::path(RTFACT_POINTS_DATA) / "bunny_bun000.ply";
    if (!fs::exists(f)) {
        ADD_FAILURE() << "tracked dataset missing: " << f;
        return false;
    }
    engine::OpenOptions oo;
    oo.kind = engine::SceneKind::Points;
    oo.progress = false;
    const engine::Scene sc = engine::open({f.string()}, oo);
    frame = fitCamera(sc.bounds(), 40.0f, 1.0f, {0.0f, 0.1f, 1.0f});
    engine::Settings settings;
    settings.points.color = mode;
    scene = engine::builtPoints(sc, settings, frame);
    return true;
}

template <class Integrator = EyeLightIntegrator>
std::vector<float> render(const PointScene& scene, const CameraFrame& frame, float quality,
                          const Integrator& integ = {}, RenderStats* stats = nullptr) {
    const PinholeCamera cam(frame, kSize, kSize);
    const_cast<PointScene&>(scene).setLoD(cam.cone(), quality);
    RGBAFramebuffer fb(kSize, kSize);
    const RayTracingRenderer<PixelCenterSampler, Integrator> r{{}, integ};
    RenderOptions ro;
    ro.progress = false;
    const RenderStats st = renderImage<64>(r, scene, cam, fb, ro);
    if (stats) *stats = st;
    return fb.resolved(1);
}

}  // namespace

// The core's direct-light (with shadow rays) and AO integrators on discs, and the LoD cut.
TEST(PointRender, DirectAOAndLoDMatchReferences) {
    std::shared_ptr<PointScene> scene;
    CameraFrame frame;
    ASSERT_TRUE(loadBunny(scene, frame));
    const std::string dir = RTFACT_TEST_DATA;
    DirectLightIntegrator direct;
    const AABB b = scene->bounds();
    direct.lights.push_back(
        PointLight{frame.eye + Vec3f(0, 1, 0) * length(b.extent()), Vec3f(2.5f * dot(b.extent(), b.extent()))});
    direct.lights.push_back(DirectionalLight{{0.3f, -1.0f, -0.4f}, Vec3f(0.5f)});
    test::expectMatchesReference(dir + "/bunny_bun000_direct.png", kSize, kSize, render(*scene, frame, 0.0f, direct));
    AOIntegrator ao;
    ao.samples = 8;
    ao.offset = 4e-3f;
    ao.minDistance = 4e-3f;
    test::expectMatchesReference(dir + "/bunny_bun000_ao.png", kSize, kSize, render(*scene, frame, 0.0f, ao));
    // A coarse cut (quality 8) answers many rays with representative splats: its own
    // reference (the kd-tree, the default structure). The wide BVH's cut (other
    // subtrees, so other representatives) stays within 1 dB of it against full detail
    // (measured: wide 27.3 dB, kd 27.0 dB; the kd-tree's 28.1 dB before its splits took the
    // centres' spread axis, session 37: a given quality cuts coarser, faster at equal PSNR;
    // 26.5 dB then, 27.0 since ranges of up to 64 discs are rank-sorted, session 38: the
    // scan's tied coordinates are split in input order, so other clusters);
    // the documented bound, >= 30 dB at quality 4, is LoDStaysCloseToFullDetail below.
    const auto lod8 = render(*scene, frame, 8.0f);
    test::expectMatchesReference(dir + "/bunny_bun000_lod8.png", kSize, kSize, lod8);
    const auto full = render(*scene, frame, 0.0f);
    PointScene wide;
    wide.accel = PointAccel::Wide;
    wide.build(scene->discs());
    const double kdDb = test::compareRGBA(lod8, full, kSize, kSize, 8).psnr;
    const double wideDb = test::compareRGBA(render(wide, frame, 8.0f), full, kSize, kSize, 8).psnr;
    std::printf("quality 8 against full detail: wide BVH %.2f dB, kd-tree %.2f dB\n", wideDb, kdDb);
    EXPECT_GE(wideDb, kdDb - 1.0);
}

TEST(PointRender, BunnyScanMatchesReference) {
    std::shared_ptr<PointScene> scene;
    CameraFrame frame;
    ASSERT_TRUE(loadBunny(scene, frame));
    const auto img = render(*scene, frame, 0.0f);
    test::expectMatchesReference(std::string(RTFACT_TEST_DATA) + "/bunny_bun000_eyelight.png", kSize, kSize, img);
}

TEST(PointRender, LoDStaysCloseToFullDetail) {
    std::shared_ptr<PointScene> scene;
    CameraFrame frame;
    ASSERT_TRUE(loadBunny(scene, frame));
    RenderStats fullStats, lodStats;
    const auto full = render(*scene, frame, 0.0f, EyeLightIntegrator{}, &fullStats);
    const auto lod = render(*scene, frame, 4.0f, EyeLightIntegrator{}, &lodStats);
    const test::ImageDiff d = test::compareRGBA(lod, full, kSize, kSize, 8);
    EXPECT_GE(d.psnr, 30.0);
    EXPECT_EQ(fullStats.counters.lodNodesHit, 0u);  // full detail: input discs only
    EXPECT_GT(lodStats.counters.lodNodesHit, 0u);   // the cut was used
}

TEST(PointRender, PacketSizesAgree) {
    std::shared_ptr<PointScene> scene;
    CameraFrame frame;
    ASSERT_TRUE(loadBunny(scene, frame));
    const PinholeCamera cam(frame, 64, 64);
    auto renderN = [&]<int N>() {
        RGBAFramebuffer fb(64, 64);
        const RayTracingRenderer<PixelCenterSampler, EyeLightIntegrator> r{{}, {}};
        RenderOptions ro;
        ro.progress = false;
        renderImage<N>(r, *scene, cam, fb, ro);
        return fb.resolved(1);
    };
    // Full detail: the same discs for every packet size, so the core's tolerance
    // (tests/core/test_render.cpp: last-bit differences only).
    scene->setLoD(cam.cone(), 0.0f);
    const auto full1 = renderN.template operator()<1>();
    for (const auto& other : {renderN.template operator()<simd::kNativeWidth>(), renderN.template operator()<256>()}) {
        const test::ImageDiff d = test::compareRGBA(full1, other, 64, 64, 1);
        EXPECT_LE(d.differentFraction, 0.001);
        EXPECT_GE(d.psnr, 50.0);
    }
    // With LoD on, decisions are per packet (first active ray), so packet sizes may differ slightly.
    scene->setLoD(cam.cone(), 1.0f);
    const auto a = renderN.template operator()<1>();
    const auto b = renderN.template operator()<simd::kNativeWidth>();
    const auto c = renderN.template operator()<256>();
    EXPECT_GE(test::compareRGBA(a, b, 64, 64, 8).psnr, 30.0);
    EXPECT_GE(test::compareRGBA(a, c, 64, 64, 8).psnr, 30.0);
    // The bunny is in the picture (a blank render would agree with itself): background is 0.05.
    int lit = 0;
    for (size_t p = 0; p < 64 * 64; ++p) lit += full1[p * 4] > 0.2f;
    EXPECT_GT(lit, 64 * 64 / 10);
}

// AO rays leave from their own hit points: the kd-tree cuts such packets at their nearest
// live lane, so with LoD on no lane is cut coarser than alone and every packet size gives
// the single-ray image (the first lane's origin standing for the packet made 64-ray packets
// differ in ~1% of the pixels, lit against black at depth edges). As the engine sets AO up.
TEST(PointRender, AOPacketSizesAgreeWithLoD) {
    std::shared_ptr<PointScene> scene;
    CameraFrame frame;
    ASSERT_TRUE(loadBunny(scene, frame));
    constexpr int S = 96;
    const PinholeCamera cam(frame, S, S);
    scene->setLoD(cam.cone(), 2.0f);
    AOIntegrator ao;
    ao.samples = 8;
    ao.offset = 4e-3f;
    ao.minDistance = 4e-3f;
    auto renderN = [&]<int N>() {
        RGBAFramebuffer fb(S, S);
        const RayTracingRenderer<PixelCenterSampler, AOIntegrator> r{{}, ao};
        RenderOptions ro;
        ro.progress = false;
        renderImage<N>(r, *scene, cam, fb, ro);
        return fb.resolved(1);
    };
    const auto single = renderN.template operator()<1>();
    for (const auto& other : {renderN.template operator()<simd::kNativeWidth>(), renderN.template operator()<64>(),
                              renderN.template operator()<256>()}) {
        const test::ImageDiff d = test::compareRGBA(single, other, S, S, 1);
        EXPECT_LE(d.differentFraction, 0.002);
    }
    int lit = 0;
    for (size_t p = 0; p < size_t(S) * S; ++p) lit += single[p * 4] > 0.2f;
    EXPECT_GT(lit, S * S / 10);
}
