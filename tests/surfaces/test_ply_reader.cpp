// The mesh PLY reader's face spellings: triangle strips (element tristrips, -1 restarts,
// alternating winding), vertex_index as well as vertex_indices, every integer list type,
// polygons fanned, faces and strips in one file; ASCII and binary of both byte orders,
// all written by the test itself. Also the one-line errors for bad strips and the
// header size limit.
#include <gtest/gtest.h>

#include <climits>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/render/direct_light_integrator.h"
#include "core/render/framebuffer.h"
#include "core/render/pinhole_camera.h"
#include "core/render/pixel_center_sampler.h"
#include "core/render/ray_tracing_renderer.h"
#include "core/render/tile_scheduler.h"
#include "core/util/error.h"
#include "surfaces/mesh_loader.h"
#include "surfaces/mesh_scene.h"
#include "surfaces/ply_reader.h"
#include "tests/common/image_compare.h"

using namespace rtfact;
using namespace rtfact::surfaces;
namespace fs = std::filesystem;

namespace {

std::string dir() {
    static const std::string d = [] {
        const std::string p = test::testOutDir() + "/surfaces_ply_reader";
        fs::create_directories(p);
        return p;
    }();
    return d;
}

// A PLY file built value by value in any of the three formats.
class PlyWriter {
   public:
    explicit PlyWriter(std::string format) : format_(std::move(format)) {}
    void header(const std::string& line) { head_ += line + "\n"; }
    // One value stored as PLY type `type` (negative values in unsigned types wrap, as a
    // writer casting -1 would store them).
    void value(const std::string& type, double v) {
        if (format_ == "ascii") {
            char b[32];
            std::snprintf(b, sizeof b, "%.9g ", v);
            body_ += b;
            return;
        }
        unsigned char bytes[8];
        size_t n = 0;
        if (type == "float" || type == "float32") {
            const float f = float(v);
            std::memcpy(bytes, &f, n = 4);
        } else if (type == "double" || type == "float64") {
            std::memcpy(bytes, &v, n = 8);
        } else {
            const int64_t i = int64_t(v);
            n = type == "char" || type == "uchar" || type == "int8" || type == "uint8"       ? 1
                : type == "short" || type == "ushort" || type == "int16" || type == "uint16" ? 2
                                                                                             : 4;
            std::memcpy(bytes, &i, n);  // little-endian host
        }
        if (format_ == "binary_big_endian")
            for (size_t k = 0; k < n / 2; ++k) std::swap(bytes[k], bytes[n - 1 - k]);
        body_.append(reinterpret_cast<const char*>(bytes), n);
    }
    void list(const std::string& countType, const std::string& itemType, const std::vector<int>& items) {
        value(countType, double(items.size()));
        for (int x : items) value(itemType, x);
        endLine();
    }
    void endLine() {
        if (format_ == "ascii") body_ += "\n";
    }
    std::string str() const { return "ply\nformat " + format_ + " 1.0\n" + head_ + "end_header\n" + body_; }
    std::string write(const std::string& name) const {
        const std::string p = dir() + "/" + name;
        std::ofstream(p, std::ios::binary) << str();
        return p;
    }

   private:
    std::string format_, head_, body_;
};

const char* kFormats[] = {"ascii", "binary_little_endian", "binary_big_endian"};

// A w x h grid of vertices at (x, y, height), row by row: header, then data.
void writeGridVertices(PlyWriter& ply, int w, int h) {
    ply.header("element vertex " + std::to_string(w * h));
    ply.header("property float x");
    ply.header("property float y");
    ply.header("property float z");
}
void writeGridVertexData(PlyWriter& ply, int w, int h, bool bumpy) {
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            ply.value("float", x);
            ply.value("float", y);
            ply.value("float", bumpy ? 0.6 * std::sin(0.9 * x) * std::cos(0.7 * y) : 0.0);
            ply.endLine();
        }
}

// One strip per grid row, rows separated by -1: (x, y+1), (x, y), (x+1, y+1), ... whose
// first triangle faces +z; every second one is stored the other way round.
std::vector<int> gridStrips(int w, int h) {
    std::vector<int> s;
    for (int y = 0; y + 1 < h; ++y) {
        if (y > 0) s.push_back(-1);
        for (int x = 0; x < w; ++x) {
            s.push_back((y + 1) * w + x);
            s.push_back(y * w + x);
        }
    }
    return s;
}

std::string gridStripFile(const std::string& name, const std::string& format, int w, int h, bool bumpy,
                          const std::string& countType = "int", const std::string& itemType = "int") {
    PlyWriter ply(format);
    writeGridVertices(ply, w, h);
    ply.header("element tristrips 1");
    ply.header("property list " + countType + " " + itemType + " vertex_indices");
    writeGridVertexData(ply, w, h, bumpy);
    ply.list(countType, itemType, gridStrips(w, h));
    return ply.write(name);
}

// The same grid as quads (x, y), (x+1, y), (x+1, y+1), (x, y+1) fanned from their first
// vertex: the same diagonals and orientation as the strips, in another order.
std::string gridQuadFile(const std::string& name, int w, int h, bool bumpy) {
    PlyWriter ply("binary_little_endian");
    writeGridVertices(ply, w, h);
    ply.header("element face " + std::to_string((w - 1) * (h - 1)));
    ply.header("property list uint8 uint32 vertex_index");
    writeGridVertexData(ply, w, h, bumpy);
    for (int y = 0; y + 1 < h; ++y)
        for (int x = 0; x + 1 < w; ++x)
            ply.list("uint8", "uint32", {y * w + x, y * w + x + 1, (y + 1) * w + x + 1, (y + 1) * w + x});
    return ply.write(name);
}

Vec3f faceNormal(const Mesh& m, size_t t) {
    const Vec3f a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]],
                c = m.positions[m.indices[3 * t + 2]];
    return cross(b - a, c - a);
}

void expectError(const std::string& path, const std::string& needle) {
    try {
        loadMesh(path);
        FAIL() << path << " loaded without error";
    } catch (const Error& e) {
        EXPECT_EQ(e.file(), path);
        const std::string msg = e.what();
        EXPECT_EQ(msg.find('\n'), std::string::npos) << "multi-line error: " << msg;
        EXPECT_NE(msg.find(needle), std::string::npos) << "message: " << msg;
        EXPECT_LT(msg.size(), 200u) << msg;
    }
}

}  // namespace

// A 3 x 2 grid (v0 v1 v2 / v3 v4 v5): two strips with a restart, and a third that starts
// with a degenerate triangle (dropped, but it still counts for the alternation).
TEST(PlyStrips, ExactTrianglesInEveryFormatAndListType) {
    const std::vector<int> strip = {3, 0, 4, 1, -1, 4, 1, 5, 2, -1, 0, 0, 1, 3};
    const std::vector<uint32_t> expected = {3, 0, 4, 4, 0, 1, 4, 1, 5, 5, 1, 2, 1, 0, 3};
    const std::pair<const char*, const char*> types[] = {{"int", "int"},       {"uchar", "int"},   {"uint8", "int32"},
                                                         {"uint32", "uint32"}, {"ushort", "uint"}, {"int16", "short"}};
    for (const char* format : kFormats)
        for (const auto& [countType, itemType] : types) {
            PlyWriter ply(format);
            ply.header("comment strips with restarts");
            writeGridVertices(ply, 3, 2);
            ply.header("element tristrips 1");
            ply.header(std::string("property list ") + countType + " " + itemType + " vertex_indices");
            writeGridVertexData(ply, 3, 2, false);
            ply.list(countType, itemType, strip);
            const std::string path =
                ply.write(std::string("exact_") + format + "_" + countType + "_" + itemType + ".ply");
            SCOPED_TRACE(path);
            EXPECT_EQ(meshFileKind(path), MeshFileKind::Ply);
            const Mesh m = loadMesh(path);
            EXPECT_EQ(m.indices, expected);
        }
}

// A strip mesh of a flat grid: every triangle faces +z whatever its place in the strip,
// so the computed vertex normals do too (inconsistent windings would cancel them out).
TEST(PlyStrips, ConsistentNormals) {
    constexpr int w = 9, h = 6;
    for (const char* format : kFormats) {
        const std::string path = gridStripFile(std::string("grid_") + format + ".ply", format, w, h, false);
        SCOPED_TRACE(path);
        const Mesh m = loadMesh(path);
        ASSERT_EQ(m.triangles(), size_t(2 * (w - 1) * (h - 1)));
        for (size_t t = 0; t < m.triangles(); ++t) EXPECT_GT(faceNormal(m, t).z, 0.0f) << "triangle " << t;
        ASSERT_EQ(m.normals.size(), size_t(w * h));
        for (const Vec3f& n : m.normals) EXPECT_NEAR(n.z, 1.0f, 1e-6f);
    }
}

// Other face spellings: vertex_index with uint8/uint32, polygons of 3 to 5 vertices,
// other list properties skipped, and faces and strips in one file (in file order).
TEST(PlyStrips, FaceSpellingsAndFacesWithStrips) {
    for (const char* format : kFormats) {
        PlyWriter ply(format);
        writeGridVertices(ply, 3, 2);
        ply.header("element face 2");
        ply.header("property list uchar float texcoord");
        ply.header("property list uint8 uint32 vertex_index");
        ply.header("property uchar flags");
        ply.header("element tristrips 1");
        ply.header("property list int int vertex_indices");
        writeGridVertexData(ply, 3, 2, false);
        ply.list("uchar", "float", {0, 1});
        ply.list("uint8", "uint32", {0, 1, 4, 3});  // quad: (0 1 4) (0 4 3)
        ply.value("uchar", 7);
        ply.list("uchar", "float", {});
        ply.list("uint8", "uint32", {1, 2, 5, 4, 4});  // pentagon with a repeated vertex
        ply.value("uchar", 7);
        ply.list("int", "int", {3, 0, 4, 1});
        const std::string path = ply.write(std::string("spellings_") + format + ".ply");
        SCOPED_TRACE(path);
        const Mesh m = loadMesh(path);
        const std::vector<uint32_t> expected = {0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4, 3, 0, 4, 4, 0, 1};
        EXPECT_EQ(m.indices, expected);
    }
}

// The same bumpy grid stored as strips (ASCII, binary of both byte orders, signed and
// unsigned indices) and as quads renders the same image.
TEST(PlyStrips, StripMeshRendersLikeFaceMesh) {
    constexpr int w = 24, h = 18, kW = 80, kH = 60;
    auto render = [&](const std::string& path) {
        const MeshScene<BVH<Triangle>> scene(std::make_shared<const Mesh>(loadMesh(path)));
        const PinholeCamera cam(fitCamera(scene.bounds(), 45.0f, float(kW) / float(kH), {0.3f, -0.8f, 1.0f}, {0, 0, 1}),
                                kW, kH);
        RGBAFramebuffer fb(kW, kH);
        DirectLightIntegrator integ;
        integ.lights = {PointLight{{30.0f, -10.0f, 25.0f}, Vec3f(2000.0f)}};
        RayTracingRenderer<PixelCenterSampler, DirectLightIntegrator> r{{}, integ};
        RenderOptions o;
        o.progress = false;
        renderImage<simd::kNativeWidth>(r, scene, cam, fb, o);
        return fb.resolved(1);
    };
    const std::vector<float> faces = render(gridQuadFile("bumpy_quads.ply", w, h, true));
    double lit = 0;
    for (size_t i = 0; i < faces.size(); i += 4) lit += faces[i];
    ASSERT_GT(lit / (kW * kH), 0.05) << "the reference image is dark: the test would compare nothing";
    for (const char* format : kFormats)
        for (const char* itemType : {"int", "uint32"}) {
            const std::string path = gridStripFile(std::string("bumpy_") + format + "_" + itemType + ".ply", format, w,
                                                   h, true, "uint32", itemType);
            SCOPED_TRACE(path);
            const std::vector<float> strips = render(path);
            ASSERT_EQ(strips.size(), faces.size());
            float maxDiff = 0;
            for (size_t i = 0; i < faces.size(); ++i) maxDiff = std::max(maxDiff, std::fabs(strips[i] - faces[i]));
            // Same triangles, other order (other BVH): only float rounding of the normals.
            EXPECT_LT(maxDiff, 1e-4f);
        }
}

TEST(PlyStrips, BadStripsGiveOneLineErrors) {
    auto stripFile = [](const std::string& name, const std::string& format, const std::vector<int>& strip,
                        int countOverride = INT_MIN, size_t cut = 0) {
        PlyWriter ply(format);
        writeGridVertices(ply, 3, 2);
        ply.header("element tristrips 1");
        ply.header("property list int int vertex_indices");
        writeGridVertexData(ply, 3, 2, false);
        ply.value("int", countOverride != INT_MIN ? countOverride : int(strip.size()));
        for (int x : strip) ply.value("int", x);
        std::string bytes = ply.str();
        bytes.resize(bytes.size() - cut);
        const std::string p = dir() + "/" + name;
        std::ofstream(p, std::ios::binary) << bytes;
        return p;
    };
    for (const char* format : {"ascii", "binary_little_endian"}) {
        const std::string f = format;
        expectError(stripFile("range_" + f + ".ply", f, {3, 0, 4, 9}), "tristrips 0 entry 3 refers to vertex 9 of 6");
        expectError(stripFile("negative_" + f + ".ply", f, {3, 0, 4, -2}), "refers to vertex -2 of 6");
        expectError(stripFile("count_" + f + ".ply", f, {3, 0, 4, 1}, 2000000000),
                    "truncated or corrupt PLY data: tristrips 0 lists 2000000000 values");
        expectError(stripFile("cut_" + f + ".ply", f, {3, 0, 4, 1, 5, 2}, INT_MIN, f == "ascii" ? 4 : 8), "truncated");
    }
    expectError(stripFile("negcount.ply", "ascii", {3, 0, 4}, -5), "tristrips 0: bad list length -5");
    // The same files with good data load (the cases above fail for the reason named).
    EXPECT_EQ(loadMesh(stripFile("good.ply", "binary_little_endian", {3, 0, 4, 1})).triangles(), 2u);
}

// The memory check before reading counts what strips can hold: at least the triangles
// they give and, in binary files, at most one per index (ASCII: within a small factor).
TEST(PlyStrips, TriangleEstimateBoundsStrips) {
    constexpr int w = 30, h = 20;
    const uint64_t triangles = 2 * (w - 1) * (h - 1), entries = gridStrips(w, h).size();
    for (const char* format : kFormats) {
        const std::string path = gridStripFile(std::string("estimate_") + format + ".ply", format, w, h, false);
        SCOPED_TRACE(path);
        const uint64_t estimate = plyTriangleEstimate(io::readPlyHeader(io::MappedFile(path)));
        EXPECT_GE(estimate, triangles);
        EXPECT_LE(estimate, std::string(format) == "ascii" ? 2 * entries : entries);
    }
}

// A header past the size limit (here a 10 MB comment) is reported as such, not as a
// missing end_header; a header that really ends early still says end_header.
TEST(PlyHeader, GiantCommentNamesTheLimit) {
    const std::string path = dir() + "/giant_comment.ply";
    {
        std::ofstream out(path, std::ios::binary);
        out << "ply\nformat ascii 1.0\ncomment " << std::string(10 << 20, 'x') << "\n"
            << "element vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
            << "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    }
    expectError(path, "PLY header longer than " + std::to_string(io::kMaxPlyHeaderBytes) + " bytes (the limit)");
    // Just below the limit: loads.
    const std::string ok = dir() + "/long_comment.ply";
    {
        std::ofstream out(ok, std::ios::binary);
        out << "ply\nformat ascii 1.0\ncomment " << std::string(io::kMaxPlyHeaderBytes - 1024, 'x') << "\n"
            << "element vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
            << "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    }
    EXPECT_EQ(loadMesh(ok).triangles(), 1u);
    std::ofstream(dir() + "/unterminated.ply", std::ios::binary) << "ply\nformat ascii 1.0\nelement vertex 3\n";
    expectError(dir() + "/unterminated.ply", "not terminated by end_header");
}
