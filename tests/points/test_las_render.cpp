// Colour by attribute and eye-dome lighting on the shipped simple.las through the engine
// (load, default view, colouring, EDL pass) against reference PNGs (metric of
// tests/common/image_compare.h); the colormaps, ranges and class colours; attributes of
// PLY and PCD files; view presets; `rtfact info` on LAS.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/image_compare.h"
#include "core/render/eye_dome_lighting.h"
#include "core/util/error.h"
#include "engine/render_session.h"
#include "engine/scene.h"
#include "points/point_cloud_io.h"
#include "points/point_colors.h"

using namespace rtfact;
using namespace rtfact::points;

namespace {

constexpr int kSize = 128;
const std::string kLas = std::string(RTFACT_POINTS_DATA) + "/simple.las";

std::vector<float> renderLas(const engine::Settings& s) {
    engine::OpenOptions oo;
    oo.progress = false;
    const engine::Scene scene = engine::open({kLas}, oo);
    engine::FrameOptions fo;
    fo.width = fo.height = kSize;
    fo.threads = 2;
    engine::Stats st;
    return engine::renderToImage(scene, s, fo, engine::fitCamera(scene.defaultView(s), 40.0f, 1.0f), 1, st).rgba;
}

engine::Settings colorSettings(ColorMode m, float edl = 0.0f) {
    engine::Settings s;
    s.points.color = m;
    s.points.edl = edl;
    s.points.radius = 60.0f;  // feet: the 1,065 points are ~120 ft apart; fixed radii keep the test fast
    return s;
}

std::string ref(const std::string& name) { return std::string(RTFACT_TEST_DATA) + "/" + name; }

double meanLuma(const std::vector<float>& rgba) {
    double sum = 0;
    for (size_t i = 0; i < rgba.size(); i += 4) sum += rgba[i] + rgba[i + 1] + rgba[i + 2];
    return sum / double(rgba.size() / 4);
}

std::string writeText(const std::string& name, const std::string& text) {
    std::filesystem::create_directories(RTFACT_TEST_OUT);
    const std::string path = std::string(RTFACT_TEST_OUT) + "/" + name;
    std::ofstream(path) << text;
    return path;
}

}  // namespace

TEST(LasRender, ColourModesMatchReferences) {
    const std::pair<ColorMode, const char*> modes[] = {{ColorMode::Elevation, "las_elevation.png"},
                                                       {ColorMode::Classification, "las_classification.png"},
                                                       {ColorMode::Intensity, "las_intensity.png"},
                                                       {ColorMode::Return, "las_return.png"},
                                                       {ColorMode::Rgb, "las_rgb.png"}};
    std::vector<std::vector<float>> images;
    for (auto [mode, file] : modes) {
        SCOPED_TRACE(file);
        images.push_back(renderLas(colorSettings(mode)));
        test::expectMatchesReference(ref(file), kSize, kSize, images.back());
    }
    // Different modes give different pictures.
    for (size_t a = 0; a < images.size(); ++a)
        for (size_t b = a + 1; b < images.size(); ++b)
            EXPECT_LT(test::compareRGBA(images[a], images[b], kSize, kSize, 8).psnr, 30.0) << a << " vs " << b;
}

TEST(LasRender, EyeDomeLightingMatchesReferenceAndDarkensSteps) {
    const std::vector<float> off = renderLas(colorSettings(ColorMode::Elevation, 0.0f));
    const std::vector<float> on = renderLas(colorSettings(ColorMode::Elevation, 2.0f));
    test::expectMatchesReference(ref("las_elevation_edl.png"), kSize, kSize, on);
    EXPECT_LT(meanLuma(on), meanLuma(off));
    // The background stays as it is.
    EXPECT_EQ(std::vector<float>(on.begin(), on.begin() + 4), std::vector<float>(off.begin(), off.begin() + 4));
    // Default: on for a cloud without normals in the file (simple.las has none).
    engine::Settings def = colorSettings(ColorMode::Elevation);
    def.points.edl.reset();
    EXPECT_LT(meanLuma(renderLas(def)), meanLuma(off));
}

TEST(LasRender, EyeDomeLightingPass) {
    // A near square in front of a far plane: the far pixels next to it darken, the
    // square and far pixels away from it do not, the background is untouched.
    const int w = 16, h = 16;
    std::vector<float> rgba(size_t(w * h * 4), 1.0f), depth(size_t(w * h), 10.0f);
    for (int y = 6; y < 10; ++y)
        for (int x = 6; x < 10; ++x) depth[size_t(y * w + x)] = 5.0f;
    depth[0] = INFINITY;
    applyEyeDomeLighting(rgba, depth, w, h, 1.0f, 1.0f);
    EXPECT_EQ(rgba[0], 1.0f);                          // background
    EXPECT_EQ(rgba[size_t(8 * w + 8) * 4], 1.0f);      // inside the square: neighbours no nearer
    EXPECT_LT(rgba[size_t(8 * w + 5) * 4], 0.5f);      // just outside: a nearer neighbour
    EXPECT_EQ(rgba[size_t(8 * w + 1) * 4], 1.0f);      // far from the step
    EXPECT_EQ(rgba[size_t(8 * w + 5) * 4 + 3], 1.0f);  // alpha untouched
}

TEST(LasRender, ColormapsRangesAndClassColours) {
    EXPECT_EQ(colormapNames(), (std::vector<std::string>{"viridis", "inferno", "turbo", "grayscale"}));
    const Vec3f lo = colormap("viridis", 0.0f), hi = colormap("viridis", 1.0f);
    EXPECT_GT(lo.z, lo.y);  // dark purple
    EXPECT_GT(hi.x, hi.z);  // yellow
    EXPECT_EQ(colormap("viridis", -5.0f), lo);
    EXPECT_EQ(colormap("grayscale", 1.0f), Vec3f(1.0f));
    EXPECT_THROW(colormap("jet", 0.5f), Error);
    // Ground brown, vegetation green, water blue.
    EXPECT_GT(classificationColor(2).x, classificationColor(2).z);
    EXPECT_GT(classificationColor(5).y, classificationColor(5).x);
    EXPECT_GT(classificationColor(9).z, classificationColor(9).x);
    // Outliers do not stretch the robust range.
    std::vector<float> v(1000);
    for (size_t i = 0; i < v.size(); ++i) v[i] = float(i % 100);
    v[3] = 1e9f;
    v[4] = -1e9f;
    const auto r = robustRange(v);
    EXPECT_GE(r[0], 0.0f);
    EXPECT_LE(r[1], 99.0f);
    EXPECT_EQ(parseColorOptions("attr:Deviation").attribute, "Deviation");
    EXPECT_EQ(parseColorOptions("classification").mode, ColorMode::Classification);
    EXPECT_THROW(parseColorOptions("attr:"), Error);
    EXPECT_THROW(parseColorOptions("height"), Error);
}

TEST(LasRender, AutoModeAndRangeOnTheCloud) {
    const PointCloud c = loadPointCloud(kLas);
    EXPECT_EQ(resolveColorMode(c, ColorMode::Auto), ColorMode::Rgb);  // simple.las has real colours
    PointCloud grey = c;
    grey.colors.clear();
    EXPECT_EQ(resolveColorMode(grey, ColorMode::Auto), ColorMode::Elevation);
    // --range in the file's coordinates: points below lo take the first colour.
    ColorOptions o;
    o.mode = ColorMode::Elevation;
    o.range = std::array<float, 2>{500.0f, 600.0f};
    const std::vector<Vec3f> col = pointColors(c, o);
    for (size_t i = 0; i < c.size(); ++i)
        if (double(c.positions[i].z) + c.origin[2] < 499.0) {
            ASSERT_EQ(col[i], colormap("viridis", 0.0f)) << i;
        }
    o.mode = ColorMode::Attribute;
    o.attribute = "gps_time";
    EXPECT_EQ(pointColors(c, o).size(), c.size());
    o.attribute = "nope";
    try {
        pointColors(c, o, "simple.las");
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("gps_time"), std::string::npos) << e.what();  // names what there is
    }
}

TEST(LasRender, PlyAndPcdAttributes) {
    const std::string ply = writeText("attrs.ply",
                                      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                      "property float z\nproperty float scalar_Deviation\nproperty uchar class\n"
                                      "property float intensity\nend_header\n0 0 0 0.5 2 10\n1 0 0 1.5 6 20\n"
                                      "0 1 0 2.5 2 30\n");
    const PointCloud p = loadPointCloud(ply);
    ASSERT_TRUE(p.scalar("scalar_Deviation"));
    EXPECT_EQ(p.scalar("scalar_Deviation")->values, (std::vector<float>{0.5f, 1.5f, 2.5f}));
    EXPECT_EQ(p.classes, (std::vector<uint8_t>{2, 6, 2}));
    EXPECT_EQ(p.intensities.size(), 3u);
    ColorOptions o = parseColorOptions("attr:Deviation");  // the scalar_ prefix may be left out
    EXPECT_EQ(pointColors(p, o).size(), 3u);
    LoadFilter ground;
    ground.classes = {2};
    EXPECT_EQ(loadPointCloud(ply, ground).size(), 2u);
    LoadFilter first;
    first.returns = LoadFilter::Returns::First;
    EXPECT_THROW(loadPointCloud(ply, first), Error);  // no return numbers in this file

    const std::string pcd =
        writeText("attrs.pcd",
                  "VERSION .7\nFIELDS x y z intensity label\nSIZE 4 4 4 4 4\nTYPE F F F F U\n"
                  "COUNT 1 1 1 1 1\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n0 0 0 5 9\n1 1 1 7 2\n");
    const PointCloud c = loadPointCloud(pcd);
    EXPECT_EQ(c.classes, (std::vector<uint8_t>{9, 2}));
    EXPECT_EQ(c.intensities, (std::vector<float>{5, 7}));
    ColorOptions cls;
    cls.mode = ColorMode::Classification;
    EXPECT_EQ(pointColors(c, cls)[0], classificationColor(9));
    const PointCloud bunny = loadPointCloud(std::string(RTFACT_POINTS_DATA) + "/bunny_bun000.ply");
    EXPECT_THROW(pointColors(bunny, cls, "bunny"), Error);
}

TEST(LasRender, ViewPresetsAndObliqueDefault) {
    engine::OpenOptions oo;
    oo.progress = false;
    const engine::Scene scene = engine::open({kLas}, oo);
    engine::Settings s;
    const engine::DefaultView auto_ = scene.defaultView(s);
    EXPECT_EQ(auto_.up, Vec3f(0, 0, 1));  // flat and georeferenced: oblique, z up
    EXPECT_GT(auto_.viewDir.z, 0.3f);
    EXPECT_LT(auto_.viewDir.z, 0.9f);
    s.points.view = "top";
    EXPECT_EQ(scene.defaultView(s).viewDir, Vec3f(0, 0, 1));
    s.points.view = "side";
    EXPECT_EQ(scene.defaultView(s).viewDir.x, 1.0f);
    s.points.view = "diagonal";
    EXPECT_THROW(scene.defaultView(s), Error);
    // A cloud that is not flat keeps the head-on default.
    const engine::Scene bunny = engine::open({std::string(RTFACT_POINTS_DATA) + "/bunny_bun000.ply"}, oo);
    EXPECT_EQ(bunny.defaultView().up, Vec3f(0, 1, 0));
}

TEST(LasRender, FileInfo) {
    const auto lines = engine::fileInfo(kLas);
    auto value = [&](const std::string& k) {
        for (const auto& [key, v] : lines)
            if (key == k) return v;
        return std::string("<missing>");
    };
    EXPECT_EQ(value("format"), "LAS 1.2, point format 3, 34-byte records");
    EXPECT_EQ(value("points"), "1065");
    EXPECT_EQ(value("by return"), "1: 925, 2: 114, 3: 21, 4: 5");
    EXPECT_NE(value("by class").find("2 ground: "), std::string::npos) << value("by class");
    EXPECT_EQ(value("crs"), "none");
    EXPECT_EQ(value("scale"), "0.01 0.01 0.01");
}
