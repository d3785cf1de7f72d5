// The truncation/bit-flip sweep (sweep.h) for every format without a shipped file: each
// test writes a small valid file by hand at run time (a few KB at most), checks that it
// loads, then sweeps it. PCD (ascii, binary, binary_compressed), XYZ, PTS; OBJ (and its
// MTL), binary and ASCII STL, legacy VTK, VTP; NRRD (attached, detached, gzip), NIfTI
// (.nii, .nii.gz), VTI, OpenVDB (uncompressed and zip); a PNG texture read at scene build.
#include <gtest/gtest.h>
#include <openvdb/openvdb.h>
#include <zlib.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "core/render/image_io.h"
#include "core/util/error.h"
#include "points/point_cloud_io.h"
#include "surfaces/mesh_loader.h"
#include "surfaces/mesh_scene.h"
#include "sweep.h"
#include "tests/common/deflate_bytes.h"
#include "volume/volume_io.h"

using namespace rtfact;
using namespace rtfact::surfaces;
using namespace rtfact::reliability;

namespace {

// ---- helpers -----------------------------------------------------------------------

std::string fmt(const char* f, double v) {
    char b[64];
    std::snprintf(b, sizeof(b), f, v);
    return b;
}
std::string num(double v) { return fmt("%.6g", v); }

template <class T>
void putLE(std::string& s, T v) {
    s.append(reinterpret_cast<const char*>(&v), sizeof(T));  // x86-64: little endian
}

std::string gzip(const std::string& raw) { return test::deflateBytes(raw, 15 + 16); }

// LZF with literal runs only: a control byte c < 32 followed by c + 1 literal bytes.
std::string lzfLiterals(const std::string& raw) {
    std::string out;
    for (size_t i = 0; i < raw.size(); i += 32) {
        const size_t n = std::min<size_t>(32, raw.size() - i);
        out.push_back(char(n - 1));
        out.append(raw, i, n);
    }
    return out;
}

// ---- generated files ---------------------------------------------------------------

constexpr int kPoints = 48;
struct Pt {
    float x, y, z, intensity;
    uint32_t rgb;
};
std::vector<Pt> cloudPoints() {
    std::vector<Pt> p;
    for (int i = 0; i < kPoints; ++i) {
        const float t = float(i) * 0.37f, s = float(i) * 0.11f;
        p.push_back({std::cos(t) * std::sin(s) + 0.25f, std::sin(t) * std::sin(s) - 1.5f, std::cos(s) * 2.0f,
                     float(i % 7) * 10.0f,
                     uint32_t((i * 40) % 256) << 16 | uint32_t((i * 17) % 256) << 8 | uint32_t(i * 5 % 256)});
    }
    return p;
}

std::string pcdHeader(const char* data) {
    return "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z intensity rgb\nSIZE 4 4 4 4 4\n"
           "TYPE F F F F U\nCOUNT 1 1 1 1 1\nWIDTH " +
           std::to_string(kPoints) + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + std::to_string(kPoints) +
           "\nDATA " + data + "\n";
}
std::string pcdAscii() {
    std::string s = pcdHeader("ascii");
    for (const Pt& p : cloudPoints())
        s += num(p.x) + " " + num(p.y) + " " + num(p.z) + " " + num(p.intensity) + " " + std::to_string(p.rgb) + "\n";
    return s;
}
std::string pcdBinary() {
    std::string s = pcdHeader("binary");
    for (const Pt& p : cloudPoints()) {
        putLE(s, p.x), putLE(s, p.y), putLE(s, p.z), putLE(s, p.intensity), putLE(s, p.rgb);
    }
    return s;
}
std::string pcdCompressed() {
    // Field-major (SoA) layout, then LZF.
    const std::vector<Pt> pts = cloudPoints();
    std::string soa;
    for (const Pt& p : pts) putLE(soa, p.x);
    for (const Pt& p : pts) putLE(soa, p.y);
    for (const Pt& p : pts) putLE(soa, p.z);
    for (const Pt& p : pts) putLE(soa, p.intensity);
    for (const Pt& p : pts) putLE(soa, p.rgb);
    const std::string lzf = lzfLiterals(soa);
    std::string s = pcdHeader("binary_compressed");
    putLE(s, uint32_t(lzf.size()));
    putLE(s, uint32_t(soa.size()));
    return s + lzf;
}
std::string xyzText() {
    // x y z nx ny nz (|normal| <= 1: read as normals)
    std::string s;
    for (const Pt& p : cloudPoints()) {
        const float l = std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
        s += num(p.x) + " " + num(p.y) + " " + num(p.z) + " " + num(p.x / l) + " " + num(p.y / l) + " " + num(p.z / l) +
             "\n";
    }
    return s;
}
std::string ptsText() {
    // count, then x y z intensity r g b
    std::string s = std::to_string(kPoints) + "\n";
    for (const Pt& p : cloudPoints())
        s += num(p.x) + " " + num(p.y) + " " + num(p.z) + " " + num(p.intensity) + " " + std::to_string(p.rgb >> 16) +
             " " + std::to_string((p.rgb >> 8) & 255) + " " + std::to_string(p.rgb & 255) + "\n";
    return s;
}

void loadCloud(const std::string& p) {
    const points::PointCloud c = points::loadPointCloud(p);
    (void)c;
}

// ---- meshes ------------------------------------------------------------------------

// A 5x5 grid of vertices with a bump: 32 triangles.
constexpr int kGrid = 5;
struct GridMesh {
    std::vector<std::array<float, 3>> v;
    std::vector<std::array<float, 2>> uv;
    std::vector<std::array<int, 3>> tris;  // 0-based
};
GridMesh gridMesh() {
    GridMesh m;
    for (int j = 0; j < kGrid; ++j)
        for (int i = 0; i < kGrid; ++i) {
            const float x = float(i) / (kGrid - 1), y = float(j) / (kGrid - 1);
            m.v.push_back({x, y, 0.3f * std::sin(3.0f * x) * std::cos(2.0f * y)});
            m.uv.push_back({x, y});
        }
    for (int j = 0; j + 1 < kGrid; ++j)
        for (int i = 0; i + 1 < kGrid; ++i) {
            const int a = j * kGrid + i, b = a + 1, c = a + kGrid, d = c + 1;
            m.tris.push_back({a, b, d});
            m.tris.push_back({a, d, c});
        }
    return m;
}
std::array<float, 3> triNormal(const GridMesh& m, const std::array<int, 3>& t) {
    const auto& a = m.v[size_t(t[0])];
    const auto& b = m.v[size_t(t[1])];
    const auto& c = m.v[size_t(t[2])];
    const float u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    std::array<float, 3> n = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    const float l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (float& x : n) x /= l;
    return n;
}

// OBJ with positions, uvs, normals, two materials from `mtl` (a name next to the OBJ).
std::string objText(const std::string& mtl) {
    const GridMesh m = gridMesh();
    std::string s = "# rtfact reliability sweep\nmtllib " + mtl + "\no grid\n";
    for (const auto& v : m.v) s += "v " + num(v[0]) + " " + num(v[1]) + " " + num(v[2]) + "\n";
    for (const auto& t : m.uv) s += "vt " + num(t[0]) + " " + num(t[1]) + "\n";
    s += "vn 0 0 1\n";
    for (size_t k = 0; k < m.tris.size(); ++k) {
        if (k == 0) s += "usemtl red\n";
        if (k == m.tris.size() / 2) s += "usemtl textured\ns 1\n";
        s += "f";
        for (int i : m.tris[k]) s += " " + std::to_string(i + 1) + "/" + std::to_string(i + 1) + "/1";
        s += "\n";
    }
    return s;
}
std::string mtlText(const std::string& texture) {
    return "# two materials\nnewmtl red\nKd 0.8 0.1 0.1\nKs 0.2 0.2 0.2\nNs 32\nillum 2\n\nnewmtl textured\nKd 1 1 1\n"
           "Ks 0 0 0\nNi 1.5\nd 1\nillum 1\nmap_Kd " +
           texture + "\n";
}
std::string stlBinary() {
    const GridMesh m = gridMesh();
    std::string s = "rtfact reliability sweep: binary STL";
    s.resize(80, ' ');
    putLE(s, uint32_t(m.tris.size()));
    for (const auto& t : m.tris) {
        for (float x : triNormal(m, t)) putLE(s, x);
        for (int i : t)
            for (float x : m.v[size_t(i)]) putLE(s, x);
        putLE(s, uint16_t(0));
    }
    return s;
}
std::string stlAscii() {
    const GridMesh m = gridMesh();
    std::string s = "solid grid\n";
    for (const auto& t : m.tris) {
        const auto n = triNormal(m, t);
        s += "  facet normal " + num(n[0]) + " " + num(n[1]) + " " + num(n[2]) + "\n    outer loop\n";
        for (int i : t) {
            const auto& v = m.v[size_t(i)];
            s += "      vertex " + num(v[0]) + " " + num(v[1]) + " " + num(v[2]) + "\n";
        }
        s += "    endloop\n  endfacet\n";
    }
    return s + "endsolid grid\n";
}
std::string vtkLegacy() {
    const GridMesh m = gridMesh();
    std::string s = "# vtk DataFile Version 3.0\nrtfact reliability sweep\nASCII\nDATASET POLYDATA\nPOINTS " +
                    std::to_string(m.v.size()) + " float\n";
    for (const auto& v : m.v) s += num(v[0]) + " " + num(v[1]) + " " + num(v[2]) + "\n";
    s += "POLYGONS " + std::to_string(m.tris.size()) + " " + std::to_string(4 * m.tris.size()) + "\n";
    for (const auto& t : m.tris)
        s += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
    s += "POINT_DATA " + std::to_string(m.v.size()) + "\nTEXTURE_COORDINATES uv 2 float\n";
    for (const auto& t : m.uv) s += num(t[0]) + " " + num(t[1]) + "\n";
    return s;
}
std::string vtpXml() {
    const GridMesh m = gridMesh();
    std::string s =
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n<PolyData>\n"
        "<Piece NumberOfPoints=\"" +
        std::to_string(m.v.size()) +
        "\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"" +
        std::to_string(m.tris.size()) +
        "\">\n<PointData TCoords=\"uv\">\n"
        "<DataArray type=\"Float32\" Name=\"uv\" NumberOfComponents=\"2\" format=\"ascii\">\n";
    for (const auto& t : m.uv) s += num(t[0]) + " " + num(t[1]) + "\n";
    s += "</DataArray>\n</PointData>\n<Points>\n<DataArray type=\"Float32\" NumberOfComponents=\"3\" "
         "format=\"ascii\">\n";
    for (const auto& v : m.v) s += num(v[0]) + " " + num(v[1]) + " " + num(v[2]) + "\n";
    s += "</DataArray>\n</Points>\n<Polys>\n<DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">\n";
    for (const auto& t : m.tris)
        s += std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
    s += "</DataArray>\n<DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">\n";
    for (size_t k = 0; k < m.tris.size(); ++k) s += std::to_string(3 * (k + 1)) + (k % 8 == 7 ? "\n" : " ");
    s += "\n</DataArray>\n</Polys>\n</Piece>\n</PolyData>\n</VTKFile>\n";
    return s;
}

void loadMeshFile(const std::string& p) { (void)loadMesh(p); }

// ---- volumes -----------------------------------------------------------------------

constexpr int kNx = 10, kNy = 8, kNz = 6;
uint16_t voxel(int i, int j, int k) {
    const float dx = float(i) - 4.5f, dy = float(j) - 3.5f, dz = float(k) - 2.5f;
    return uint16_t(4000.0f * std::exp(-(dx * dx + dy * dy + dz * dz) / 12.0f) + float((i * 7 + j * 13 + k * 29) % 97));
}
std::string u16Payload() {
    std::string s;
    for (int k = 0; k < kNz; ++k)
        for (int j = 0; j < kNy; ++j)
            for (int i = 0; i < kNx; ++i) putLE(s, voxel(i, j, k));
    return s;
}
std::string nrrdHeader(const std::string& encoding, const std::string& dataFile) {
    std::string s =
        "NRRD0004\n# rtfact reliability sweep\ntype: unsigned short\ndimension: 3\nsizes: " + std::to_string(kNx) +
        " " + std::to_string(kNy) + " " + std::to_string(kNz) +
        "\nspace: left-posterior-superior\nspace directions: (0.5,0,0) (0,0.5,0) (0,0,1.25)\n"
        "space origin: (-2.5,-2,0)\nkinds: domain domain domain\nendian: little\nencoding: " +
        encoding + "\n";
    if (!dataFile.empty()) s += "data file: " + dataFile + "\n";
    return s + "\n";
}
// NIfTI-1: the 348-byte header, 4 extension bytes (none), i16 data at vox_offset 352.
std::string nifti() {
    std::string h(352, '\0');
    auto put = [&](int off, const void* v, size_t n) { std::memcpy(&h[size_t(off)], v, n); };
    const int32_t sz = 348;
    put(0, &sz, 4);
    const int16_t dim[8] = {3, kNx, kNy, kNz, 1, 1, 1, 1};
    put(40, dim, 16);
    const int16_t datatype = 4, bitpix = 16;  // DT_INT16
    put(70, &datatype, 2);
    put(72, &bitpix, 2);
    const float pix[8] = {1, 0.5f, 0.75f, 2.0f, 1, 1, 1, 1};
    put(76, pix, 32);
    const float vox = 352, slope = 0.5f, inter = -100.0f;
    put(108, &vox, 4);
    put(112, &slope, 4);
    put(116, &inter, 4);
    const uint8_t units = 2;  // mm
    put(123, &units, 1);
    put(148, "rtfact reliability sweep", 24);
    put(344, "n+1", 4);
    std::string data;
    for (int k = 0; k < kNz; ++k)
        for (int j = 0; j < kNy; ++j)
            for (int i = 0; i < kNx; ++i) putLE(data, int16_t(int(voxel(i, j, k)) - 2000));
    return h + data;
}
std::string vti() {
    std::string s =
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
        "<ImageData WholeExtent=\"0 " +
        std::to_string(kNx - 1) + " 0 " + std::to_string(kNy - 1) + " 0 " + std::to_string(kNz - 1) +
        "\" Origin=\"0 0 0\" Spacing=\"0.5 0.5 1.25\">\n<Piece Extent=\"0 " + std::to_string(kNx - 1) + " 0 " +
        std::to_string(kNy - 1) + " 0 " + std::to_string(kNz - 1) +
        "\">\n<PointData Scalars=\"density\">\n<DataArray type=\"UInt8\" Name=\"density\" format=\"ascii\">\n";
    int n = 0;
    for (int k = 0; k < kNz; ++k)
        for (int j = 0; j < kNy; ++j)
            for (int i = 0; i < kNx; ++i) s += std::to_string(voxel(i, j, k) / 16) + (++n % 20 == 0 ? "\n" : " ");
    s += "\n</DataArray>\n</PointData>\n<CellData>\n</CellData>\n</Piece>\n</ImageData>\n</VTKFile>\n";
    return s;
}
std::string vdbBytes(uint32_t compression) {
    openvdb::initialize();
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
    grid->setName("density");
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(0.5));
    auto acc = grid->getAccessor();
    for (int k = 0; k < kNz; ++k)
        for (int j = 0; j < kNy; ++j)
            for (int i = 0; i < kNx; ++i)
                if ((i + j + k) % 3 != 0)
                    acc.setValue(openvdb::Coord(i + 1, j + 2, k + 3), float(voxel(i, j, k)) / 4000.0f);
    const std::string tmp = sweepPath(".tmp.vdb");
    openvdb::io::File f(tmp);
    f.setCompression(compression);
    f.write({grid});
    f.close();
    std::string bytes = readAll(tmp);
    std::filesystem::remove(tmp);
    return bytes;
}

volume::VolumeLoadOptions quiet() {
    volume::VolumeLoadOptions o;
    o.progress = false;
    return o;
}
void loadVol(const std::string& p) { (void)volume::loadVolume(p, quiet()); }

// The intact volume is the one generated (dims), so the sweep's "loads" are meaningful.
void expectDims(const std::string& p, int nx, int ny, int nz) {
    const volume::VolumeGrid g = volume::loadVolume(p, quiet());
    EXPECT_EQ(g.dims[0], nx);
    EXPECT_EQ(g.dims[1], ny);
    EXPECT_EQ(g.dims[2], nz);
}

}  // namespace

// ---- point clouds ------------------------------------------------------------------

namespace {
// The intact file must load all its points; then at least `minRejected` variants must fail.
void sweepCloud(const std::string& bytes, const std::string& ext, int minRejected) {
    writeAll(sweepPath(ext), bytes);
    EXPECT_EQ(points::loadPointCloud(sweepPath(ext)).size(), size_t(kPoints));
    EXPECT_GT(hammerBytes(bytes, ext, loadCloud).rejected, minRejected);
}
}  // namespace

TEST(Hostile, PcdAsciiTruncatedAndFlipped) { sweepCloud(pcdAscii(), ".pcd", 70); }

TEST(Hostile, PcdBinaryTruncatedAndFlipped) { sweepCloud(pcdBinary(), ".pcd", 70); }

TEST(Hostile, PcdBinaryCompressedTruncatedAndFlipped) { sweepCloud(pcdCompressed(), ".pcd", 70); }

TEST(Hostile, XyzTruncatedAndFlipped) { sweepCloud(xyzText(), ".xyz", 80); }

// The count on the first line catches every truncation.
TEST(Hostile, PtsTruncatedAndFlipped) { sweepCloud(ptsText(), ".pts", 90); }

// ---- meshes ------------------------------------------------------------------------

TEST(Hostile, ObjTruncatedAndFlipped) {
    const std::string mtl = testName() + ".mtl";
    writeAll(outDir() + "/" + mtl, mtlText(testName() + ".png"));
    const std::string bytes = objText(mtl);
    writeAll(sweepPath(".obj"), bytes);
    const Mesh m = loadMesh(sweepPath(".obj"));
    EXPECT_EQ(m.triangles(), gridMesh().tris.size());
    EXPECT_EQ(m.materials.size(), size_t(2));
    const Outcome o = hammerBytes(bytes, ".obj", loadMeshFile);
    EXPECT_GT(o.rejected, 80);
}

TEST(Hostile, ObjMaterialLibraryTruncatedAndFlipped) {
    // The MTL is swept; the OBJ next to it stays intact.
    const std::string obj = outDir() + "/" + testName() + "_model.obj";
    writeAll(obj, objText(testName() + ".mtl"));
    const std::string bytes = mtlText(testName() + ".png");
    const Outcome o = hammerBytes(bytes, ".mtl", [&](const std::string&) { (void)loadMesh(obj); });
    EXPECT_GT(o.rejected, 25);
}

TEST(Hostile, StlBinaryTruncatedAndFlipped) {
    const std::string bytes = stlBinary();
    writeAll(sweepPath(".stl"), bytes);
    EXPECT_EQ(loadMesh(sweepPath(".stl")).triangles(), gridMesh().tris.size());
    const Outcome o = hammerBytes(bytes, ".stl", loadMeshFile);
    EXPECT_GT(o.rejected, 70);  // every truncation breaks the triangle count
}

TEST(Hostile, StlAsciiTruncatedAndFlipped) {
    const std::string bytes = stlAscii();
    writeAll(sweepPath(".stl"), bytes);
    EXPECT_EQ(loadMesh(sweepPath(".stl")).triangles(), gridMesh().tris.size());
    const Outcome o = hammerBytes(bytes, ".stl", loadMeshFile);
    EXPECT_GT(o.rejected, 90);
}

// Found by this sweep, fixed by surfaces/vtk_legacy_check.cpp: a POLYGONS list shorter
// than declared (the file cut after the "POLYGONS 32 128" line) crashed vtkPolyDataReader
// (SIGSEGV in vtkDataReader::ReadString).
TEST(Hostile, VtkLegacyTruncatedAndFlipped) {
    const std::string bytes = vtkLegacy();
    writeAll(sweepPath(".vtk"), bytes);
    const Mesh m = loadMesh(sweepPath(".vtk"));
    EXPECT_EQ(m.triangles(), gridMesh().tris.size());
    EXPECT_EQ(m.uvs.size(), 2 * m.positions.size());
    const Outcome o = hammerBytes(bytes, ".vtk", loadMeshFile);
    EXPECT_GT(o.rejected, 60);
}

TEST(Hostile, VtpTruncatedAndFlipped) {
    const std::string bytes = vtpXml();
    writeAll(sweepPath(".vtp"), bytes);
    const Mesh m = loadMesh(sweepPath(".vtp"));
    EXPECT_EQ(m.triangles(), gridMesh().tris.size());
    EXPECT_EQ(m.uvs.size(), 2 * m.positions.size());
    const Outcome o = hammerBytes(bytes, ".vtp", loadMeshFile);
    EXPECT_GT(o.rejected, 90);
}

// map_Kd images are read when the scene is built (MeshScene::build -> readImage): the PNG
// is swept, the OBJ and MTL pointing at it stay intact.
TEST(Hostile, TexturePngTruncatedAndFlipped) {
    const std::string png = sweepPath(".png");
    std::vector<float> rgba;
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) {
            rgba.insert(rgba.end(), {float(x) / 15.0f, float(y) / 15.0f, float((x * 7 + y * 3) % 16) / 15.0f, 1.0f});
        }
    writeImage(png, 16, 16, rgba);
    const std::string bytes = readAll(png);
    writeAll(outDir() + "/" + testName() + ".mtl", mtlText(testName() + ".png"));
    const std::string obj = outDir() + "/" + testName() + "_model.obj";
    writeAll(obj, objText(testName() + ".mtl"));
    const auto mesh = std::make_shared<const Mesh>(loadMesh(obj));
    ASSERT_FALSE(mesh->uvs.empty());
    {
        const MeshScene<BVH<Triangle>> scene(mesh);
        ASSERT_EQ(scene.diffuseMaps.size(), size_t(2));
        ASSERT_TRUE(scene.diffuseMaps[1].image);
        EXPECT_EQ(scene.diffuseMaps[1].image->width, 16);
    }
    const Outcome o = hammerBytes(bytes, ".png", [&](const std::string&) {
        MeshScene<BVH<Triangle>> scene;
        scene.buildWide = false;
        scene.mesh = mesh;
        scene.build();
    });
    EXPECT_GT(o.rejected, 90);
}

// ---- volumes -----------------------------------------------------------------------

TEST(Hostile, NrrdAttachedTruncatedAndFlipped) {
    const std::string bytes = nrrdHeader("raw", "") + u16Payload();
    writeAll(sweepPath(".nrrd"), bytes);
    expectDims(sweepPath(".nrrd"), kNx, kNy, kNz);
    const Outcome o = hammerBytes(bytes, ".nrrd", loadVol);
    EXPECT_GT(o.rejected, 70);
}

TEST(Hostile, NrrdDetachedHeaderTruncatedAndFlipped) {
    const std::string raw = testName() + "_data.raw";
    writeAll(outDir() + "/" + raw, u16Payload());
    const std::string bytes = nrrdHeader("raw", raw);
    writeAll(sweepPath(".nhdr"), bytes);
    expectDims(sweepPath(".nhdr"), kNx, kNy, kNz);
    const Outcome o = hammerBytes(bytes, ".nhdr", loadVol);
    EXPECT_GT(o.rejected, 90);
}

TEST(Hostile, NrrdGzipTruncatedAndFlipped) {
    const std::string bytes = nrrdHeader("gzip", "") + gzip(u16Payload());
    writeAll(sweepPath(".nrrd"), bytes);
    expectDims(sweepPath(".nrrd"), kNx, kNy, kNz);
    const Outcome o = hammerBytes(bytes, ".nrrd", loadVol);
    EXPECT_GT(o.rejected, 90);
}

TEST(Hostile, NiftiTruncatedAndFlipped) {
    const std::string bytes = nifti();
    writeAll(sweepPath(".nii"), bytes);
    expectDims(sweepPath(".nii"), kNx, kNy, kNz);
    const Outcome o = hammerBytes(bytes, ".nii", loadVol);
    EXPECT_GT(o.rejected, 70);  // every truncation cuts the header or the data
}

TEST(Hostile, NiftiGzipTruncatedAndFlipped) {
    const std::string bytes = gzip(nifti());
    writeAll(sweepPath(".nii.gz"), bytes);
    expectDims(sweepPath(".nii.gz"), kNx, kNy, kNz);
    const Outcome o = hammerBytes(bytes, ".nii.gz", loadVol);
    EXPECT_GT(o.rejected, 90);
}

TEST(Hostile, VtiTruncatedAndFlipped) {
    const std::string bytes = vti();
    writeAll(sweepPath(".vti"), bytes);
    expectDims(sweepPath(".vti"), kNx, kNy, kNz);
    const Outcome o = hammerBytes(bytes, ".vti", loadVol);
    EXPECT_GT(o.rejected, 90);
}

// Found by these sweeps, fixed by volume/vdb_file_check.cpp: OpenVDB read a cut header past
// the end of the file and took garbage string lengths (cut at 105 bytes: ~20 s, then a
// 431 MB "KeyError: Map ..." message).
TEST(Hostile, VdbTruncatedAndFlipped) {
    // Values stored plainly (only inactive tiles are elided, else the internal nodes' tile
    // tables make the file ~160 KB).
    const std::string bytes = vdbBytes(openvdb::io::COMPRESS_ACTIVE_MASK);
    writeAll(sweepPath(".vdb"), bytes);
    expectDims(sweepPath(".vdb"), kNx, kNy, kNz);
    const Outcome o = hammerBytes(bytes, ".vdb", loadVol);
    EXPECT_GT(o.rejected, 60);
}

TEST(Hostile, VdbZipTruncatedAndFlipped) {
    const std::string bytes = vdbBytes(openvdb::io::COMPRESS_ZIP | openvdb::io::COMPRESS_ACTIVE_MASK);
    writeAll(sweepPath(".vdb"), bytes);
    expectDims(sweepPath(".vdb"), kNx, kNy, kNz);
    const Outcome o = hammerBytes(bytes, ".vdb", loadVol);
    EXPECT_GT(o.rejected, 60);
}
