// The march's voxel copies (BrickedVolume::quads for u8, BrickedVolume::pairs for u16 and,
// on request, u8): their trilinear samples equal the brick pool's bit for bit and a
// brute-force trilinear over BrickedVolume::stored, at random positions of u8 and u16
// volumes whose sizes are not brick multiples; f32 has no copy; a march from either layout
// gives the same image.
#include <gtest/gtest.h>

#include <random>

#include "core/render/framebuffer.h"
#include "core/render/pinhole_camera.h"
#include "render_volume_image.h"
#include "volume/volume_generators.h"
#include "volume/volume_integrator.h"
#include "volume/volume_scene.h"

using namespace rtfact;
using namespace rtfact::volume;

namespace {

constexpr int kW = simd::kNativeWidth;

template <class T>
VolumeGrid randomGrid(Storage st, float maxValue) {
    VolumeGrid g;
    g.dims[0] = 37;
    g.dims[1] = 26;
    g.dims[2] = 19;
    g.allocate(st);
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.0f, maxValue);
    for (size_t n = 0; n < g.voxelCount(); ++n) g.data<T>()[n] = T(u(rng));
    // a zero region, so some bricks are the shared zero brick
    for (int k = 0; k < 9; ++k)
        for (int j = 0; j < 9; ++j)
            for (int i = 0; i < 17; ++i) g.data<T>()[g.index(i, j, k)] = T(0);
    return g;
}

// The trilinear sample in the integrator's arithmetic order, from BrickedVolume::stored.
float bruteForce(const BrickedVolume& v, Vec3f p) {
    const int ix = int(p.x), iy = int(p.y), iz = int(p.z);
    const float fx = p.x - float(ix), fy = p.y - float(iy), fz = p.z - float(iz);
    auto row = [&](int j, int k) {
        const float a = v.stored(ix, j, k), b = v.stored(ix + 1, j, k);
        return a + (b - a) * fx;
    };
    const float c0 = row(iy, iz), c1 = row(iy + 1, iz), c2 = row(iy, iz + 1), c3 = row(iy + 1, iz + 1);
    const float d0 = c0 + (c1 - c0) * fy, d1 = c2 + (c3 - c2) * fy;
    return d0 + (d1 - d0) * fz;
}

template <class T, VoxelLayout L>
void checkLayouts(Storage st, float maxValue) {
    static_assert(L != VoxelLayout::Rows);
    BrickedVolume bv = brickVolume(randomGrid<T>(st, maxValue));
    EXPECT_LT(bv.storedBricks(), bv.brickCount());
    // per stored brick (and the zero brick): 9 x 8 x 9 y-pairs of two samples, or
    // 9 x 8 x 8 y-z quads of four
    const size_t entries = L == VoxelLayout::YZQuads ? BrickedVolume::kQuadEntries : BrickedVolume::kPairEntries;
    const size_t perEntry = (L == VoxelLayout::YZQuads ? 4 : 2) * sizeof(T);
    if (L == VoxelLayout::YPairs && st == Storage::U8) {
        ASSERT_TRUE(buildMarchCopy(bv, false));
    }
    const std::vector<uint8_t>& copy = L == VoxelLayout::YZQuads ? bv.quads : bv.pairs;
    ASSERT_FALSE(copy.empty()) << "a small volume gets its march copy";
    EXPECT_TRUE((L == VoxelLayout::YZQuads ? bv.pairs : bv.quads).empty()) << "one copy at most";
    EXPECT_EQ(copy.size(), (bv.storedBricks() + 1) * entries * perEntry + 64);
    TransferFunction tf = transferFunctionPreset("grayscale");
    const VolumeScene<T> s(bv, buildTable(tf, {0.0f, maxValue}, 0.5f), {});
    ASSERT_NE(s.copyVoxels, nullptr);
    ASSERT_EQ(s.copyLayout, L);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int it = 0; it < 400; ++it) {
        Vec3<kW> p;
        for (int i = 0; i < kW; ++i) {
            Vec3f q(u(rng) * float(bv.dims[0] - 1), u(rng) * float(bv.dims[1] - 1), u(rng) * float(bv.dims[2] - 1));
            if (it == 0 && i == 0) q = Vec3f(float(bv.dims[0] - 1), float(bv.dims[1] - 1), float(bv.dims[2] - 1));
            if (it == 1) q[i % 3] = float((i / 3) * 8 % (bv.dims[i % 3] - 1));  // on brick faces
            p.setLane(i, q);
        }
        const Vec3<kW> c = VolumeIntegrator::clampToGrid<kW>(s, p);
        const Packet<kW> rows = VolumeIntegrator::sample<kW, VoxelLayout::Rows>(s, c);
        const Packet<kW> fromCopy = VolumeIntegrator::sample<kW, L>(s, c);
        for (int i = 0; i < kW; ++i) {
            const Vec3f q(c.x[i], c.y[i], c.z[i]);
            ASSERT_EQ(fromCopy[i], rows[i]) << q.x << "," << q.y << "," << q.z;
            const Packet<1> one = VolumeIntegrator::sample<1, L>(s, VolumeIntegrator::clampToGrid<1>(s, Vec3<1>(q)));
            ASSERT_EQ(float(one), fromCopy[i]) << q.x << "," << q.y << "," << q.z;
            const float ref = bruteForce(bv, q);
            ASSERT_NEAR(fromCopy[i], ref, 1e-5f * std::max(1.0f, std::fabs(ref))) << q.x << "," << q.y << "," << q.z;
        }
    }
}

// One pixel-centre pass of a w x h view, resolved.
template <class Scene>
std::vector<float> renderView(const Scene& scene, const PinholeCamera& cam, int w, int h) {
    RGBAFramebuffer fb(w, h);
    RenderOptions ro;
    ro.progress = false;
    test::renderVolumeImage(64, scene, cam, fb, ro);
    return fb.resolved(1);
}

std::vector<float> renderDvr(const BrickedVolume& bv, VolumeMode mode) {
    const TransferFunction tf = transferFunctionPreset("ct-bone");
    const auto [lo, hi] = bv.valueRange();
    VolumeRenderSettings rs;
    rs.mode = mode;
    rs.iso = lo + 0.4f * (hi - lo);
    const TFTable table = buildTable(tf, {lo, hi}, rs.stepVoxels);
    std::vector<float> out;
    withVolumeScene(bv, table, rs, [&](const auto& scene) {
        const PinholeCamera cam(fitCamera(scene.bounds(), 40.0f, 1.0f, {0.45f, -1.0f, 0.35f}, {0, 0, 1}), 64, 64);
        out = renderView(scene, cam, 64, 64);
    });
    return out;
}

}  // namespace

TEST(VoxelLayout, YZQuadsEqualRowsU8) { checkLayouts<uint8_t, VoxelLayout::YZQuads>(Storage::U8, 255.0f); }
TEST(VoxelLayout, YPairsEqualRowsU8) { checkLayouts<uint8_t, VoxelLayout::YPairs>(Storage::U8, 255.0f); }
TEST(VoxelLayout, YPairsEqualRowsU16) { checkLayouts<uint16_t, VoxelLayout::YPairs>(Storage::U16, 65535.0f); }

TEST(VoxelLayout, F32HasNoCopy) {
    const BrickedVolume bv = brickVolume(randomGrid<float>(Storage::F32, 1.0f));
    EXPECT_TRUE(bv.pairs.empty());
    EXPECT_TRUE(bv.quads.empty());
    const VolumeScene<float> s(bv, buildTable(transferFunctionPreset("grayscale"), {0.0f, 1.0f}, 0.5f), {});
    EXPECT_EQ(s.copyVoxels, nullptr);
    EXPECT_EQ(s.copyLayout, VoxelLayout::Rows);
}

// Without the march's copy (the memory budget's fallback) the march reads the pool, and
// u8 y-pairs give what u8 quads give: same image, in every mode.
TEST(VoxelLayout, ImagesEqualWithoutCopy) {
    for (Storage st : {Storage::U16, Storage::U8}) {
        BrickedVolume with = brickVolume(makeSheppLogan(45, st));
        ASSERT_FALSE((st == Storage::U8 ? with.quads : with.pairs).empty());
        BrickedVolume without = with;
        without.pairs.clear();
        without.quads.clear();
        BrickedVolume pairs = with;
        if (st == Storage::U8) {
            ASSERT_TRUE(buildMarchCopy(pairs, false));
        }
        for (VolumeMode m : {VolumeMode::DVR, VolumeMode::Shaded, VolumeMode::MIP, VolumeMode::Iso}) {
            const std::vector<float> a = renderDvr(with, m), b = renderDvr(without, m), c = renderDvr(pairs, m);
            ASSERT_EQ(a.size(), b.size());
            ASSERT_EQ(a.size(), c.size());
            float maxDiff = 0, sum = 0;
            for (size_t i = 0; i < a.size(); ++i) {
                maxDiff = std::max({maxDiff, std::fabs(a[i] - b[i]), std::fabs(a[i] - c[i])});
                sum += a[i];
            }
            EXPECT_EQ(maxDiff, 0.0f) << int(m) << " storage " << int(st);
            EXPECT_GT(sum, 0.0f) << int(m);  // something was drawn
        }
    }
}

// The march prefetches bricks ahead of its rays where the voxels it reads (the row layout's
// pool or the march's copy) outgrow the caches (VolumeScene::prefetchBricks): forced on for
// a small volume, it changes no pixel, from outside the box and from inside it (the brick
// ahead clamped to the grid), in every layout.
template <class T>
void checkPrefetchChangesNoPixel(Storage st, VoxelLayout layout) {
    SCOPED_TRACE(int(layout));
    BrickedVolume bv = brickVolume(makeSheppLogan(45, st));
    if (layout == VoxelLayout::Rows) {
        bv.pairs.clear();
        bv.quads.clear();
    }
    const TransferFunction tf = transferFunctionPreset("ct-bone");
    const auto [lo, hi] = bv.valueRange();
    VolumeRenderSettings rs;
    const TFTable table = buildTable(tf, {lo, hi}, rs.stepVoxels);
    VolumeScene<T> scene(bv, table, rs);
    ASSERT_EQ(scene.copyLayout, layout);
    EXPECT_FALSE(scene.prefetchBricks) << "a 45^3 volume fits the caches";
    const AABB box = scene.bounds();
    const CameraFrame views[2] = {fitCamera(box, 40.0f, 1.0f, {0.45f, -1.0f, 0.35f}, {0, 0, 1}),
                                  {box.center(), box.center() + Vec3f(0.7f, 0.2f, -0.4f), {0, 0, 1}, 100.0f}};
    for (const CameraFrame& view : views) {
        const PinholeCamera cam(view, 48, 48);
        std::vector<float> img[2];
        for (int on = 0; on < 2; ++on) {
            scene.prefetchBricks = on == 1;
            img[on] = renderView(scene, cam, 48, 48);
        }
        float sum = 0;
        for (size_t i = 0; i < img[0].size(); ++i) {
            ASSERT_EQ(img[0][i], img[1][i]) << "pixel value " << i;
            sum += img[0][i];
        }
        EXPECT_GT(sum, 0.0f);  // something was drawn
    }
}

TEST(VoxelLayout, BrickPrefetchChangesNoPixel) {
    checkPrefetchChangesNoPixel<uint16_t>(Storage::U16, VoxelLayout::Rows);
    checkPrefetchChangesNoPixel<uint16_t>(Storage::U16, VoxelLayout::YPairs);
    checkPrefetchChangesNoPixel<uint8_t>(Storage::U8, VoxelLayout::YZQuads);
}
