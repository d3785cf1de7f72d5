// Gradient bricks (volume/gradient_bricks.h), u8, u16 and f32: their entries decode to the
// clamped central differences of the voxels (brute force over BrickedVolume::stored), the
// gradient read from them equals the six-sample gradient at random positions (widths 1 and
// native, brick faces and the grid's border included), their per-lane fetch equals scalar
// reads, and shaded images with and without them match.
#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <type_traits>

#include "core/render/framebuffer.h"
#include "core/render/pinhole_camera.h"
#include "render_volume_image.h"
#include "volume/gradient_bricks.h"
#include "volume/volume_generators.h"
#include "volume/volume_integrator.h"
#include "volume/volume_scene.h"
#include "volume/voxel_gather.h"

using namespace rtfact;
using namespace rtfact::volume;

namespace {

constexpr int kW = simd::kNativeWidth;

template <class T>
constexpr Storage storageOf() {
    return std::is_same_v<T, float> ? Storage::F32 : sizeof(T) == 1 ? Storage::U8 : Storage::U16;
}
// the largest random integer of the volumes (f32: times 0.37)
template <class T>
constexpr float maxOf() {
    return std::is_same_v<T, float> ? 2700.0f : float(std::numeric_limits<T>::max());
}

// Random voxels over the whole range, sizes no brick multiple, and a zero corner (bricks
// sharing brick 0).
template <class T>
BrickedVolume randomVolume() {
    VolumeGrid g;
    g.dims[0] = 37;
    g.dims[1] = 26;
    g.dims[2] = 19;
    g.allocate(storageOf<T>());
    std::mt19937 rng(3);
    std::uniform_int_distribution<int> u(0, int(maxOf<T>()));
    for (size_t n = 0; n < g.voxelCount(); ++n) g.data<T>()[n] = T(u(rng)) * T(std::is_same_v<T, float> ? 0.37f : 1);
    for (int k = 0; k < 9; ++k)
        for (int j = 0; j < 9; ++j)
            for (int i = 0; i < 17; ++i) g.data<T>()[g.index(i, j, k)] = 0;
    return brickVolume(g);
}

template <class T>
VolumeScene<T> shadedScene(const BrickedVolume& bv, bool skipping = true) {
    VolumeRenderSettings rs;
    rs.mode = VolumeMode::Shaded;
    rs.skipping = skipping;
    const auto [lo, hi] = bv.valueRange();
    return VolumeScene<T>(bv, buildTable(transferFunctionPreset("ct-bone"), {lo, hi}, rs.stepVoxels), rs);
}

template <int W, class T>
Vec3<W> bothGradients(const VolumeScene<T>& s, const Vec3<W>& q, Vec3<W>& six) {
    using I = Packet<W, int32_t>;
    const Vec3<W> p = VolumeIntegrator::clampToGrid<W>(s, q);
    const I cell[3] = {toInt(p.x), toInt(p.y), toInt(p.z)};
    const I brick[3] = {cell[0] >> 3, cell[1] >> 3, cell[2] >> 3};
    six = VolumeIntegrator::gradient<W>(s, p);
    return VolumeIntegrator::gradientFromBricks<W>(s, p, cell, brick);
}

template <class T>
std::vector<float> render(const VolumeScene<T>& scene, int n) {
    const PinholeCamera cam(fitCamera(scene.bounds(), 40.0f, 1.0f, {0.45f, -1.0f, 0.35f}, {0, 0, 1}), n, n);
    RGBAFramebuffer fb(n, n);
    RenderOptions ro;
    ro.progress = false;
    test::renderVolumeImage(64, scene, cam, fb, ro);
    return fb.resolved(1);
}

}  // namespace

template <int B>
void checkRoundTrip(int m) {
    for (int x : {-m, -m + 1, -1, 0, 1, m - 1, m})
        for (int y : {-m, -7, 0, 200, m})
            for (int z : {-m, 0, 3, m - 2, m}) {
                int32_t w[B], g[3];
                GradientBricks::pack<B>(x, y, z, w);
                GradientBricks::decode<B>(w, g);
                EXPECT_EQ(g[0], x);
                EXPECT_EQ(g[1], y);
                EXPECT_EQ(g[2], z);
            }
}
TEST(GradientBricks, PackedFieldsRoundTrip) {
    checkRoundTrip<1>(255);
    checkRoundTrip<2>(65535);
}

template <class T>
void checkEntries() {
    constexpr int B = std::is_same_v<T, float> ? 3 : int(sizeof(T));
    const BrickedVolume bv = randomVolume<T>();
    const size_t nb = bv.brickCount();
    std::vector<uint8_t> shown(nb, 0);
    for (size_t b = 0; b < nb; b += 2) shown[b] = 1;  // every other brick
    const GradientBricks g = GradientBricks::build(bv, shown, uint64_t(1) << 30);
    ASSERT_EQ(g.words, B);
    ASSERT_EQ(g.start.size(), nb);
    for (int e = 0; e < BrickedVolume::kBrick * B; ++e)
        ASSERT_EQ(B == 3 ? g.values[size_t(e)] : float(g.entries[size_t(e)]), 0.0f) << "brick 0 is zeros";
    constexpr int C = BrickedVolume::kCells, E = BrickedVolume::kEdge;
    auto at = [&](int x, int y, int z) {
        return bv.stored(std::clamp(x, 0, bv.dims[0] - 1), std::clamp(y, 0, bv.dims[1] - 1),
                         std::clamp(z, 0, bv.dims[2] - 1));
    };
    size_t checked = 0;
    for (int bz = 0; bz < bv.nb[2]; ++bz)
        for (int by = 0; by < bv.nb[1]; ++by)
            for (int bx = 0; bx < bv.nb[0]; ++bx) {
                const size_t b = bv.brickIndex(bx, by, bz);
                if (!shown[b]) {
                    EXPECT_EQ(g.start[b], 0);
                    continue;
                }
                ASSERT_GT(g.start[b], 0);
                for (int k = 0; k < E; ++k)
                    for (int j = 0; j < E; ++j)
                        for (int i = 0; i < E; ++i) {
                            const int x = bx * C + i, y = by * C + j, z = bz * C + k;
                            if (x >= bv.dims[0] || y >= bv.dims[1] || z >= bv.dims[2]) continue;  // never read
                            const int first = g.start[b] + (i + j * E + k * E * E) * B;
                            float d[3];
                            if constexpr (B == 3) {
                                for (int a = 0; a < 3; ++a) d[a] = g.values[size_t(first + a)];
                            } else {
                                int32_t w[B], di[3];
                                for (int q = 0; q < B; ++q) w[q] = g.entries[size_t(first + q)];
                                GradientBricks::decode<B>(w, di);
                                for (int a = 0; a < 3; ++a) d[a] = float(di[a]);
                            }
                            ASSERT_EQ(d[0], at(x + 1, y, z) - at(x - 1, y, z)) << x << "," << y << "," << z;
                            ASSERT_EQ(d[1], at(x, y + 1, z) - at(x, y - 1, z)) << x << "," << y << "," << z;
                            ASSERT_EQ(d[2], at(x, y, z + 1) - at(x, y, z - 1)) << x << "," << y << "," << z;
                            ++checked;
                        }
            }
    EXPECT_GT(checked, bv.voxelCount() / 3);
    EXPECT_TRUE(GradientBricks::build(bv, shown, 1000).empty()) << "over budget: none (six samples)";
}
TEST(GradientBricks, EntriesAreClampedCentralDifferencesU8) { checkEntries<uint8_t>(); }
TEST(GradientBricks, EntriesAreClampedCentralDifferencesU16) { checkEntries<uint16_t>(); }
TEST(GradientBricks, EntriesAreClampedCentralDifferencesF32) { checkEntries<float>(); }

template <int W, class T>
void checkEqualsSixSamples() {
    const BrickedVolume bv = randomVolume<T>();
    VolumeScene<T> s = shadedScene<T>(bv);
    ASSERT_TRUE(s.gradients) << "a shaded scene has gradient bricks";
    s.gradients = std::make_shared<const GradientBricks>(
        GradientBricks::build(bv, std::vector<uint8_t>(bv.brickCount(), 1), uint64_t(1) << 30));
    std::mt19937 rng(9);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int it = 0; it < 300; ++it) {
        Vec3<W> q;
        for (int i = 0; i < W; ++i) {
            Vec3f v(u(rng) * float(bv.dims[0] - 1), u(rng) * float(bv.dims[1] - 1), u(rng) * float(bv.dims[2] - 1));
            if (it == 0) v[i % 3] = i % 2 ? float(bv.dims[i % 3] - 1) : 0.0f;         // the border
            if (it == 1) v[i % 3] = float((i / 3 + 1) * 8 % (bv.dims[i % 3] - 1));    // brick faces
            if (it == 2) v[i % 3] = i % 2 ? float(bv.dims[i % 3] - 1) - 0.4f : 0.4f;  // within a voxel of it
            q.setLane(i, v);
        }
        Vec3<W> six;
        const Vec3<W> fast = bothGradients<W, T>(s, q, six);
        for (int i = 0; i < W; ++i)
            for (int a = 0; a < 3; ++a)
                ASSERT_NEAR(fast[a][i], six[a][i], 1e-5f * maxOf<T>())
                    << "lane " << i << " axis " << a << " at " << q.x[i] << "," << q.y[i] << "," << q.z[i];
    }
}

// fetchEntryPair (the gradient's per-lane reads of two adjacent entries) against scalar reads:
// every entry size, 32-bit integers and floats, widths 1, native and multi-chunk, odd and even
// (unaligned) word offsets and repeated lanes.
template <int B, int W, class T>
void checkEntryPairFetch() {
    std::vector<T> words(1000);
    for (size_t i = 0; i < words.size(); ++i) words[i] = T(int32_t(i * 2654435761u % 100003u) - 50000);
    std::mt19937 rng(uint32_t(17 * B + W));
    std::uniform_int_distribution<int32_t> u(0, int32_t(words.size()) - 2 * B);
    for (int it = 0; it < 50; ++it) {
        Packet<W, int32_t> idx;
        for (int i = 0; i < W; ++i) idx[i] = it == 0 ? 5 : u(rng);  // 5: every lane the same
        Packet<W, T> first[B], second[B];
        fetchEntryPair<B, W>(words.data(), idx, first, second);
        for (int i = 0; i < W; ++i)
            for (int k = 0; k < B; ++k) {
                ASSERT_EQ(first[k][i], words[size_t(idx[i] + k)]) << "B " << B << " W " << W << " lane " << i;
                ASSERT_EQ(second[k][i], words[size_t(idx[i] + B + k)]) << "B " << B << " W " << W << " lane " << i;
            }
    }
}
template <int W>
void checkEntryPairFetches() {
    checkEntryPairFetch<1, W, int32_t>();
    checkEntryPairFetch<2, W, int32_t>();
    checkEntryPairFetch<3, W, float>();
    checkEntryPairFetch<1, W, float>();
}
TEST(GradientBricks, EntryPairFetchEqualsScalarReads) {
    checkEntryPairFetches<1>();
    checkEntryPairFetches<kW>();
    checkEntryPairFetches<64>();
}

TEST(GradientBricks, EqualSixSampleGradientWidth1) {
    checkEqualsSixSamples<1, uint8_t>();
    checkEqualsSixSamples<1, uint16_t>();
    checkEqualsSixSamples<1, float>();
}
TEST(GradientBricks, EqualSixSampleGradientNative) {
    checkEqualsSixSamples<kW, uint8_t>();
    checkEqualsSixSamples<kW, uint16_t>();
    checkEqualsSixSamples<kW, float>();
}

// The shaded march reads the gradient bricks where the TF shows the volume (skipping on
// or off): the image is the six-sample one's within float rounding.
template <class T>
void checkShadedImage() {
    VolumeGrid grid = makeSheppLogan(45, std::is_same_v<T, uint8_t> ? Storage::U8 : Storage::U16);
    if constexpr (std::is_same_v<T, float>) {
        VolumeGrid f;
        for (int a = 0; a < 3; ++a) f.dims[a] = grid.dims[a];
        f.allocate(Storage::F32);
        for (size_t n = 0; n < grid.voxelCount(); ++n) f.data<float>()[n] = 0.25f * float(grid.data<uint16_t>()[n]);
        grid = std::move(f);
    }
    const BrickedVolume bv = brickVolume(grid);
    ASSERT_EQ(bv.storage, storageOf<T>());
    for (bool skipping : {true, false}) {
        VolumeScene<T> s = shadedScene<T>(bv, skipping);
        ASSERT_TRUE(s.gradients);
        const std::vector<float> fast = render(s, 64);
        s.gradients = nullptr;
        const std::vector<float> six = render(s, 64);
        ASSERT_EQ(fast.size(), six.size());
        float maxDiff = 0, sum = 0;
        for (size_t i = 0; i < fast.size(); ++i) {
            maxDiff = std::max(maxDiff, std::fabs(fast[i] - six[i]));
            sum += six[i];
        }
        EXPECT_LT(maxDiff, 1e-4f) << "skipping " << skipping;
        EXPECT_GT(sum, 0.0f);
    }
    // other modes build none
    VolumeRenderSettings dvr;
    const auto [lo, hi] = bv.valueRange();
    const TFTable table = buildTable(transferFunctionPreset("ct-bone"), {lo, hi}, dvr.stepVoxels);
    EXPECT_FALSE(VolumeScene<T>(bv, table, dvr).gradients);
}
TEST(GradientBricks, ShadedImageMatchesSixSamplesU8) { checkShadedImage<uint8_t>(); }
TEST(GradientBricks, ShadedImageMatchesSixSamplesU16) { checkShadedImage<uint16_t>(); }
TEST(GradientBricks, ShadedImageMatchesSixSamplesF32) { checkShadedImage<float>(); }

// A scene takes the gradient bricks offered when they hold every brick it shows (same
// image as its own), and builds its own when they do not.
TEST(GradientBricks, SceneReusesBricksThatCoverItsBricks) {
    const BrickedVolume bv = brickVolume(makeSheppLogan(45, Storage::U16));
    const auto [lo, hi] = bv.valueRange();
    VolumeRenderSettings rs;
    rs.mode = VolumeMode::Shaded;
    const TFTable bone = buildTable(transferFunctionPreset("ct-bone"), {lo, hi}, rs.stepVoxels);
    const TFTable all = buildTable(transferFunctionPreset("grayscale"), {lo, hi}, rs.stepVoxels);
    const VolumeScene<uint16_t> fewer(bv, bone, rs), more(bv, all, rs);
    ASSERT_TRUE(fewer.gradients && more.gradients);
    size_t nFewer = 0, nMore = 0;
    for (size_t b = 0; b < bv.brickCount(); ++b) {
        nFewer += fewer.gradients->start[b] != 0;
        nMore += more.gradients->start[b] != 0;
        ASSERT_TRUE(fewer.gradients->start[b] == 0 || more.gradients->start[b] != 0);
    }
    ASSERT_LT(nFewer, nMore) << "the grayscale TF shows more bricks than ct-bone";
    // covered: taken, same image
    const VolumeScene<uint16_t> reused(bv, bone, rs, more.gradients);
    EXPECT_EQ(reused.gradients, more.gradients);
    EXPECT_EQ(render(reused, 48), render(fewer, 48));
    // not covered: its own
    const VolumeScene<uint16_t> own(bv, all, rs, fewer.gradients);
    EXPECT_NE(own.gradients, fewer.gradients);
    EXPECT_EQ(render(own, 48), render(more, 48));
}
