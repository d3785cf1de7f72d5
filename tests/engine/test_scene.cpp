// engine::open on the tracked datasets, info(), fileInfo() and the array constructors.
#include <gtest/gtest.h>

#include <cmath>

#include "common/image_compare.h"
#include "engine/render_session.h"
#include "engine/scene.h"
#include "engine/usage_error.h"

using namespace rtfact;
using namespace rtfact::engine;

namespace {

const std::string kPoints = std::string(RTFACT_DATASETS) + "/points/bunny_bun000.ply";
const std::string kMesh = std::string(RTFACT_DATASETS) + "/meshes/bunny.ply";
const std::string kVolume = std::string(RTFACT_DATASETS) + "/volumes/tooth_103x94x161_uint8.mhd";

OpenOptions quiet() {
    OpenOptions o;
    o.progress = false;
    return o;
}

// Fraction of pixels with coverage (alpha > 0) in a frame.
double coverage(const Frame& f) {
    size_t n = 0;
    for (size_t i = 3; i < f.rgba.size(); i += 4) n += f.rgba[i] > 0.0f;
    return double(n) / double(size_t(f.width) * size_t(f.height));
}

Frame renderDefault(const Scene& s, const Settings& settings = {}, int w = 48, int h = 40) {
    FrameOptions fo;
    fo.width = w;
    fo.height = h;
    const CameraFrame cam = fitCamera(s.defaultView(settings), 45.0f, float(w) / float(h));
    Stats stats;
    return renderToImage(s, settings, fo, cam, 1, stats);
}

}  // namespace

TEST(EngineOpen, PointCloudFromFile) {
    const Scene s = open({kPoints}, quiet());
    EXPECT_EQ(s.kind(), SceneKind::Points);
    EXPECT_EQ(s.info().get("kind"), "points");
    const long n = std::stol(s.info().get("points"));
    EXPECT_GT(n, 10000);
    EXPECT_EQ(s.loadStats().get("points"), std::to_string(n));
    EXPECT_FALSE(s.bounds().isEmpty());
    EXPECT_FALSE(s.loadStats().get("load_ms").empty());
    EXPECT_GT(coverage(renderDefault(s)), 0.05);
}

TEST(EngineOpen, MeshFromFile) {
    const Scene s = open({kMesh}, quiet());
    EXPECT_EQ(s.kind(), SceneKind::Mesh);
    EXPECT_EQ(s.info().get("kind"), "mesh");
    EXPECT_GT(std::stol(s.info().get("triangles")), 10000);
    EXPECT_FALSE(s.bounds().isEmpty());
    EXPECT_GT(coverage(renderDefault(s)), 0.05);
}

TEST(EngineOpen, VolumeFromFile) {
    const Scene s = open({kVolume}, quiet());
    EXPECT_EQ(s.kind(), SceneKind::Volume);
    EXPECT_EQ(s.info().get("dims"), "103 x 94 x 161");
    EXPECT_EQ(s.info().get("voxels"), std::to_string(103 * 94 * 161));
    EXPECT_NE(s.info().get("range").find(" .. "), std::string::npos);
    EXPECT_FALSE(s.info().get("tf_default").empty());
    // The default view of a volume looks along -y with z up.
    EXPECT_EQ(s.defaultView().up.z, 1.0f);
    EXPECT_GT(coverage(renderDefault(s)), 0.05);
}

TEST(EngineOpen, VolumeViewFitsTheClippedBox) {
    const Scene s = open({kVolume}, quiet());
    Settings st;
    st.volume.clipHi = Vec3f(1, 1, 0.5f);
    const AABB full = s.defaultView().focus, clipped = s.defaultView(st).focus;
    EXPECT_FLOAT_EQ(clipped.hi.z - clipped.lo.z, 0.5f * (full.hi.z - full.lo.z));
}

TEST(EngineOpen, ForcedKindAndUnknownFiles) {
    OpenOptions o = quiet();
    o.kind = SceneKind::Mesh;
    EXPECT_EQ(open({kMesh}, o).kind(), SceneKind::Mesh);
    EXPECT_THROW(open({}, quiet()), UsageError);
    EXPECT_THROW(open({std::string(RTFACT_DATASETS) + "/meshes/README.md"}, quiet()), Error);
    EXPECT_THROW(open({std::string(RTFACT_DATASETS) + "/does-not-exist.ply"}, quiet()), Error);
}

TEST(EngineOpen, SpheresDemo) {
    const Scene s = spheres(10);
    EXPECT_EQ(s.kind(), SceneKind::Spheres);
    EXPECT_EQ(s.info().get("spheres"), "11");
    EXPECT_EQ(s.loadStats().get("primitives"), "11");
    EXPECT_GT(coverage(renderDefault(s)), 0.05);
}

TEST(EngineFileInfo, EveryKind) {
    auto get = [](const std::vector<std::pair<std::string, std::string>>& l, const std::string& k) {
        for (const auto& [key, v] : l)
            if (key == k) return v;
        return std::string("<absent>");
    };
    EXPECT_EQ(get(fileInfo(kVolume), "kind"), "volume");
    EXPECT_EQ(get(fileInfo(kVolume), "dims"), "103 x 94 x 161");
    EXPECT_EQ(get(fileInfo(kMesh), "type"), "mesh (PLY)");
    EXPECT_EQ(get(fileInfo(kPoints), "type"), "point cloud");
    EXPECT_THROW(fileInfo(std::string(RTFACT_DATASETS) + "/meshes/README.md"), Error);
}

TEST(EngineArrays, PointsFromArrays) {
    // A 40x40 grid in the z = 0 plane facing +z, red.
    std::vector<Vec3f> p, c;
    for (int j = 0; j < 40; ++j)
        for (int i = 0; i < 40; ++i) {
            p.emplace_back(float(i) / 39.0f, float(j) / 39.0f, 0.0f);
            c.emplace_back(1.0f, 0.0f, 0.0f);
        }
    std::vector<Vec3f> n(p.size(), Vec3f(0, 0, 1));
    const Scene s = pointsFromArrays(p, c, n, std::vector<float>(p.size(), 0.03f));
    EXPECT_EQ(s.kind(), SceneKind::Points);
    EXPECT_EQ(s.info().get("points"), "1600");
    EXPECT_EQ(s.info().get("normals"), "yes");
    Settings st;
    st.points.normals = "file";
    FrameOptions fo;
    fo.width = fo.height = 32;
    const CameraFrame cam{{0.5f, 0.5f, 3.0f}, {0.5f, 0.5f, 0.0f}, {0, 1, 0}, 20.0f};
    Stats stats;
    const Frame f = renderToImage(s, st, fo, cam, 1, stats);
    const float* mid = &f.rgba[(16 * 32 + 16) * 4];
    EXPECT_GT(mid[3], 0.99f);
    EXPECT_GT(mid[0], 0.2f);
    EXPECT_EQ(mid[1], 0.0f);  // red points
    EXPECT_EQ(stats.get("normals"), "file");
    EXPECT_EQ(stats.get("radii"), "file");
    EXPECT_THROW(pointsFromArrays(p, std::vector<Vec3f>(3)), UsageError);
    EXPECT_THROW(pointsFromArrays({}), UsageError);
}

TEST(EngineArrays, MeshFromArrays) {
    // A unit square of two triangles at z = 0.
    const Scene s = meshFromArrays({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {0, 1, 2, 0, 2, 3});
    EXPECT_EQ(s.kind(), SceneKind::Mesh);
    EXPECT_EQ(s.info().get("triangles"), "2");
    EXPECT_EQ(s.bounds().hi.x, 1.0f);
    FrameOptions fo;
    fo.width = fo.height = 16;
    const CameraFrame cam{{0.5f, 0.5f, 2.0f}, {0.5f, 0.5f, 0.0f}, {0, 1, 0}, 20.0f};
    Stats stats;
    const Frame f = renderToImage(s, {}, fo, cam, 1, stats);
    EXPECT_EQ(coverage(f), 1.0);  // the square fills the view
    EXPECT_EQ(stats.get("triangles"), "2");
    EXPECT_THROW(meshFromArrays({{0, 0, 0}}, {0, 1}), UsageError);
    EXPECT_THROW(meshFromArrays({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 7}), Error);
}

TEST(EngineArrays, VolumeFromArray) {
    // A 16^3 ball of value 1 in a zero background.
    const int n = 16;
    std::vector<float> v(size_t(n) * n * n);
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const float dx = float(i) - 7.5f, dy = float(j) - 7.5f, dz = float(k) - 7.5f;
                v[(size_t(k) * n + size_t(j)) * n + size_t(i)] = dx * dx + dy * dy + dz * dz < 36.0f ? 1.0f : 0.0f;
            }
    const Scene s = volumeFromArray(v, {n, n, n}, {0.5f, 0.5f, 0.5f});
    EXPECT_EQ(s.kind(), SceneKind::Volume);
    EXPECT_EQ(s.info().get("range"), "0 .. 1");
    EXPECT_EQ(s.bounds().hi.x, 7.5f);
    Settings st;
    st.volume.mode = "mip";
    const Frame f = renderDefault(s, st, 32, 32);
    EXPECT_GT(f.rgba[(16 * 32 + 16) * 4 + 3], 0.5f);  // the ball in the centre
    EXPECT_LT(f.rgba[3], 0.01f);                      // background in the corner
    EXPECT_THROW(volumeFromArray(v, {n, n, n + 1}), UsageError);
}

TEST(EngineSettings, UnknownNamesAreUsageErrors) {
    const Scene s = spheres(3);
    Settings st;
    st.spheres.integrator = "path";
    EXPECT_THROW(renderDefault(s, st), UsageError);
    const Scene m = meshFromArrays({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}}, {0, 1, 2});
    st = {};
    st.mesh.lights.push_back({LightSpec::Kind::Directional, Vec3f(0.0f)});
    EXPECT_THROW(renderDefault(m, st), UsageError);
    EXPECT_THROW(glassMaterial(9.0f), UsageError);
}

// The point structures (settings.points.accel): the same discs at full detail, so the
// same image up to the last bits of the SIMD arithmetic; with the LoD cut each answers
// with its own representatives, both close to full detail (>= 30 dB, the documented
// bound at quality 4; the default quality is 2). Unknown names are usage errors.
TEST(EngineSettings, PointStructuresAgree) {
    const Scene s = open({kPoints}, quiet());
    const int w = 96, h = 80;
    auto render = [&](const std::string& accel, bool lod) {
        Settings st;
        st.points.accel = accel;
        st.points.lod = lod;
        return renderDefault(s, st, w, h);
    };
    const Frame kd = render("kd", false);
    EXPECT_GT(coverage(kd), 0.05);
    const auto& kdFull = kd.rgba;
    const auto wideFull = render("wide", false).rgba;
    const test::ImageDiff full = test::compareRGBA(kdFull, wideFull, w, h, 1);
    EXPECT_LE(full.differentFraction, 0.001);
    EXPECT_GE(full.psnr, 50.0);
    EXPECT_GE(test::compareRGBA(render("kd", true).rgba, kdFull, w, h, 8).psnr, 30.0);
    const auto wideLod = render("wide", true).rgba;
    EXPECT_NE(wideLod, wideFull);  // the cut answered some rays
    EXPECT_GE(test::compareRGBA(wideLod, kdFull, w, h, 8).psnr, 30.0);
    Settings bad;
    bad.points.accel = "octree";
    EXPECT_THROW(renderDefault(s, bad), UsageError);
}
