// The rendering pipeline: cameras, samplers, image output, the sphere scene against
// reference images, and determinism across packet sizes and thread counts.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/geometry/sphere_scene.h"
#include "core/render/direct_light_integrator.h"
#include "core/render/eyelight_integrator.h"
#include "core/render/framebuffer.h"
#include "core/render/image_io.h"
#include "core/render/jittered_sampler.h"
#include "core/render/orthographic_camera.h"
#include "core/render/pixel_center_sampler.h"
#include "core/render/ray_tracing_renderer.h"
#include "core/render/tile_scheduler.h"
#include "core/util/error.h"
#include "tests/common/image_compare.h"

using namespace rtfact;

namespace {

constexpr int kW = 160, kH = 120;

const SphereScene& scene() {
    static const SphereScene s = SphereScene::demo(100);
    return s;
}

CameraFrame frame() {
    CameraFrame f;
    f.eye = {0.0f, 7.0f, 9.0f};
    f.at = {0.0f, 0.0f, 0.0f};
    f.fovDeg = 50.0f;
    return f;
}

DirectLightIntegrator directIntegrator() {
    DirectLightIntegrator d;
    d.lights.push_back(PointLight{{-3.0f, 6.0f, 2.0f}, Vec3f(40.0f)});
    d.lights.push_back(DirectionalLight{{0.3f, -1.0f, -0.4f}, Vec3f(0.5f)});
    return d;
}

template <int N, class Integ>
std::vector<float> render(const Integ& integ, int threads = 0, int spp = 1) {
    const PinholeCamera cam(frame(), kW, kH);
    RGBAFramebuffer fb(kW, kH);
    RayTracingRenderer<JitteredSampler, Integ> r{{}, integ};
    RenderOptions o;
    o.threads = threads;
    o.spp = spp;
    o.progress = false;
    o.tileSize = 16;
    renderImage<N>(r, scene(), cam, fb, o);
    return fb.resolved(spp);
}

std::string refPath(const std::string& name) { return std::string(RTFACT_TEST_DATA) + "/" + name; }

}  // namespace

// Tiles clear their pixels before their first sample (RenderOptions::clear): rendering into
// a framebuffer that holds another image gives the image of a fresh one; without the clear the
// samples add to the old ones. Clear::Color keeps the depth (its minimum over passes).
TEST(Render, TilesClearTheirPixelsBeforeTheFirstSample) {
    const PinholeCamera cam(frame(), kW, kH);
    RayTracingRenderer<JitteredSampler, EyeLightIntegrator> r{};
    RenderOptions o;
    o.progress = false;
    o.tileSize = 16;
    RGBAFramebuffer fresh(kW, kH, true);
    renderImage<simd::kNativeWidth>(r, scene(), cam, fresh, o);
    for (const auto clear :
         {RenderOptions::Clear::None, RenderOptions::Clear::Color, RenderOptions::Clear::ColorAndDepth}) {
        RGBAFramebuffer fb(kW, kH, true);
        CameraFrame other = frame();
        other.eye = {5.0f, 3.0f, -6.0f};
        renderImage<simd::kNativeWidth>(r, scene(), PinholeCamera(other, kW, kH), fb, o);
        const std::vector<float> otherDepth = fb.depth();
        RenderOptions c = o;
        c.clear = clear;
        c.threads = 2;
        renderImage<simd::kNativeWidth>(r, scene(), cam, fb, c);
        if (clear == RenderOptions::Clear::None) {
            EXPECT_NE(fb.resolved(1), fresh.resolved(1));
            continue;
        }
        EXPECT_EQ(fb.resolved(1), fresh.resolved(1)) << "clear " << int(clear);
        if (clear == RenderOptions::Clear::ColorAndDepth) {
            EXPECT_EQ(fb.depth(), fresh.depth());
        } else {
            size_t nearer = 0;  // pixels where the other view's depth is the minimum
            for (size_t i = 0; i < otherDepth.size(); ++i) {
                ASSERT_EQ(fb.depth()[i], std::min(otherDepth[i], fresh.depth()[i])) << "pixel " << i;
                nearer += otherDepth[i] < fresh.depth()[i];
            }
            EXPECT_GT(nearer, 100u);
        }
    }
    // A region clear touches only that region (clipped to the image).
    RGBAFramebuffer fb = fresh;
    fb.clear(Region{kW - 8, 4, kW + 8, 12}, true);
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            const size_t p = size_t(y) * kW + size_t(x);
            const bool in = x >= kW - 8 && y >= 4 && y < 12;
            for (int c = 0; c < 4; ++c)
                ASSERT_EQ(fb.rawRGBA()[p * 4 + c], in ? 0.0f : fresh.rawRGBA()[p * 4 + c]) << x << "," << y;
            ASSERT_EQ(fb.depth()[p], in ? kInfinity : fresh.depth()[p]) << x << "," << y;
        }
}

// RGBAFramebuffer::write against per-pixel sums: runs of 4 lanes on 4 consecutive pixels
// of a row take the vector path, the rest (a run with an invalid lane, permuted lanes, a
// run across two rows) the scalar one; writes of the overwrite sample replace the pixels.
template <int N>
void checkFramebufferWrites() {
    constexpr int w = 15, h = 9;  // every lane its own pixel
    RGBAFramebuffer fb(w, h, true);
    std::vector<float> rgba(size_t(w) * h * 4, 0.0f), depth(size_t(w) * h, kInfinity);
    uint32_t seed = 7;
    auto rnd = [&] { return float((seed = seed * 1664525u + 1013904223u) >> 8) / float(1 << 24); };
    for (int pass = 0; pass < 3; ++pass) {
        const int sample = pass == 0 ? 5 : pass == 1 ? 0 : 1;  // pass 1 overwrites
        fb.overwriteSample(pass >= 1 ? 0 : -1, true);
        PixelSample<N> s;
        s.sample = sample;
        Radiance<N> r;
        Mask<N> valid(false);
        for (int i = 0; i < N; ++i) {
            const int run = (i / 4) % 4, k = i % 4, y = 2 * (i / 16);
            int x = 0, yy = y;
            if (run == 0) x = 1 + k;   // a row: vector
            if (run == 1) x = 5 + k;   // a row, lane 2 invalid: scalar
            if (run == 2) x = 12 - k;  // permuted: scalar
            if (run == 3) {            // across two rows: scalar
                x = 13 + k % 2;
                yy = y + k / 2;
            }
            s.px[i] = x;
            s.py[i] = yy;
            valid.set(i, !(run == 1 && k == 2) && (pass != 0 || i % 3 != 0));
            r.color.x[i] = rnd(), r.color.y[i] = rnd(), r.color.z[i] = rnd(), r.alpha[i] = rnd();
            r.depth[i] = rnd();
        }
        fb.template write<N>(s, r, valid);
        for (int i = 0; i < N; ++i) {
            if (!valid[i]) continue;
            const size_t p = size_t(s.py[i]) * w + size_t(s.px[i]);
            const float c[4] = {r.color.x[i], r.color.y[i], r.color.z[i], r.alpha[i]};
            for (int k = 0; k < 4; ++k) rgba[p * 4 + k] = pass == 1 ? c[k] : rgba[p * 4 + k] + c[k];
            depth[p] = pass == 1 ? float(r.depth[i]) : std::min(depth[p], float(r.depth[i]));
        }
        EXPECT_EQ(fb.resolved(1), rgba) << "N " << N << " pass " << pass;
        EXPECT_EQ(fb.depth(), depth) << "N " << N << " pass " << pass;
    }
}

TEST(Render, FramebufferWritesMatchPerPixelSums) {
    checkFramebufferWrites<1>();
    checkFramebufferWrites<16>();
    checkFramebufferWrites<64>();
}

TEST(Render, PacketBlockShapes) {
    EXPECT_EQ(packetBlockWidth(1), 1);
    EXPECT_EQ(packetBlockWidth(4), 2);
    EXPECT_EQ(packetBlockWidth(8), 4);
    EXPECT_EQ(packetBlockWidth(16), 4);
    EXPECT_EQ(packetBlockWidth(64), 8);
    EXPECT_EQ(packetBlockWidth(256), 16);
}

TEST(Render, PinholeCameraGeometry) {
    CameraFrame f;
    f.eye = {1, 2, 3};
    f.at = {1, 2, -7};
    f.fovDeg = 90.0f;
    const PinholeCamera cam(f, 200, 100);
    RayPacket<1> r;
    cam.generate<1>(Packet<1>(100.0f), Packet<1>(50.0f), r);  // image centre
    EXPECT_NEAR(r.dir.z[0], -1.0f, 1e-6f);
    EXPECT_EQ(r.org.lane(0), Vec3f(1, 2, 3));
    EXPECT_TRUE(r.commonOrigin);
    cam.generate<1>(Packet<1>(100.0f), Packet<1>(0.0f), r);  // top edge: 45 degrees up
    EXPECT_NEAR(r.dir.y[0], std::sqrt(0.5f), 1e-5f);
    EXPECT_NEAR(cam.cone().slope, 2.0f / 100.0f, 1e-6f);
}

TEST(Render, OrthographicCameraGeometry) {
    CameraFrame f;
    f.eye = {0, 0, 5};
    f.at = {0, 0, 0};
    const OrthographicCamera cam(f, 4.0f, 100, 100);
    RayPacket<4> r;
    cam.generate<4>(Packet<4>(0.0f), Packet<4>(50.0f), r);
    EXPECT_NEAR(r.org.x[0], -2.0f, 1e-5f);
    EXPECT_NEAR(r.dir.z[0], -1.0f, 1e-6f);
    EXPECT_FALSE(r.commonOrigin);
}

// Every packet size must give a pixel the same ray to the last bit: integrators that
// classify samples (a transfer-function entry, a cell) turn a one-ulp difference into a
// visible one. Whole-packet arithmetic on 256-ray packets (32 AVX2 chunks) once compiled
// without the FMAs the smaller sizes got, and a volume MIP pixel changed.
template <int N, class Cam>
void expectRaysMatchSingleRays(const Cam& cam, const char* name) {
    Packet<N> px, py;
    for (int i = 0; i < N; ++i) {
        px[i] = 31.25f + float(i % 16) * 0.93f;
        py[i] = 17.5f + float(i / 16) * 1.37f;
    }
    RayPacket<N> rays;
    cam.template generate<N>(px, py, rays);
    int differing = 0;
    for (int i = 0; i < N; ++i) {
        RayPacket<1> one;
        cam.template generate<1>(Packet<1>(px[i]), Packet<1>(py[i]), one);
        for (int a = 0; a < 3; ++a) {
            differing += rays.dir[a][i] != float(one.dir[a]);
            differing += rays.org[a][i] != float(one.org[a]);
        }
    }
    EXPECT_EQ(differing, 0) << name << " N=" << N;
}

TEST(Render, CameraRaysBitIdenticalAtEveryPacketSize) {
    CameraFrame f = frame();
    f.eye = {0.37f, 7.3f, 9.1f};
    const PinholeCamera pin(f, 640, 480);
    const OrthographicCamera ortho(f, 3.3f, 640, 480);
    expectRaysMatchSingleRays<simd::kNativeWidth>(pin, "pinhole");
    expectRaysMatchSingleRays<64>(pin, "pinhole");
    expectRaysMatchSingleRays<256>(pin, "pinhole");
    expectRaysMatchSingleRays<simd::kNativeWidth>(ortho, "ortho");
    expectRaysMatchSingleRays<64>(ortho, "ortho");
    expectRaysMatchSingleRays<256>(ortho, "ortho");
}

TEST(Render, JitteredSamplerIsDeterministicAndInsidePixels) {
    const JitteredSampler s;
    Packet<16, int32_t> px = Packet<16, int32_t>::ramp(0), py(3);
    Packet<16> ox, oy, ox2, oy2;
    s.offsets<16>(px, py, 5, ox, oy);
    s.offsets<16>(px, py, 5, ox2, oy2);
    float mean = 0;
    for (int i = 0; i < 16; ++i) {
        EXPECT_EQ(ox[i], ox2[i]);
        EXPECT_GE(ox[i], 0.0f);
        EXPECT_LT(ox[i], 1.0f);
        EXPECT_GE(oy[i], 0.0f);
        EXPECT_LT(oy[i], 1.0f);
        mean += ox[i] / 16.0f;
    }
    EXPECT_GT(mean, 0.2f);
    EXPECT_LT(mean, 0.8f);
    s.offsets<16>(px, py, 0, ox, oy);
    EXPECT_EQ(ox[3], 0.5f);
}

TEST(Render, SphereSceneEyeLightMatchesReference) {
    test::expectMatchesReference(refPath("spheres_eyelight.png"), kW, kH,
                                 render<simd::kNativeWidth>(EyeLightIntegrator{}));
}

TEST(Render, SphereSceneDirectLightMatchesReference) {
    test::expectMatchesReference(refPath("spheres_direct.png"), kW, kH, render<64>(directIntegrator()));
}

TEST(Render, DeterministicAcrossPacketSizesAndThreads) {
    const auto ref = render<64>(directIntegrator(), 0);
    // Same packet size, different thread counts: bit-identical.
    EXPECT_EQ(render<64>(directIntegrator(), 1), ref);
    // Different packet sizes: the same arithmetic per lane except the reciprocal
    // estimate at width 1, so allow last-bit differences only.
    for (const auto& other : {render<1>(directIntegrator(), 2), render<simd::kNativeWidth>(directIntegrator(), 2),
                              render<256>(directIntegrator(), 1)}) {
        const auto d = test::compareRGBA(ref, other, kW, kH, 1);
        EXPECT_LE(d.differentFraction, 0.001);
        EXPECT_GE(d.psnr, 50.0);
    }
}

TEST(Render, ProgressiveSamplesAverage) {
    const auto one = render<16>(EyeLightIntegrator{}, 0, 1);
    const auto four = render<16>(EyeLightIntegrator{}, 0, 4);
    const auto d = test::compareRGBA(one, four, kW, kH, 8);
    EXPECT_GT(d.psnr, 20.0);                // the same picture...
    EXPECT_GT(d.differentFraction, 0.001);  // ...but antialiased edges
}

TEST(ImageIO, RoundTripAndAtomicWrite) {
    const std::string dir = test::testOutDir() + "/imageio";
    std::filesystem::create_directories(dir);
    std::vector<float> rgba(4 * 3 * 2);
    for (size_t i = 0; i < rgba.size(); ++i) rgba[i] = float(i % 4) / 3.0f;
    for (const char* ext : {".png", ".exr", ".tif"}) {
        const std::string p = dir + "/img" + ext;
        writeImage(p, 3, 2, rgba);
        const Image img = readImage(p);
        ASSERT_EQ(img.width, 3);
        ASSERT_EQ(img.height, 2);
        EXPECT_NEAR(img.at(1, 1, 1), 1.0f / 3.0f, 0.01f) << ext;
    }
    for (const auto& e : std::filesystem::directory_iterator(dir))
        EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << "temporary file left behind";
    EXPECT_THROW(writeImage(dir + "/missing/x.png", 3, 2, rgba), Error);
    EXPECT_THROW(checkImageWritable(dir + "/x.bmpx"), Error);
    EXPECT_THROW(readImage(dir + "/nothing.png"), Error);
}

// OpenImageIO comes only through the module loaded on the first image read or write
// (core/render/image_codec.h): a binary linked to it directly starts 0.6 s slower.
TEST(ImageIO, OpenImageIOLoadsOnFirstUse) {
    const auto mapped = [](const char* name) {
        std::ifstream maps("/proc/self/maps");
        std::string line;
        while (std::getline(maps, line))
            if (line.find(name) != std::string::npos) return true;
        return false;
    };
    EXPECT_FALSE(mapped("libOpenImageIO.so") && !mapped("rtfact_image_oiio.so"))
        << "OpenImageIO is linked into the test binary instead of loaded through rtfact_image_oiio.so";
    const std::string dir = test::testOutDir() + "/imageio_module";
    std::filesystem::create_directories(dir);
    writeImage(dir + "/a.png", 2, 2, std::vector<float>(16, 0.5f));
    EXPECT_EQ(readImage(dir + "/a.png").width, 2);
    EXPECT_TRUE(mapped("rtfact_image_oiio.so"));
    EXPECT_TRUE(mapped("libOpenImageIO.so"));
}

TEST(Render, ImageMetricDetectsDifferences) {
    // The regression metric must notice a different picture (guards against a gate
    // that cannot fail).
    const auto a = render<16>(EyeLightIntegrator{}), b = render<16>(directIntegrator());
    const auto d = test::compareRGBA(a, b, kW, kH, 8);
    EXPECT_GT(d.differentFraction, 0.05);
    EXPECT_LT(d.psnr, 35.0);
}
