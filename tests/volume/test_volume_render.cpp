// Volume rendering: trilinear sampling against linear fields, homogeneous-slab
// transmittance against exp(-sigma d), empty-space skipping and packet size leaving the
// image unchanged, and image regression of every mode on the shipped tooth CT.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <random>

#include "common/image_compare.h"
#include "core/render/framebuffer.h"
#include "core/render/pinhole_camera.h"
#include "render_volume_image.h"
#include "volume/volume_generators.h"
#include "volume/volume_integrator.h"
#include "volume/volume_io.h"
#include "volume/volume_scene.h"

using namespace rtfact;
using namespace rtfact::volume;

namespace {

constexpr int kW = simd::kNativeWidth;

TFTable flatTable(float lo, float hi, float opacity, float step) {
    TransferFunction tf;
    tf.colors = {{0.0f, {1, 1, 1}}, {1.0f, {1, 1, 1}}};
    tf.opacity = {{0.0f, opacity}, {1.0f, opacity}};
    return buildTable(tf, {lo, hi}, step);
}

template <class T>
void checkTrilinear(VolumeGrid g, const std::function<float(float, float, float)>& f, float tol) {
    const BrickedVolume bv = brickVolume(g);
    const VolumeScene<T> s(bv, flatTable(0, 1, 0.5f, 0.5f), {});
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int it = 0; it < 200; ++it) {
        Vec3<kW> p;
        Vec3f ref[kW];
        for (int i = 0; i < kW; ++i) {
            ref[i] = Vec3f(u(rng) * float(g.dims[0] - 1), u(rng) * float(g.dims[1] - 1), u(rng) * float(g.dims[2] - 1));
            if (it == 0 && i == 0)
                ref[i] = Vec3f(float(g.dims[0] - 1), float(g.dims[1] - 1), float(g.dims[2] - 1));  // far corner
            p.setLane(i, ref[i]);
        }
        const Packet<kW> v = VolumeIntegrator::sample<kW>(s, VolumeIntegrator::clampToGrid<kW>(s, p));
        for (int i = 0; i < kW; ++i) {
            const float expect = f(ref[i].x, ref[i].y, ref[i].z);
            EXPECT_NEAR(v[i] * g.scale + g.offset, expect, tol * std::max(1.0f, std::fabs(expect)));
            // single-lane path gives the same value
            const Packet<1> v1 = VolumeIntegrator::sample<1>(s, VolumeIntegrator::clampToGrid<1>(s, Vec3<1>(ref[i])));
            EXPECT_NEAR(float(v1), v[i], 1e-4f * std::max(1.0f, std::fabs(v[i])));
        }
    }
}

template <class T>
VolumeGrid linearGrid(int nx, int ny, int nz, Storage st, const std::function<float(float, float, float)>& f) {
    VolumeGrid g;
    g.dims[0] = nx;
    g.dims[1] = ny;
    g.dims[2] = nz;
    g.allocate(st);
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) g.data<T>()[g.index(i, j, k)] = T(f(float(i), float(j), float(k)));
    return g;
}

struct Rendered {
    int w, h;
    std::vector<float> rgba;
    uint64_t samples, skipped;
};

// packet: the rays a packet (renderVolumeImage's sizes)
Rendered render(int packet, const VolumeGrid& g, const TransferFunction& tf, VolumeRenderSettings rs, int w = 128,
                int h = 128) {
    const BrickedVolume bv = brickVolume(g);
    const auto [lo, hi] = bv.valueRange();
    const TFTable table = buildTable(tf, resolveWindow(tf, lo, hi, std::nullopt, std::nullopt), rs.stepVoxels);
    if (rs.mode == VolumeMode::Iso) rs.iso = lo + 0.4f * (hi - lo);
    Rendered out{w, h, {}, 0, 0};
    withVolumeScene(bv, table, rs, [&](const auto& scene) {
        const PinholeCamera cam(fitCamera(scene.bounds(), 40.0f, float(w) / float(h), {0.45f, -1.0f, 0.35f}, {0, 0, 1}),
                                w, h);
        RGBAFramebuffer fb(w, h);
        RenderOptions ro;
        ro.threads = 2;
        ro.progress = false;
        const RenderStats st = test::renderVolumeImage(packet, scene, cam, fb, ro);
        out.rgba = fb.resolved(1);
        out.samples = st.counters.volumeSamples;
        out.skipped = st.counters.volumeSkipped;
    });
    return out;
}

float maxAbsDiff(const std::vector<float>& a, const std::vector<float>& b) {
    float m = 0;
    for (size_t i = 0; i < a.size(); ++i) m = std::max(m, std::fabs(a[i] - b[i]));
    return m;
}

// The shipped tooth CT. Tracked data is never optional: a missing file throws (the test
// fails naming it) instead of skipping.
const VolumeGrid& tooth() {
    static VolumeGrid g = [] {
        VolumeLoadOptions o;
        o.progress = false;
        return loadVolume(std::string(RTFACT_DATASETS) + "/volumes/tooth_103x94x161_uint8.raw", o);
    }();
    return g;
}

}  // namespace

TEST(VolumeSampling, TrilinearMatchesLinearFieldsF32) {
    auto f = [](float x, float y, float z) { return 0.5f + 1.5f * x - 2.0f * y + 0.25f * z; };
    checkTrilinear<float>(linearGrid<float>(7, 6, 5, Storage::F32, f), f, 1e-5f);
}
TEST(VolumeSampling, TrilinearMatchesLinearFieldsU16) {
    auto f = [](float x, float y, float z) { return x + 3.0f * y + 7.0f * z; };
    checkTrilinear<uint16_t>(linearGrid<uint16_t>(33, 20, 17, Storage::U16, f), f, 1e-5f);
}
TEST(VolumeSampling, TrilinearMatchesLinearFieldsU8) {
    auto f = [](float x, float y, float z) { return 2.0f * x + 3.0f * y + 5.0f * z; };
    checkTrilinear<uint8_t>(linearGrid<uint8_t>(20, 19, 18, Storage::U8, f), f, 1e-5f);
}

// Rays along +z through a homogeneous volume of 64 voxels depth: transmittance must be
// exp(-sigma d) with sigma = -ln(1 - a) per voxel for TF opacity a. Steps dividing the
// depth: relative error <= 1e-3. Other steps: |ln T - ln T_exact| <= sigma * step (the
// last sample covers at most one step past the end).
TEST(VolumeDVR, SlabTransmittanceMatchesClosedForm) {
    const BrickedVolume g = brickVolume(makeSlab(9, 9, 65, 0, 64, 255));
    const float a = 0.02f, sigma = -std::log(1.0f - a), d = 64.0f;
    const float exact = std::exp(-sigma * d);
    for (float step : {0.25f, 0.5f, 1.0f, 2.0f, 0.3f, 0.7f}) {
        VolumeRenderSettings rs;
        rs.stepVoxels = step;
        rs.maxStepMultiple = 1;  // the plain march (adaptive steps: VolumeAdaptiveSteps below)
        const VolumeScene<uint8_t> s(g, flatTable(0, 255, a, step), rs);
        RayPacket<kW> rays;
        for (int i = 0; i < kW; ++i) rays.setLane(i, {1.0f + 6.0f * float(i) / kW, 4.0f, -5.0f}, {0, 0, 1});
        rays.finalize();
        PixelSample<kW> ps;
        const Radiance<kW> r = VolumeIntegrator{}.eval<kW>(s, rays, Mask<kW>(true), ps);
        for (int i = 0; i < kW; ++i) {
            const float T = 1.0f - r.alpha[i];
            const bool divides = std::fabs(d / step - std::round(d / step)) < 1e-4f;
            if (divides)
                EXPECT_NEAR(T, exact, 1e-3f * exact) << "step " << step;
            else
                EXPECT_LE(std::fabs(std::log(T) - std::log(exact)), sigma * step * 1.001f) << "step " << step;
        }
    }
}

// The march leaves out the TF fetch when no lane's entry lies in [tfVisibleLo,
// tfVisibleHi): those must bracket exactly the entries with opacity, for a band in the
// middle of the table, one at either end, and none at all.
TEST(VolumeDVR, VisibleEntryRangeBracketsTheOpacity) {
    const VolumeGrid ph = makeSheppLogan(16, Storage::U8);
    const BrickedVolume bv = brickVolume(ph);
    for (const char* json :
         {R"({"colors":[[0,1,1,1],[1,1,1,1]],"opacity":[[0,0],[0.3,0],[0.31,0.2],[0.6,0.2],[0.61,0],[1,0]]})",
          R"({"colors":[[0,1,1,1],[1,1,1,1]],"opacity":[[0,0.1],[0.5,0],[1,0]]})",
          R"({"colors":[[0,1,1,1],[1,1,1,1]],"opacity":[[0,0],[0.5,0],[1,0.4]]})",
          R"({"colors":[[0,1,1,1],[1,1,1,1]],"opacity":[[0,0],[1,0]]})"}) {
        const TransferFunction tf = parseTransferFunctionJson(json, "t");
        const VolumeScene<uint8_t> s(bv, buildTable(tf, {0.0f, 255.0f}, 0.5f), {});
        int first = -1, last = -1;
        for (int e = 0; e < s.tf.size; ++e)
            if (s.tf.a[size_t(e)] > 0.0f) {
                if (first < 0) first = e;
                last = e;
            }
        if (first < 0) {
            EXPECT_LE(s.tfVisibleHi, s.tfVisibleLo) << json;
            continue;
        }
        EXPECT_EQ(s.tfVisibleLo, float(first)) << json;
        EXPECT_EQ(s.tfVisibleHi, float(last + 1)) << json;
        EXPECT_TRUE(first > 0 || last + 1 < s.tf.size) << json;  // each case leaves some out
    }
}

TEST(VolumeDVR, EmptySpaceSkippingChangesNoPixel) {
    const VolumeGrid ph = makeSheppLogan(64, Storage::U16);
    const TransferFunction tf = parseTransferFunctionJson(
        R"({"colors":[[0,0.2,0.3,0.9],[1,1,0.9,0.8]],"opacity":[[0,0],[0.15,0],[0.2,0.05],[0.3,0.2],[0.5,0],[1,0]]})",
        "t");
    // pre-integrated: a jump closes the segment into the empty cube and opens the one out of
    // it, and the cube's own segments add nothing
    for (const bool pre : {false, true})
        for (VolumeMode m : {VolumeMode::DVR, VolumeMode::Shaded, VolumeMode::MIP}) {
            if (pre && m == VolumeMode::MIP) continue;
            VolumeRenderSettings on, off;
            on.mode = off.mode = m;
            on.preintegrated = off.preintegrated = pre;
            off.skipping = false;
            const Rendered a = render(16, ph, tf, on), b = render(16, ph, tf, off);
            // identical sample positions: tolerance only for float noise
            EXPECT_LE(maxAbsDiff(a.rgba, b.rgba), 1e-6f) << int(m) << " pre " << pre;
            EXPECT_GT(a.skipped, 0u) << int(m);
            EXPECT_LT(a.samples, b.samples) << int(m);
        }
    // Iso: brackets across skipped cells are wider, refinement converges to the same
    // crossing up to the bisection's resolution.
    VolumeRenderSettings on, off;
    on.mode = off.mode = VolumeMode::Iso;
    off.skipping = false;
    const Rendered a = render(16, ph, tf, on), b = render(16, ph, tf, off);
    EXPECT_LE(maxAbsDiff(a.rgba, b.rgba), 0.02f);
}

// Packet sizes must not change the image. The cameras give every packet size
// bit-identical rays (core test Render.CameraRaysBitIdenticalAtEveryPacketSize): on AVX2
// the 256-ray packets once got rays one ulp off, and a MIP pixel whose maximum sat on a
// transfer-function entry boundary jumped one entry (0.001). The 1e-4 left is for the
// scalar (W = 1) and vector marches contracting their arithmetic differently. Every voxel
// layout the march reads: u8 from its y-z quads, u16 from its y-pairs (the benchmarks' CT
// and phantom path), f32 from the brick pool.
TEST(VolumeDVR, PacketAndSingleRayGiveTheSameImage) {
    const TransferFunction tf = transferFunctionPreset("viridis");
    for (Storage st : {Storage::U8, Storage::U16, Storage::F32}) {
        const VolumeGrid ph = makeSheppLogan(48, st);
        for (VolumeMode m : {VolumeMode::DVR, VolumeMode::Shaded, VolumeMode::MIP, VolumeMode::Iso, VolumeMode(-1)}) {
            VolumeRenderSettings rs;
            rs.mode = m;
            if (int(m) < 0) rs.mode = VolumeMode::DVR, rs.preintegrated = true;  // pre-integrated DVR
            const std::string what = std::string(storageName(st)) + " mode " + std::to_string(int(m));
            const Rendered one = render(1, ph, tf, rs, 64, 64);
            // one native chunk (the one-chunk march: on AVX2 16 rays are two chunks; a scalar
            // build's is the single ray), then groups
            if constexpr (kW != 1 && kW != 16) {
                const Rendered pn = render(kW, ph, tf, rs, 64, 64);
                EXPECT_LE(maxAbsDiff(one.rgba, pn.rgba), 1e-4f) << what;
            }
            const Rendered p16 = render(16, ph, tf, rs, 64, 64);
            const Rendered p64 = render(64, ph, tf, rs, 64, 64);
            const Rendered p256 = render(256, ph, tf, rs, 64, 64);
            EXPECT_GT(one.samples, 0u) << what;
            EXPECT_LE(maxAbsDiff(one.rgba, p16.rgba), 1e-4f) << what;
            EXPECT_LE(maxAbsDiff(one.rgba, p64.rgba), 1e-4f) << what;
            EXPECT_LE(maxAbsDiff(one.rgba, p256.rgba), 1e-4f) << what;
            EXPECT_EQ(one.samples, p64.samples) << what;
        }
    }
}

// Image regression on the shipped tooth CT, one reference per mode. Metric (shared with
// the other domains, tests/common/image_compare.h): 8-bit sRGB; at most 0.5% of pixels
// may differ by more than 8/255 in a channel and PSNR must stay >= 35 dB.
class ToothRegression : public ::testing::TestWithParam<const char*> {};
TEST_P(ToothRegression, MatchesReference) {
    ASSERT_NO_THROW(tooth()) << "tracked dataset datasets/volumes/tooth_103x94x161_uint8.raw";
    const std::string mode = GetParam();
    VolumeRenderSettings rs;
    rs.mode = mode == "shaded" ? VolumeMode::Shaded
              : mode == "mip"  ? VolumeMode::MIP
              : mode == "iso"  ? VolumeMode::Iso
                               : VolumeMode::DVR;
    const TransferFunction tf = transferFunctionPreset(mode == "mip" ? "grayscale" : "ct-bone");
    const Rendered r = render(64, tooth(), tf, rs, 160, 160);
    test::expectMatchesReference(std::string(RTFACT_TEST_DATA) + "/tooth_" + mode + ".png", r.w, r.h, r.rgba);
}
INSTANTIATE_TEST_SUITE_P(Modes, ToothRegression, ::testing::Values("dvr", "shaded", "mip", "iso"));

TEST(VolumeBricks, MatchDenseGridAndShareZeroBricks) {
    VolumeGrid g = makeSheppLogan(37, Storage::U16);  // not a multiple of the brick size
    const BrickedVolume b = brickVolume(g);
    for (int k = 0; k < 37; ++k)
        for (int j = 0; j < 37; ++j)
            for (int i = 0; i < 37; ++i)
                ASSERT_EQ(b.stored(i, j, k), g.stored(g.index(i, j, k))) << i << "," << j << "," << k;
    EXPECT_LT(b.storedBricks(), b.brickCount());  // the air around the phantom shares brick 0
    EXPECT_LE(double(b.pool.capacity()), 1.5 * double(g.voxelCount() * 2) + 4096.0);
    // the y-pair copy: 8 x 9 x 9 pairs per brick (1.78x the pool)
    EXPECT_LE(double(b.pairs.capacity()), 1.78 * double(b.pool.capacity()) + 4096.0);
    EXPECT_TRUE(b.quads.empty()) << "u16 gets y-pairs";
    // u8: the y-z quads, 8 x 8 x 9 quads per brick (3.16x the pool), and no pairs
    const BrickedVolume b8 = brickVolume(makeSheppLogan(37, Storage::U8));
    ASSERT_FALSE(b8.quads.empty());
    EXPECT_TRUE(b8.pairs.empty());
    EXPECT_LE(double(b8.quads.capacity()), 3.16 * double(b8.pool.capacity()) + 4096.0);
}

// OpenVDB input is bricked from the sparse tree; it must render like the densified grid.
TEST(VolumeBricks, SparseVdbRendersLikeDense) {
    const std::string p = std::string(RTFACT_SHARED_DATA) + "/volumes/bonsai_ct_density.vdb";
    if (!std::filesystem::exists(p)) GTEST_SKIP() << "shared datasets not present: " << p;
    VolumeLoadOptions o;
    o.progress = false;
    const BrickedVolume sparse = loadVDBBricked(p, o);
    VolumeGrid dense = loadVolume(p, o);
    const BrickedVolume fromDense = brickVolume(dense);
    ASSERT_EQ(sparse.dims[2], fromDense.dims[2]);
    // bricks touching a leaf node (some all zero) but far fewer than the dense brick grid
    EXPECT_LE(double(sparse.storedBricks()), 1.25 * double(fromDense.storedBricks()));
    EXPECT_LT(sparse.storedBricks(), sparse.brickCount() / 2);
    const TransferFunction tf = transferFunctionPreset("viridis");
    const TFTable table = buildTable(tf, {0.0f, 1.0f}, 0.5f);
    std::vector<float> img[2];
    int idx = 0;
    for (const BrickedVolume* v : {&sparse, &fromDense}) {
        withVolumeScene(*v, table, {}, [&](const auto& scene) {
            const PinholeCamera cam(fitCamera(scene.bounds(), 40.0f, 1.0f, {0.45f, -1.0f, 0.35f}, {0, 0, 1}), 64, 64);
            RGBAFramebuffer fb(64, 64);
            RenderOptions ro;
            ro.progress = false;
            test::renderVolumeImage(16, scene, cam, fb, ro);
            img[idx++] = fb.resolved(1);
        });
    }
    EXPECT_LE(maxAbsDiff(img[0], img[1]), 1e-6f);
}

namespace {

// Transmittance of kW parallel rays down the z axis of a volume 64 voxels deep, and the
// samples they took.
std::pair<std::vector<float>, uint64_t> marchTransmittance(const BrickedVolume& g, const TFTable& table, float step,
                                                           int maxStepMultiple) {
    VolumeRenderSettings rs;
    rs.stepVoxels = step;
    rs.maxStepMultiple = maxStepMultiple;
    const VolumeScene<uint8_t> s(g, table, rs);
    RayPacket<kW> rays;
    for (int i = 0; i < kW; ++i) rays.setLane(i, {1.0f + 6.0f * float(i) / kW, 4.0f, -5.0f}, {0, 0, 1});
    rays.finalize();
    PixelSample<kW> ps;
    const uint64_t before = tlsCounters.volumeSamples;
    const Radiance<kW> r = VolumeIntegrator{}.eval<kW>(s, rays, Mask<kW>(true), ps);
    std::vector<float> T(kW);
    for (int i = 0; i < kW; ++i) T[size_t(i)] = 1.0f - r.alpha[i];
    return {T, tlsCounters.volumeSamples - before};
}

// A homogeneous slab (opacity `a` per voxel everywhere).
std::pair<std::vector<float>, uint64_t> slabTransmittance(float a, float step, int maxStepMultiple) {
    static const BrickedVolume g = brickVolume(makeSlab(9, 9, 65, 0, 64, 255));
    return marchTransmittance(g, flatTable(0, 255, a, step), step, maxStepMultiple);
}

double psnrOf(const std::vector<float>& a, const std::vector<float>& b) {
    double se = 0;
    size_t n = 0;
    for (size_t i = 0; i < a.size(); ++i)
        if (i % 4 != 3) {
            se += double(a[i] - b[i]) * double(a[i] - b[i]);
            ++n;
        }
    return se == 0 ? 1e9 : 10.0 * std::log10(double(n) / se);
}

}  // namespace

// Opacity-adaptive steps on a homogeneous slab, against exp(-sigma d) and the plain march.
// The TF's opacity is the same for every value, so one long step is exact and the march
// takes the longest (4 base steps) at any opacity, shortened to 2 or 1 where fewer samples
// are left in the brick. When 4 steps divide the depth the product of the step opacities
// is the closed form exactly (float tolerance 1e-3 relative); otherwise the last step may
// reach past the slab: |log T - log T_exact| <= 4 sigma step. Samples: the plain march's
// divided by 4, plus at most 2 per brick crossed (the shortened steps; 9 bricks).
TEST(VolumeAdaptiveSteps, HomogeneousSlabMatchesClosedFormAndPlainMarch) {
    for (float a : {0.002f, 0.02f}) {
        const float sigma = -std::log(1.0f - a), d = 64.0f, m = 4.0f;
        const float exact = std::exp(-sigma * d);
        for (float step : {0.25f, 0.5f, 1.0f, 2.0f, 0.3f, 0.7f, 4.0f}) {
            const auto [Ta, na] = slabTransmittance(a, step, 4);
            const auto [Tp, np] = slabTransmittance(a, step, 1);
            const bool divides = std::fabs(d / (m * step) - std::round(d / (m * step))) < 1e-4f;
            const float tol = m * sigma * step * 1.001f;
            for (int i = 0; i < kW; ++i) {
                if (divides)
                    EXPECT_NEAR(Ta[size_t(i)], exact, 1e-3f * exact) << "a " << a << " step " << step;
                else
                    EXPECT_LE(std::fabs(std::log(Ta[size_t(i)]) - std::log(exact)), tol)
                        << "a " << a << " step " << step;
                EXPECT_LE(std::fabs(std::log(Ta[size_t(i)]) - std::log(Tp[size_t(i)])), tol)
                    << "a " << a << " step " << step;
            }
            EXPECT_LE(na, (np + uint64_t(m - 1) * uint64_t(kW)) / uint64_t(m) + 2 * 9 * uint64_t(kW))
                << "a " << a << " step " << step;
            if (step == 1.0f) {
                EXPECT_EQ(na * uint64_t(m), np);  // 8 samples a brick: two long steps each
            }
            EXPECT_GE(na * uint64_t(m), np) << "a " << a << " step " << step;
        }
    }
}

// Where the TF's opacity varies across every brick's values by more than a long step can
// follow (a z ramp of values 0..252 under an opacity ramp 0..0.2 per voxel: 0.025 across
// a brick, 4.9% error for a double step against the 1% allowed), the adaptive march is
// the plain march, sample for sample.
TEST(VolumeAdaptiveSteps, VaryingOpacityMarchesPlainly) {
    VolumeGrid grid = makeSlab(9, 9, 65, 0, 64, 0);
    for (int k = 0; k < 65; ++k)
        for (int j = 0; j < 9; ++j)
            for (int i = 0; i < 9; ++i) grid.bytes[grid.index(i, j, k)] = uint8_t(std::min(4 * k, 252));
    const BrickedVolume g = brickVolume(grid);
    TransferFunction tf;
    tf.colors = {{0.0f, {1, 1, 1}}, {1.0f, {1, 1, 1}}};
    tf.opacity = {{0.0f, 0.0f}, {1.0f, 0.2f}};
    for (float step : {0.5f, 1.0f}) {
        const TFTable table = buildTable(tf, {0, 255}, step);
        const auto [Ta, na] = marchTransmittance(g, table, step, 4);
        const auto [Tp, np] = marchTransmittance(g, table, step, 1);
        EXPECT_EQ(na, np) << "step " << step;
        EXPECT_EQ(Ta, Tp) << "step " << step;
        EXPECT_LT(Tp[0], 0.9f) << "step " << step;  // the ramp is visible
    }
}

namespace {

// A 9 x 9 x 65 slab whose voxel layer k holds value(k), and the TF of the sub-brick tests:
// faint (0.02) up to 40% of the range, hidden at 60%, ramping to 0.2 at the top.
template <class F>
BrickedVolume layeredSlab(F value) {
    VolumeGrid grid = makeSlab(9, 9, 65, 0, 64, 0);
    for (int k = 0; k < 65; ++k)
        for (int j = 0; j < 9; ++j)
            for (int i = 0; i < 9; ++i) grid.bytes[grid.index(i, j, k)] = uint8_t(value(k));
    return brickVolume(grid);
}
TransferFunction faintAndSteepTF() {
    TransferFunction tf;
    tf.colors = {{0.0f, {1, 1, 1}}, {1.0f, {1, 1, 1}}};
    tf.opacity = {{0.0f, 0.02f}, {0.4f, 0.02f}, {0.6f, 0.0f}, {1.0f, 0.2f}};
    return tf;
}

}  // namespace

// A brick whose value range is too wide for long steps may hold sub-bricks whose own range
// allows them: along z, every brick is homogeneous (value 50, opacity 0.02) in its voxel
// layers 0-4, the lower sub-brick, and steep (values 150 / 200 / 250 under an opacity ramp
// 0 -> 0.2) in layers 5-7. The lower sub-brick's samples take long steps that end at its
// exit (at step 1: one sample for four there, 5 a brick instead of 8), the steep ones
// march plainly, and the transmittance stays that of the plain march: the homogeneous long
// steps are exact up to the half-float opacity tables (|log T| within 2e-3).
TEST(VolumeAdaptiveSteps, SubBricksOfMixedBricksTakeLongSteps) {
    const BrickedVolume g = layeredSlab([](int k) { return k % 8 <= 4 ? 50 : 150 + 50 * (k % 8 - 5); });
    const TransferFunction tf = faintAndSteepTF();
    for (float step : {1.0f, 0.5f}) {
        const TFTable table = buildTable(tf, {0, 255}, step);
        const auto [Ta, na] = marchTransmittance(g, table, step, 4);
        const auto [Tp, np] = marchTransmittance(g, table, step, 1);
        EXPECT_LT(Tp[0], 0.5f) << "step " << step;  // both parts are visible
        for (int i = 0; i < kW; ++i)
            EXPECT_LE(std::fabs(std::log(Ta[size_t(i)]) - std::log(Tp[size_t(i)])), 2e-3f) << "step " << step;
        EXPECT_LE(double(na), 0.7 * double(np)) << "step " << step;
        if (step == 1.0f) {
            EXPECT_EQ(na * 8, np * 5);
        }
        VolumeRenderSettings rs;
        rs.stepVoxels = step;
        EXPECT_TRUE((VolumeScene<uint8_t>(g, table, rs).longSteps)) << "step " << step;  // half of them
    }
}

// Where few of the shown sub-bricks allow long steps (below VolumeScene::kMinLongStepShare:
// here the lower sub-bricks of the first of 8 bricks, 4 of 64), the march takes none: it is
// the plain march, sample for sample.
TEST(VolumeAdaptiveSteps, FewLongStepSubBricksMarchPlainly) {
    const BrickedVolume g = layeredSlab([](int k) { return k <= 4 ? 50 : 150 + 50 * (k % 3); });
    const TransferFunction tf = faintAndSteepTF();
    for (float step : {1.0f, 0.5f}) {
        const TFTable table = buildTable(tf, {0, 255}, step);
        VolumeRenderSettings rs;
        rs.stepVoxels = step;
        const VolumeScene<uint8_t> s(g, table, rs);
        EXPECT_FALSE(s.longSteps) << "step " << step;
        for (int32_t info : s.subInfo) {
            if (info >= 0) {
                EXPECT_EQ(info >> 28, 0) << "step " << step;
            }
        }
        const auto [Ta, na] = marchTransmittance(g, table, step, 4);
        const auto [Tp, np] = marchTransmittance(g, table, step, 1);
        EXPECT_LT(Tp[0], 0.5f) << "step " << step;
        EXPECT_EQ(na, np) << "step " << step;
        EXPECT_EQ(Ta, Tp) << "step " << step;
    }
}

// On the phantom with a faint TF (at most 0.002 per voxel: every visible brick takes 4
// steps at once) the adaptive march takes under 40% of the plain march's samples and stays
// within 40 dB (linear RGB, peak 1) of it at the same step, in DVR and shaded DVR, with the
// mean opacity within 2% (the 1-step opacity on 4-step samples would quarter it); MIP and
// isosurfaces do not use it (same image, same samples).
TEST(VolumeAdaptiveSteps, CloseToPlainMarchWithFewerSamples) {
    const VolumeGrid ph = makeSheppLogan(64, Storage::U16);
    const TransferFunction tf = parseTransferFunctionJson(
        R"({"colors":[[0,0.2,0.3,0.9],[1,1,0.9,0.8]],"opacity":[[0,0],[0.05,0],[1,0.002]]})", "t");
    for (VolumeMode m : {VolumeMode::DVR, VolumeMode::Shaded, VolumeMode::MIP, VolumeMode::Iso}) {
        VolumeRenderSettings adaptive, plain;
        adaptive.mode = plain.mode = m;
        adaptive.stepVoxels = plain.stepVoxels = 1.0f;
        plain.maxStepMultiple = 1;
        const Rendered a = render(16, ph, tf, adaptive), p = render(16, ph, tf, plain);
        if (m == VolumeMode::DVR || m == VolumeMode::Shaded) {
            EXPECT_GE(psnrOf(a.rgba, p.rgba), 40.0) << int(m);
            double sa = 0, sp = 0;
            for (size_t i = 3; i < a.rgba.size(); i += 4) {
                sa += a.rgba[i];
                sp += p.rgba[i];
            }
            EXPECT_GT(sp, 20.0) << int(m);
            EXPECT_NEAR(sa, sp, 0.02 * sp) << int(m);
            EXPECT_LT(double(a.samples), 0.4 * double(p.samples)) << int(m);
        } else {
            EXPECT_EQ(a.rgba, p.rgba) << int(m);
            EXPECT_EQ(a.samples, p.samples) << int(m);
        }
    }
}

// The skipped sub-bricks' distance map is the Chebyshev distance (in sub-bricks, capped)
// to the nearest one that is not skipped, so a jump never passes over a visible one; on a
// sparse volume (two blobs in 12^3 bricks, 24^3 sub-bricks) the long jumps change no pixel.
TEST(VolumeSkipping, DistanceMapIsChebyshevAndJumpsChangeNoPixel) {
    VolumeGrid g;
    g.dims[0] = g.dims[1] = g.dims[2] = 97;
    g.allocate(Storage::U8);
    for (int k = 0; k < 97; ++k)
        for (int j = 0; j < 97; ++j)
            for (int i = 0; i < 97; ++i) {
                const bool blobA = i >= 4 && i < 12 && j >= 4 && j < 12 && k >= 4 && k < 12;
                const bool blobB = std::abs(i - 60) < 6 && std::abs(j - 50) < 6 && std::abs(k - 70) < 6;
                g.data<uint8_t>()[g.index(i, j, k)] = uint8_t(blobA || blobB ? 200 : 0);
            }
    const TransferFunction tf = parseTransferFunctionJson(
        R"({"colors":[[0,1,1,1],[1,1,1,1]],"opacity":[[0,0],[0.5,0],[0.6,0.3],[1,0.3]]})", "t");
    const BrickedVolume bv = brickVolume(g);
    const VolumeScene<uint8_t> s(bv, buildTable(tf, {0.0f, 255.0f}, 0.5f), {});
    // the skipping grid: sub-bricks of 4^3 cells
    const int n = s.subs[0];
    ASSERT_EQ(n, 24);
    std::vector<std::array<int, 3>> flagged;
    for (int i = 0; i < n * n * n; ++i)
        if (s.subFlags[size_t(i)]) flagged.push_back({i % n, i / n % n, i / (n * n)});
    ASSERT_FALSE(flagged.empty());
    int far = 0;
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const size_t i = size_t(x + n * (y + n * z));
                int best = VolumeScene<uint8_t>::kMaxDistance;
                for (const auto& o : flagged)
                    best = std::min(best, std::max({std::abs(o[0] - x), std::abs(o[1] - y), std::abs(o[2] - z)}));
                if (s.subFlags[i]) {
                    EXPECT_GE(s.subInfo[i], 0);
                } else {
                    ASSERT_LT(s.subInfo[i], 0);
                    EXPECT_EQ(s.subInfo[i] & 0x7fffffff, best) << x << "," << y << "," << z;
                    far += best > 2;
                }
            }
    EXPECT_GT(far, 100);  // the map allows long jumps here
    for (VolumeMode m : {VolumeMode::DVR, VolumeMode::Shaded}) {
        VolumeRenderSettings on, off;
        on.mode = off.mode = m;
        off.skipping = false;
        const Rendered a = render(16, g, tf, on), b = render(16, g, tf, off);
        EXPECT_LE(maxAbsDiff(a.rgba, b.rgba), 1e-6f) << int(m);
        EXPECT_GT(a.skipped, 10 * a.samples) << int(m);
    }
}

namespace {

// Opacity of kW parallel rays down z (x from 1 to 7, y = 4) under settings rs.
std::vector<float> zAlpha(const BrickedVolume& g, const TFTable& table, const VolumeRenderSettings& rs) {
    const VolumeScene<uint8_t> s(g, table, rs);
    EXPECT_EQ(s.tfIntegral.empty(), !rs.preintegrated);
    RayPacket<kW> rays;
    for (int i = 0; i < kW; ++i) rays.setLane(i, {1.0f + 6.0f * float(i) / kW, 4.0f, -5.0f}, {0, 0, 1});
    rays.finalize();
    PixelSample<kW> ps;
    const Radiance<kW> r = VolumeIntegrator{}.eval<kW>(s, rays, Mask<kW>(true), ps);
    std::vector<float> A(kW);
    for (int i = 0; i < kW; ++i) A[size_t(i)] = r.alpha[i];
    // the single-ray march gives the same
    RayPacket<1> one = rays.lane(kW / 2);
    const Radiance<1> r1 = VolumeIntegrator{}.eval<1>(s, one, Mask<1>(true), PixelSample<1>{});
    EXPECT_NEAR(1.0f - float(r1.alpha), 1.0f - A[kW / 2], 1e-6f);
    return A;
}

// Transmittance of those rays (plain march or pre-integrated, no long steps).
std::vector<float> zTransmittance(const BrickedVolume& g, const TFTable& table, float step, bool pre) {
    VolumeRenderSettings rs;
    rs.stepVoxels = step;
    rs.maxStepMultiple = 1;
    rs.preintegrated = pre;
    std::vector<float> T = zAlpha(g, table, rs);
    for (float& t : T) t = 1.0f - t;
    return T;
}

}  // namespace

// Pre-integration on the homogeneous slab: every segment has one TF entry at both ends, so
// the march is the plain one (exp(-sigma d) within the plain march's tolerance, and the
// plain march's transmittance within 1e-4 relative).
TEST(VolumePreintegration, HomogeneousSlabMatchesPlainMarch) {
    const BrickedVolume g = brickVolume(makeSlab(9, 9, 65, 0, 64, 255));
    const float a = 0.02f, sigma = -std::log(1.0f - a), d = 64.0f;
    for (float step : {0.5f, 1.0f, 2.0f, 0.7f}) {
        const std::vector<float> Tp = zTransmittance(g, flatTable(0, 255, a, step), step, false);
        const std::vector<float> Ti = zTransmittance(g, flatTable(0, 255, a, step), step, true);
        for (int i = 0; i < kW; ++i) {
            EXPECT_NEAR(Ti[size_t(i)], Tp[size_t(i)], 2e-3f * Tp[size_t(i)]) << "step " << step;
            EXPECT_LE(std::fabs(std::log(Ti[size_t(i)]) + sigma * d), sigma * step * 1.001f) << "step " << step;
        }
    }
}

// A thin opaque shell: the value rises linearly along z (4 per voxel) through a TF band of
// opacity a per voxel 5.1 values (1.275 voxels) wide. Closed form: T = exp(-sigma w) with
// sigma = -ln(1 - a), w the band's depth (its edges' ramps are 0.255 values wide: counted
// half, within 1%). The plain march at step 2 samples values 8 apart and steps over the
// band (T = 1); pre-integrated segments hold it at every step (2% relative: the table's
// 4096 entries quantize the segment's ends).
TEST(VolumePreintegration, ThinShellMatchesClosedFormAtLongSteps) {
    const BrickedVolume g =
        brickVolume(linearGrid<uint8_t>(9, 9, 64, Storage::U8, [](float, float, float z) { return 4.0f * z; }));
    const float a = 0.5f, sigma = -std::log(1.0f - a);
    TransferFunction tf;
    tf.colors = {{0.0f, {1, 1, 1}}, {1.0f, {1, 1, 1}}};
    tf.opacity = {{0.0f, 0.0f}, {0.399f, 0.0f}, {0.4f, a}, {0.42f, a}, {0.421f, 0.0f}, {1.0f, 0.0f}};
    const float w = (0.4205f - 0.3995f) * 255.0f / 4.0f;
    const float exact = std::exp(-sigma * w);
    for (float step : {0.25f, 0.5f, 1.0f, 2.0f, 3.0f, 0.7f}) {
        const TFTable table = buildTable(tf, {0.0f, 255.0f}, step);
        const std::vector<float> Ti = zTransmittance(g, table, step, true);
        for (int i = 0; i < kW; ++i) EXPECT_NEAR(Ti[size_t(i)], exact, 0.02f * exact) << "step " << step;
        if (step == 2.0f) {
            const std::vector<float> Tp = zTransmittance(g, table, step, false);
            EXPECT_GT(Tp[0], 0.99f);  // the plain march misses the shell
        }
    }
}

// A clip plane at a step in the values: 255 (in the TF's band) up to z = 19, 100 (below the
// band) from z = 20, clipped at z = 20 and marched without skipping: inside the box every
// value is 100, so nothing may show (the plain march: alpha 0). A ray's first segment opens a
// step before its first sample, outside the box: its look-back sample is taken at the clip
// face (100), not beyond it, where the hidden side's values (177 at z = 19.5) would add a film
// of the band.
TEST(VolumePreintegration, ClipPlaneHidesWhatLiesBeyond) {
    const BrickedVolume g = brickVolume(
        linearGrid<uint8_t>(9, 9, 64, Storage::U8, [](float, float, float z) { return z < 19.5f ? 255.0f : 100.0f; }));
    TransferFunction tf;
    tf.colors = {{0.0f, {1, 1, 1}}, {1.0f, {1, 1, 1}}};
    tf.opacity = {{0.0f, 0.0f}, {0.5f, 0.0f}, {0.51f, 0.5f}, {1.0f, 0.5f}};
    for (float step : {0.5f, 1.0f, 2.0f, 4.0f}) {
        for (bool pre : {false, true}) {
            VolumeRenderSettings rs;
            rs.stepVoxels = step;
            rs.maxStepMultiple = 1;
            rs.skipping = false;
            rs.preintegrated = pre;
            rs.clipLo.z = 20.0f / 63.0f;
            const std::vector<float> A = zAlpha(g, buildTable(tf, {0.0f, 255.0f}, step), rs);
            for (int i = 0; i < kW; ++i)
                EXPECT_EQ(A[size_t(i)], 0.0f)
                    << "step " << step << (pre ? ", pre-integrated" : ", plain") << ", lane " << i;
        }
    }
}
