// Loaders: the same cloud through every format and encoding; hostile files (truncated,
// lying counts, NaN points, empty clouds, garbage) give rtfact::Error with a clear
// message, never a crash or a huge allocation.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <future>

#include "core/util/error.h"
#include "points/point_cloud_io.h"

using namespace rtfact;
using namespace rtfact::points;
namespace fs = std::filesystem;

namespace {

// One directory per test process, removed when the process exits.
fs::path tmpDir() {
    struct Dir {
        fs::path path = fs::temp_directory_path() / ("rtfact_points_io_" + std::to_string(::getpid()));
        ~Dir() {
            std::error_code ec;
            fs::remove_all(path, ec);
        }
    };
    static const Dir d;
    fs::create_directories(d.path);
    return d.path;
}
std::string writeFile(const std::string& name, const std::string& bytes) {
    const fs::path p = tmpDir() / name;
    std::ofstream(p, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
    return p.string();
}
template <class T>
void put(std::string& s, T v, bool bigEndian = false) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    if (bigEndian) std::reverse(b, b + sizeof(T));
    s.append(b, sizeof(T));
}

// Three points with normals, uchar colours, radius and intensity.
const float P[3][3] = {{0, 0, 0}, {1, 2, 3}, {-1, 0.5f, 2}};
const float Nn[3][3] = {{0, 0, 1}, {0, 1, 0}, {1, 0, 0}};
const int Col[3][3] = {{255, 0, 0}, {0, 255, 0}, {10, 20, 30}};

std::string plyHeader(const std::string& fmt, int n, bool floatColor = false) {
    const std::string ct = floatColor ? "float" : "uchar";
    return "ply\nformat " + fmt + " 1.0\ncomment test\nelement vertex " + std::to_string(n) +
           "\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty "
           "float nz\n"
           "property " +
           ct + " red\nproperty " + ct + " green\nproperty " + ct +
           " blue\nproperty float radius\nproperty float intensity\nend_header\n";
}
std::string binaryPly(bool be, bool floatColor = false, int declared = 3) {
    std::string s = plyHeader(be ? "binary_big_endian" : "binary_little_endian", declared, floatColor);
    for (int i = 0; i < 3; ++i) {
        for (int a = 0; a < 3; ++a) put(s, P[i][a], be);
        for (int a = 0; a < 3; ++a) put(s, Nn[i][a], be);
        for (int a = 0; a < 3; ++a) {
            if (floatColor)
                put(s, float(Col[i][a]) / 255.0f, be);
            else
                s.push_back(char(uint8_t(Col[i][a])));
        }
        put(s, 0.25f * float(i + 1), be);
        put(s, 100.0f * float(i), be);
    }
    return s;
}
std::string asciiPly() {
    std::string s = plyHeader("ascii", 3);
    for (int i = 0; i < 3; ++i) {
        for (int a = 0; a < 3; ++a) s += std::to_string(P[i][a]) + " ";
        for (int a = 0; a < 3; ++a) s += std::to_string(Nn[i][a]) + " ";
        for (int a = 0; a < 3; ++a) s += std::to_string(Col[i][a]) + " ";
        s += std::to_string(0.25f * float(i + 1)) + " " + std::to_string(100.0f * float(i)) + "\n";
    }
    return s;
}

void expectCloud(const PointCloud& c) {
    ASSERT_EQ(c.size(), 3u);
    ASSERT_EQ(c.normals.size(), 3u);
    ASSERT_EQ(c.colors.size(), 3u);
    ASSERT_EQ(c.radii.size(), 3u);
    ASSERT_EQ(c.intensities.size(), 3u);
    for (int i = 0; i < 3; ++i) {
        for (int a = 0; a < 3; ++a) {
            EXPECT_NEAR(c.positions[size_t(i)][a], P[i][a], 1e-6f);
            EXPECT_NEAR(c.normals[size_t(i)][a], Nn[i][a], 1e-6f);
            EXPECT_EQ(int(c.colors[size_t(i)][size_t(a)]), Col[i][a]);
        }
        EXPECT_FLOAT_EQ(c.radii[size_t(i)], 0.25f * float(i + 1));
        EXPECT_FLOAT_EQ(c.intensities[size_t(i)], 100.0f * float(i));
    }
}

template <class F>
void expectError(F&& f, const std::string& fragment) {
    try {
        f();
        ADD_FAILURE() << "no error thrown, expected one mentioning '" << fragment << "'";
    } catch (const Error& e) {
        EXPECT_NE(e.message().find(fragment), std::string::npos) << "message: " << e.message();
        EXPECT_FALSE(e.file().empty());
        EXPECT_EQ(e.message().find('\n'), std::string::npos) << "one line: " << e.message();
    }
}

}  // namespace

TEST(PlyLoader, BinaryLittleEndian) { expectCloud(loadPointCloud(writeFile("le.ply", binaryPly(false)))); }
TEST(PlyLoader, BinaryBigEndian) { expectCloud(loadPointCloud(writeFile("be.ply", binaryPly(true)))); }
TEST(PlyLoader, Ascii) { expectCloud(loadPointCloud(writeFile("ascii.ply", asciiPly()))); }
TEST(PlyLoader, FloatColours) { expectCloud(loadPointCloud(writeFile("fc.ply", binaryPly(false, true)))); }

TEST(PlyLoader, WriteReadRoundTrip) {
    PointCloud c = loadPly(writeFile("rt_in.ply", binaryPly(false)));
    const std::string out = (tmpDir() / "rt_out.ply").string();
    writePly(out, c);
    PointCloud d = loadPly(out);
    ASSERT_EQ(d.size(), 3u);
    for (size_t i = 0; i < 3; ++i) {
        EXPECT_EQ(d.positions[i], c.positions[i]);
        EXPECT_EQ(d.colors[i], c.colors[i]);
        EXPECT_EQ(d.radii[i], c.radii[i]);
    }
}

TEST(PlyLoader, SkipsElementsBeforeVertices) {
    std::string s =
        "ply\nformat binary_little_endian 1.0\nelement junk 2\nproperty list uchar int idx\nelement vertex 1\n"
        "property float x\nproperty float y\nproperty float z\nend_header\n";
    s.push_back(2), put(s, 1), put(s, 2);
    s.push_back(0);
    put(s, 1.0f), put(s, 2.0f), put(s, 3.0f);
    const PointCloud c = loadPly(writeFile("junk.ply", s));
    ASSERT_EQ(c.size(), 1u);
    EXPECT_EQ(c.positions[0], Vec3f(1, 2, 3));
}

TEST(PlyLoader, LargeCoordinatesAreShiftedInDouble) {
    std::string s =
        "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty double x\nproperty double y\nproperty double "
        "z\nend_header\n";
    put(s, 512050.25), put(s, 5403060.5), put(s, 300.0);
    put(s, 512051.75), put(s, 5403061.0), put(s, 301.0);
    const PointCloud c = loadPly(writeFile("utm.ply", s));
    EXPECT_EQ(c.origin[1], 5403061.0);  // first point, rounded
    EXPECT_FLOAT_EQ(c.positions[1].x - c.positions[0].x, 1.5f);
    EXPECT_FLOAT_EQ(c.positions[1].y - c.positions[0].y, 0.5f);
}

TEST(PlyLoader, NaNPointsAreDroppedAndCounted) {
    std::string s =
        "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float "
        "z\nend_header\n";
    put(s, 0.0f), put(s, 0.0f), put(s, 0.0f);
    put(s, std::nanf("")), put(s, 1.0f), put(s, 1.0f);
    put(s, 1.0f), put(s, 1.0f), put(s, 1.0f);
    const PointCloud c = loadPly(writeFile("nan.ply", s));
    EXPECT_EQ(c.size(), 2u);
    EXPECT_EQ(c.droppedNonFinite, 1u);
}

TEST(PlyLoader, HostileFiles) {
    const std::string good = binaryPly(false);
    expectError([&] { loadPly(writeFile("trunc.ply", good.substr(0, good.size() - 5))); }, "bytes follow the header");
    expectError([&] { loadPly(writeFile("lying.ply", binaryPly(false, false, 2000000000))); }, "2000000000 vertices");
    expectError([&] { loadPly(writeFile("neg.ply", binaryPly(false, false, -1))); }, "bad count");
    expectError([&] { loadPly(writeFile("empty.ply", plyHeader("binary_little_endian", 0))); }, "empty point cloud");
    expectError([&] { loadPly(writeFile("nohdr.ply", "ply\nformat ascii 1.0\nelement vertex 3\n")); }, "end_header");
    expectError([&] { loadPly(writeFile("magic.ply", "plx\n")); }, "not a PLY file");
    expectError([&] { loadPly(writeFile("zero.ply", "")); }, "not a PLY file");
    const std::string asc = asciiPly();
    expectError([&] { loadPly(writeFile("trunc_ascii.ply", asc.substr(0, asc.size() - 20))); }, "truncated");
    expectError([&] { loadPly(writeFile("bad_ascii.ply", plyHeader("ascii", 1) + "1 2 x 0 0 1 1 2 3 1 1\n")); },
                "bad number");
    std::string allNan =
        "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float "
        "z\nend_header\nnan 0 0\n0 nan 0\n";
    expectError([&] { loadPly(writeFile("allnan.ply", allNan)); }, "no point with finite coordinates");
    expectError(
        [&] {
            loadPly(
                writeFile("noxyz.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float a\nend_header\n1\n"));
        },
        "lack x");
    expectError(
        [&] {
            loadPly(
                writeFile("type.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n1\n"));
        },
        "unknown PLY property type");
    expectError([&] { loadPointCloud((tmpDir() / "missing.ply").string()); }, "no such file");
    // Infinite coordinates count as non-finite; a little-endian body declared big-endian
    // decodes to absurd but finite values, or NaNs: loads or fails cleanly, never crashes.
    std::string allInf =
        "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float "
        "z\nend_header\ninf 0 0\n0 -inf 0\n";
    expectError([&] { loadPly(writeFile("allinf.ply", allInf)); }, "no point with finite coordinates");
    std::string inf1 = allInf;
    inf1.replace(inf1.find("0 -inf 0"), 8, "0 1 0");
    EXPECT_EQ(loadPly(writeFile("oneinf.ply", inf1)).droppedNonFinite, 1u);
    expectError([&] { loadPointCloud(writeFile("x.foo", "1 2 3\n")); }, "unknown point cloud format");
}

TEST(PlyProbe, MeshesAreNotPointClouds) {
    const std::string mesh =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
        "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    const std::string f = writeFile("mesh.ply", mesh);
    EXPECT_FALSE(probePointFile(f).has_value());
    const auto info = probePointFile(writeFile("cloud.ply", binaryPly(false)));
    ASSERT_TRUE(info.has_value());
    EXPECT_EQ(info->points, 3u);
    EXPECT_EQ(info->properties.size(), 11u);
}

namespace {
std::string pcdHeader(const std::string& data, int points, const std::string& fields = "x y z intensity") {
    return "# .PCD v0.7\nVERSION 0.7\nFIELDS " + fields + "\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH " +
           std::to_string(points) + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + std::to_string(points) +
           "\nDATA " + data + "\n";
}
}  // namespace

TEST(PcdLoader, AsciiAndBinary) {
    std::string a = pcdHeader("ascii", 3) + "0 0 0 1\n1 2 3 2\nnan nan nan 3\n";
    const PointCloud c = loadPointCloud(writeFile("a.pcd", a));
    ASSERT_EQ(c.size(), 2u);
    EXPECT_EQ(c.droppedNonFinite, 1u);
    EXPECT_EQ(c.positions[1], Vec3f(1, 2, 3));
    ASSERT_EQ(c.intensities.size(), 2u);
    EXPECT_EQ(c.intensities[1], 2.0f);
    std::string b = pcdHeader("binary", 2);
    for (float v : {1.f, 2.f, 3.f, 4.f, 5.f, 6.f, 7.f, 8.f}) put(b, v);
    b += std::string(100, '\0');  // PCL pads binary files
    const PointCloud d = loadPointCloud(writeFile("b.pcd", b));
    ASSERT_EQ(d.size(), 2u);
    EXPECT_EQ(d.positions[1], Vec3f(5, 6, 7));
}

TEST(PcdLoader, PackedRgb) {
    std::string b =
        "VERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA "
        "binary\n";
    put(b, 1.f), put(b, 2.f), put(b, 3.f), put(b, uint32_t(0x00112233));
    const PointCloud c = loadPointCloud(writeFile("rgb.pcd", b));
    ASSERT_EQ(c.colors.size(), 1u);
    EXPECT_EQ(c.colors[0], (std::array<uint8_t, 3>{0x11, 0x22, 0x33}));
}

TEST(PcdLoader, HostileFiles) {
    std::string b = pcdHeader("binary", 1000000);
    for (float v : {1.f, 2.f, 3.f, 4.f}) put(b, v);
    expectError([&] { loadPcd(writeFile("lying.pcd", b)); }, "1000000 points");
    expectError([&] { loadPcd(writeFile("empty.pcd", pcdHeader("binary", 0))); }, "empty point cloud");
    std::string c = pcdHeader("binary_compressed", 10);
    put(c, uint32_t(5000)), put(c, uint32_t(160));
    c += std::string(20, 'x');
    expectError([&] { loadPcd(writeFile("trunc_c.pcd", c)); }, "runs past the end");
    std::string c2 = pcdHeader("binary_compressed", 10);
    put(c2, uint32_t(8)), put(c2, uint32_t(999));
    c2 += std::string(8, 'x');
    expectError([&] { loadPcd(writeFile("usize.pcd", c2)); }, "uncompressed size");
    std::string w = pcdHeader("ascii", 3);
    w.replace(w.find("WIDTH 3"), 7, "WIDTH 7");
    expectError([&] { loadPcd(writeFile("wh.pcd", w + "1 2 3 4\n")); }, "differs from POINTS");
    expectError([&] { loadPcd(writeFile("nodata.pcd", "VERSION 0.7\nFIELDS x y z\n")); }, "no DATA");
    expectError([&] { loadPcd(writeFile("asc_trunc.pcd", pcdHeader("ascii", 3) + "1 2 3 4\n1 2 3 4\n")); }, "PCD");
    expectError(
        [&] { loadPcd(writeFile("garbage.pcd", std::string("\x89PNG\r\n\x1a\n", 8) + std::string(64, '\x01'))); },
        "PCD");
    // Negative, zero and overflowing sizes; all-NaN and all-Inf bodies; a directory.
    expectError([&] { loadPcd(writeFile("negpoints.pcd", pcdHeader("ascii", -3) + "1 2 3 4\n")); }, "PCD");
    std::string zeroSize = pcdHeader("binary", 1);
    zeroSize.replace(zeroSize.find("SIZE 4 4 4 4"), 12, "SIZE 4 4 0 4");
    expectError([&] { loadPcd(writeFile("zerosize.pcd", zeroSize + std::string(16, '\0'))); }, "PCD");
    std::string hugeCount = pcdHeader("binary", 1);
    hugeCount.replace(hugeCount.find("COUNT 1 1 1 1"), 13, "COUNT 1 1 1 2000000000");
    expectError([&] { loadPcd(writeFile("hugecount.pcd", hugeCount + std::string(16, '\0'))); }, "PCD");
    // Found by fuzz_pcd: a COUNT that overflows int ended our stream read silently and PCL
    // then allocated 12 GB by its own reading of the number.
    std::string overflowCount = pcdHeader("binary", 1);
    overflowCount.replace(overflowCount.find("COUNT 1 1 1 1"), 13, "COUNT 19999999999999999999999 1 1 1");
    expectError([&] { loadPcd(writeFile("overflowcount.pcd", overflowCount + std::string(16, '\0'))); },
                "bad PCD COUNT");
    std::string wh = pcdHeader("binary", 1);
    wh.replace(wh.find("WIDTH 1\nHEIGHT 1"), 16, "WIDTH 4294967296\nHEIGHT 4294967296");
    expectError([&] { loadPcd(writeFile("overflow.pcd", wh + std::string(16, '\0'))); }, "PCD");
    expectError([&] { loadPcd(writeFile("allnan.pcd", pcdHeader("ascii", 2) + "nan 0 0 1\n0 nan 0 1\n")); },
                "no point with finite coordinates");
    expectError([&] { loadPcd(writeFile("allinf.pcd", pcdHeader("ascii", 2) + "inf 0 0 1\n0 -inf 0 1\n")); },
                "no point with finite coordinates");
    // Found by fuzz_pcd: a "\r" line ends PCL's header parse and PCL then crashed on the body.
    expectError([&] { loadPcd(writeFile("cr_line.pcd", "#c\r\n\r\n" + pcdHeader("ascii", 1) + "1 2 3 4\n")); },
                "blank line");
    expectError([&] { loadPcd(writeFile("short_row.pcd", pcdHeader("ascii", 2) + "10 20 30 40\n10 20 30\n")); },
                "point 2 has 3 values");
    // Odd header tokens that PCL's own parser mishandled (a use-after-free found by fuzz_pcd).
    std::string oddField = pcdHeader("ascii", 1, "x y z\xec\xec i");
    expectError([&] { loadPcd(writeFile("oddfield.pcd", oddField + "1 2 3 4\n")); }, "bad PCD field name");
    std::string oddView = pcdHeader("ascii", 1);
    oddView.replace(oddView.find("VIEWPOINT 0 0 0 1 0 0 0"), 23, "VIEWPOINT 0 0 0 1 0 0 \x10");
    expectError([&] { loadPcd(writeFile("oddview.pcd", oddView + "1 2 3 4\n")); }, "bad PCD VIEWPOINT");
    // Found by fuzz_pcd in our own decoder: a 2-byte float field was read as 4 bytes.
    std::string halfFloat = pcdHeader("binary", 1);
    halfFloat.replace(halfFloat.find("SIZE 4 4 4 4"), 12, "SIZE 4 4 4 2");
    expectError([&] { loadPcd(writeFile("halffloat.pcd", halfFloat + std::string(14, '\0'))); }, "float of 2 bytes");
    fs::create_directories(tmpDir() / "dir.pcd");
    expectError([&] { loadPointCloud((tmpDir() / "dir.pcd").string()); }, "dir.pcd");
}

TEST(PcdLoader, SharedKinectFrameDropsNaNs) {
    const fs::path f = fs::path(RTFACT_SHARED_DATA) / "points/pcl_office1_kinect.pcd";
    if (!fs::exists(f)) GTEST_SKIP() << "shared dataset not present: " << f;
    const PointCloud c = loadPointCloud(f.string());
    EXPECT_EQ(c.size(), 254456u);  // finite points, per the datasets' MANIFEST
    EXPECT_EQ(c.droppedNonFinite, 307200u - 254456u);
    EXPECT_EQ(c.colors.size(), c.size());
}

TEST(XyzLoader, ColumnsAndPts) {
    const PointCloud a = loadPointCloud(writeFile("a.xyz", "0 0 0\n1 2 3\n\n4 5 6\n"));
    EXPECT_EQ(a.size(), 3u);
    const PointCloud n = loadPointCloud(writeFile("n.xyz", "0 0 0 0 0 1\n1 2 3 0 1 0\n"));
    EXPECT_EQ(n.normals.size(), 2u);
    const PointCloud c = loadPointCloud(writeFile("c.xyz", "0 0 0 255 128 0\n1 2 3 0 1 200\n"));
    ASSERT_EQ(c.colors.size(), 2u);
    EXPECT_EQ(int(c.colors[0][1]), 128);
    const PointCloud p = loadPointCloud(writeFile("p.pts", "2\n0 0 0 10 255 0 0\n1 1 1 20 0 255 0\n"));
    EXPECT_EQ(p.size(), 2u);
    EXPECT_EQ(p.intensities[1], 20.0f);
    EXPECT_EQ(int(p.colors[1][1]), 255);
}

TEST(XyzLoader, HostileFiles) {
    expectError([&] { loadXyz(writeFile("bad.xyz", "0 0 0\n1 2 three\n")); }, "not a list of numbers");
    expectError([&] { loadXyz(writeFile("cols.xyz", "0 0 0\n1 2\n")); }, "expected 3");
    expectError([&] { loadXyz(writeFile("empty.xyz", "\n\n")); }, "empty point cloud");
    expectError([&] { loadXyz(writeFile("nan.xyz", "nan 0 0\n0 nan 0\n")); }, "no point with finite coordinates");
    expectError([&] { loadXyz(writeFile("lying.pts", "1000000000\n0 0 0\n")); }, "file is too small");
    expectError([&] { loadXyz(writeFile("short.pts", "3\n0.000000 0.000000 0.000000\n1.000000 1.000000 1.000000\n")); },
                "truncated");
    expectError([&] { loadXyz(writeFile("few.xyz", "1 2\n")); }, "fewer than 3");
    expectError([&] { loadXyz(writeFile("neg.pts", "-5\n0 0 0\n")); }, "neg.pts");
    expectError([&] { loadXyz(writeFile("zero.pts", "0\n")); }, "zero.pts");
    expectError([&] { loadXyz(writeFile("inf.xyz", "inf 0 0\n0 1e39 0\n")); }, "no point with finite coordinates");
    expectError([&] { loadXyz(writeFile("binary.xyz", std::string("\x7f\x45\x4c\x46\x02\x01\x01\x00\x00\xff", 10))); },
                "binary.xyz");
    expectError([&] { loadPointCloud((tmpDir() / "missing.xyz").string()); }, "missing.xyz");
    fs::create_directories(tmpDir() / "dir.xyz");
    expectError([&] { loadPointCloud((tmpDir() / "dir.xyz").string()); }, "dir.xyz");
}

// Every format drops points with a NaN, an inf or a coordinate beyond 1e18 and counts
// them (the CLI warns with droppedPointsMessage); a file with nothing else is an error.
TEST(NonFinitePoints, CountedInEveryFormatAndAllDroppedIsAnError) {
    // Five points: two finite, then NaN, inf and 1e30 in turn.
    const double v[5][3] = {{0, 0, 0}, {1, 2, 3}, {NAN, 1, 1}, {1, INFINITY, 1}, {1, 1, 1e30}};
    auto text = [&](int first, const std::string& sep) {
        std::string s;
        for (int i = first; i < 5; ++i) {
            for (int a = 0; a < 3; ++a) {
                const double x = v[i][a];
                s += (std::isnan(x)   ? std::string("nan")
                      : std::isinf(x) ? std::string("inf")
                                      : std::to_string(x)) +
                     (a < 2 ? " " : "");
            }
            s += sep + "\n";
        }
        return s;
    };
    auto plyBinary = [&](int first) {
        std::string s = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(5 - first) +
                        "\nproperty double x\nproperty double y\nproperty double z\nend_header\n";
        for (int i = first; i < 5; ++i)
            for (int a = 0; a < 3; ++a) put(s, v[i][a]);
        return s;
    };
    auto plyAscii = [&](int first) {
        return "ply\nformat ascii 1.0\nelement vertex " + std::to_string(5 - first) +
               "\nproperty double x\nproperty double y\nproperty double z\nend_header\n" + text(first, "");
    };
    auto pcdAscii = [&](int first) {
        return "VERSION 0.7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\nWIDTH " + std::to_string(5 - first) +
               "\nHEIGHT 1\nPOINTS " + std::to_string(5 - first) + "\nDATA ascii\n" + text(first, "");
    };
    auto pcdBinary = [&](int first) {
        std::string s = "VERSION 0.7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\nWIDTH " +
                        std::to_string(5 - first) + "\nHEIGHT 1\nPOINTS " + std::to_string(5 - first) +
                        "\nDATA binary\n";
        for (int i = first; i < 5; ++i)
            for (int a = 0; a < 3; ++a) put(s, v[i][a]);
        return s;
    };
    auto xyz = [&](int first) { return text(first, ""); };
    auto pts = [&](int first) { return std::to_string(5 - first) + "\n" + text(first, " 0 10 20 30"); };
    const std::vector<std::pair<std::string, std::function<std::string(int)>>> formats = {
        {"ply", plyBinary}, {"ply", plyAscii}, {"pcd", pcdAscii}, {"pcd", pcdBinary}, {"xyz", xyz}, {"pts", pts}};
    int k = 0;
    for (const auto& [ext, make] : formats) {
        SCOPED_TRACE(ext + " #" + std::to_string(k));
        const std::string f = writeFile("nonfinite" + std::to_string(k) + "." + ext, make(0));
        const PointCloud c = loadPointCloud(f);
        ASSERT_EQ(c.size(), 2u);
        EXPECT_EQ(c.positions[1], Vec3f(1, 2, 3));
        EXPECT_EQ(c.droppedNonFinite, 3u);
        EXPECT_EQ(droppedPointsMessage(f, c), f + ": 3 points with non-finite coordinates dropped");
        const std::string all = writeFile("allnonfinite" + std::to_string(k) + "." + ext, make(2));
        try {
            loadPointCloud(all);
            ADD_FAILURE() << all << ": loaded although every point is non-finite";
        } catch (const Error& e) {
            EXPECT_EQ(e.file(), all);
            EXPECT_NE(e.message().find("no point with finite coordinates"), std::string::npos) << e.message();
            EXPECT_EQ(e.message().find('\n'), std::string::npos);
        }
        ++k;
    }
}

TEST(NonFinitePoints, MessageIsOneLineAndOnlyWhenSomethingWasDropped) {
    PointCloud c;
    EXPECT_EQ(droppedPointsMessage("a.xyz", c), "");
    c.droppedNonFinite = 1;
    EXPECT_EQ(droppedPointsMessage("a.xyz", c), "a.xyz: 1 point with non-finite coordinates dropped");
}

// A named pipe blocks open() until a writer appears: every loader and probe must refuse
// it before opening. A loader that still blocks fails here (the pipe's write end is then
// opened to release it) instead of hanging the test run.
TEST(PointLoaders, NamedPipesAreRefusedWithoutHanging) {
    for (const std::string ext : {"xyz", "ply", "pcd", "pts"}) {
        const std::string fifo = (tmpDir() / ("pipe." + ext)).string();
        std::filesystem::remove(fifo);
        ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0) << fifo << ": " << std::strerror(errno);
        for (const bool probe : {false, true}) {
            auto result = std::async(std::launch::async, [&]() -> std::string {
                try {
                    if (probe)
                        probePointFile(fifo);
                    else
                        loadPointCloud(fifo);
                    return "no error";
                } catch (const Error& e) {
                    return e.message();
                }
            });
            if (result.wait_for(std::chrono::seconds(30)) != std::future_status::ready) {
                ADD_FAILURE() << fifo << (probe ? " (probe)" : "") << ": blocked opening the named pipe";
                const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
                if (fd >= 0) ::close(fd);
            }
            const std::string msg = result.get();
            EXPECT_EQ(msg, fifo + ": is a named pipe, not a regular file") << (probe ? "probe" : "load");
        }
        std::filesystem::remove(fifo);
    }
}

// The header search stops after 1 MiB: a longer header (here a 2 MiB comment) is refused
// naming that limit, not as a file without end_header.
TEST(PlyLoader, HeaderLimitIsNamed) {
    const std::string body =
        "element vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n";
    const std::string longComment = "ply\nformat ascii 1.0\ncomment " + std::string(2 << 20, 'c') + "\n" + body;
    expectError([&] { loadPly(writeFile("long_comment.ply", longComment)); },
                "PLY header longer than 1048576 bytes (the limit)");
    // end_header inside a comment does not end the header.
    const PointCloud c =
        loadPly(writeFile("comment_end.ply", "ply\nformat ascii 1.0\ncomment no end_header here\n" + body));
    ASSERT_EQ(c.size(), 1u);
    EXPECT_EQ(c.positions[0], Vec3f(1, 2, 3));
    // Without end_header in a short file: still the truncation message.
    expectError([&] { loadPly(writeFile("no_end.ply", "ply\nformat ascii 1.0\nelement vertex 1\n")); },
                "not terminated by end_header");
}
