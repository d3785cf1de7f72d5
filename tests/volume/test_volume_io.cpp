// Loaders: formats round-trip, real data (skipped when ../shared/datasets is absent),
// and hostile inputs giving a one-line rtfact::Error instead of a crash or a huge
// allocation.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <thread>

#include "core/util/error.h"
#include "volume/dicom_modality.h"
#include "volume/transfer_function.h"
#include "volume/volume_generators.h"
#include "volume/volume_io.h"

using namespace rtfact;
using namespace rtfact::volume;
namespace fs = std::filesystem;

namespace {

std::string tmpDir() {
    const fs::path d = fs::path(RTFACT_TEST_OUT) / "volume-io";
    fs::create_directories(d);
    return d.string();
}
std::string writeFile(const std::string& name, const std::string& bytes) {
    const std::string p = tmpDir() + "/" + name;
    std::ofstream f(p, std::ios::binary);
    f.write(bytes.data(), std::streamsize(bytes.size()));
    return p;
}
std::string gzip(const std::string& raw) {
    uLongf n = compressBound(uLong(raw.size())) + 64;
    std::string out(n, '\0');
    // gzip wrapper via deflateInit2 (windowBits 15 + 16)
    z_stream z{};
    deflateInit2(&z, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY);
    z.next_in = (Bytef*)raw.data();
    z.avail_in = uInt(raw.size());
    z.next_out = (Bytef*)out.data();
    z.avail_out = uInt(out.size());
    deflate(&z, Z_FINISH);
    out.resize(z.total_out);
    deflateEnd(&z);
    return out;
}
// A minimal NIfTI-1 header for a u8/i16 volume.
std::string niftiHeader(int nx, int ny, int nz, int16_t datatype, int16_t bitpix, float slope = 1, float inter = 0) {
    std::string h(352, '\0');
    auto put = [&](int off, const void* v, size_t n) { std::memcpy(&h[size_t(off)], v, n); };
    const int32_t sz = 348;
    put(0, &sz, 4);
    const int16_t dim[8] = {3, int16_t(nx), int16_t(ny), int16_t(nz), 1, 1, 1, 1};
    put(40, dim, 16);
    put(70, &datatype, 2);
    put(72, &bitpix, 2);
    const float pix[8] = {1, 0.5f, 0.75f, 2.0f, 1, 1, 1, 1};
    put(76, pix, 32);
    const float vox = 352;
    put(108, &vox, 4);
    put(112, &slope, 4);
    put(116, &inter, 4);
    put(344, "n+1", 4);
    return h;
}
void expectError(const std::function<void()>& f, const std::string& needle) {
    try {
        f();
        ADD_FAILURE() << "no error (expected '" << needle << "')";
    } catch (const Error& e) {
        const std::string m = e.message();
        EXPECT_NE(m.find(needle), std::string::npos) << m;
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
}
VolumeLoadOptions quiet() {
    VolumeLoadOptions o;
    o.progress = false;
    return o;
}

}  // namespace

TEST(VolumeIO, RawAndMetaImageRoundTrip) {
    const VolumeGrid g = makeSheppLogan(24, Storage::U16);
    const std::string mhd = tmpDir() + "/phantom24.mhd";
    writeMetaImage(mhd, g);
    const VolumeGrid a = loadVolume(mhd, quiet());
    ASSERT_EQ(a.dims[0], 24);
    ASSERT_EQ(a.storage, Storage::U16);
    EXPECT_EQ(std::memcmp(a.bytes.data(), g.bytes.data(), g.voxelCount() * 2), 0);
    VolumeLoadOptions o = quiet();
    o.dims = std::array<int, 3>{24, 24, 24};
    o.type = "u16";
    o.spacing = Vec3f(1, 2, 3);
    const VolumeGrid b = loadVolume(tmpDir() + "/phantom24.raw", o);
    EXPECT_EQ(std::memcmp(b.bytes.data(), g.bytes.data(), g.voxelCount() * 2), 0);
    EXPECT_FLOAT_EQ(b.spacing.z, 3.0f);
    // Memory: compact storage, at most 1.5x the raw size.
    EXPECT_LE(double(b.memoryBytes()), 1.5 * double(g.voxelCount() * 2));
}

TEST(VolumeIO, RawBigEndianSignedAndHeaderSkip) {
    // 2x2x2 i16 big endian after 5 header bytes: values -3, -2, ..., 4
    std::string bytes = "HEAD!";
    for (int v = -3; v <= 4; ++v) {
        const uint16_t u = uint16_t(int16_t(v));
        bytes.push_back(char(u >> 8));
        bytes.push_back(char(u & 0xFF));
    }
    const std::string p = writeFile("be.raw", bytes);
    VolumeLoadOptions o = quiet();
    o.dims = std::array<int, 3>{2, 2, 2};
    o.type = "i16";
    o.endian = "big";
    o.headerSkip = 5;
    const VolumeGrid g = loadVolume(p, o);
    for (int n = 0; n < 8; ++n) EXPECT_FLOAT_EQ(g.value(size_t(n)), float(n - 3));
}

TEST(VolumeIO, NiftiGzipWithSlope) {
    std::string raw = niftiHeader(3, 2, 2, 4, 16, 2.0f, -10.0f);
    for (int i = 0; i < 12; ++i) {
        const int16_t v = int16_t(i * 100 - 500);
        raw.append(reinterpret_cast<const char*>(&v), 2);
    }
    const std::string p = writeFile("s.nii.gz", gzip(raw));
    const VolumeGrid g = loadVolume(p, quiet());
    EXPECT_EQ(g.dims[0], 3);
    EXPECT_FLOAT_EQ(g.spacing.y, 0.75f);
    for (int i = 0; i < 12; ++i) EXPECT_FLOAT_EQ(g.value(size_t(i)), 2.0f * float(i * 100 - 500) - 10.0f);
    // the same uncompressed
    const VolumeGrid u = loadVolume(writeFile("s.nii", raw), quiet());
    EXPECT_FLOAT_EQ(u.value(size_t(11)), g.value(size_t(11)));
}

TEST(VolumeIO, NrrdAttachedGzipAndDetachedSlices) {
    std::string data;
    for (int i = 0; i < 2 * 3 * 4; ++i) data.push_back(char(i));
    const std::string hdr = "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 3 4\nspacings: 1 1 2.5\nencoding: gzip\n\n";
    const VolumeGrid g = loadVolume(writeFile("a.nrrd", hdr + gzip(data)), quiet());
    EXPECT_EQ(g.dims[2], 4);
    EXPECT_FLOAT_EQ(g.spacing.z, 2.5f);
    EXPECT_FLOAT_EQ(g.value(size_t(23)), 23.0f);
    // detached per-slice files: data file: sl.%d 1 4 1
    for (int k = 0; k < 4; ++k) writeFile("sl." + std::to_string(k + 1), data.substr(size_t(k) * 6, 6));
    const VolumeGrid s = loadVolume(
        writeFile("d.nhdr",
                  "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 3 4\nencoding: raw\ndata file: sl.%d 1 4 1\n"),
        quiet());
    EXPECT_EQ(std::memcmp(s.bytes.data(), data.data(), 24), 0);
    // Zero-padded slice numbers, as printf's %03d would write them.
    for (int k = 0; k < 4; ++k)
        writeFile("pad" + std::string(k + 1 < 10 ? "00" : "0") + std::to_string(k + 1) + ".raw",
                  data.substr(size_t(k) * 6, 6));
    const VolumeGrid z = loadVolume(
        writeFile("p.nhdr",
                  "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 3 4\nencoding: raw\ndata file: pad%03d.raw 1 4 1\n"),
        quiet());
    EXPECT_EQ(std::memcmp(z.bytes.data(), data.data(), 24), 0);
}

TEST(VolumeIO, MalformedInputsGiveClearErrors) {
    VolumeLoadOptions o = quiet();
    o.dims = std::array<int, 3>{10, 10, 10};
    o.type = "u8";
    const std::string small = writeFile("small.raw", std::string(999, 'x'));
    expectError([&] { loadVolume(small, o); }, "raw size mismatch");
    expectError([] { parseDims("0,10,10"); }, "positive");
    expectError([] { parseDims("100000,100000,100000"); }, "too large");
    expectError([] { parseDims("10,10"); }, "X,Y,Z");
    // MetaImage: zero, overflowing and lying dims, bad type, missing data file
    const std::string raw = writeFile("m.raw", std::string(64, 'x'));
    auto mhd = [&](const std::string& body) {
        return writeFile("m.mhd", "NDims = 3\n" + body + "ElementDataFile = m.raw\n");
    };
    expectError([&] { loadVolume(mhd("DimSize = 0 4 4\nElementType = MET_UCHAR\n"), quiet()); }, "positive");
    expectError([&] { loadVolume(mhd("DimSize = 4000000000 4000000000 4\nElementType = MET_UCHAR\n"), quiet()); },
                "too large");
    expectError([&] { loadVolume(mhd("DimSize = 1000 1000 1000\nElementType = MET_UCHAR\n"), quiet()); },
                "size mismatch");
    expectError([&] { loadVolume(mhd("DimSize = 4 4 4\nElementType = MET_BOGUS\n"), quiet()); },
                "unsupported voxel type");
    expectError([&] { loadVolume(mhd("DimSize = 4 4 x\nElementType = MET_UCHAR\n"), quiet()); }, "DimSize");
    expectError([&] { loadVolume(writeFile("n.mhd", "NDims = 3\nDimSize = 4 4 4\n"), quiet()); }, "ElementDataFile");
    expectError([&] { loadVolume(mhd("DimSize = -4 4 4\nElementType = MET_UCHAR\n"), quiet()); }, "m.mhd");
    expectError(
        [&] { loadVolume(mhd("DimSize = 4 4 4\nElementSpacing = nan 1 1\nElementType = MET_UCHAR\n"), quiet()); },
        "ElementSpacing");
    expectError(
        [&] { loadVolume(mhd("DimSize = 4 4 4\nElementSpacing = 1 inf 1\nElementType = MET_UCHAR\n"), quiet()); },
        "ElementSpacing");
    expectError(
        [&] {
            loadVolume(writeFile("gone.mhd",
                                 "NDims = 3\nDimSize = 4 4 4\nElementType = MET_UCHAR\nElementDataFile = gone.raw\n"),
                       quiet());
        },
        "gone.raw");
    expectError([] { parseDims("-1,10,10"); }, "positive");
    {
        VolumeLoadOptions skip = o;
        skip.dims = std::array<int, 3>{2, 2, 2};
        skip.headerSkip = 5000;
        expectError([&] { loadVolume(small, skip); }, "small.raw");
    }
    // NRRD: bad magic, missing type, unsupported encoding, lying sizes, truncated gzip
    expectError([&] { loadVolume(writeFile("b1.nrrd", "NRRX0004\n"), quiet()); }, "NRRD000");
    expectError([&] { loadVolume(writeFile("b2.nrrd", "NRRD0004\nsizes: 2 2 2\nencoding: raw\n\n01234567"), quiet()); },
                "type");
    expectError(
        [&] {
            loadVolume(writeFile("b3.nrrd", "NRRD0004\ntype: uint8\nsizes: 2 2 2\nencoding: bzip2\n\n01234567"),
                       quiet());
        },
        "encoding");
    expectError(
        [&] {
            loadVolume(writeFile("b4.nrrd", "NRRD0004\ntype: uint8\nsizes: 1000 1000 1000\nencoding: raw\n\n0123"),
                       quiet());
        },
        "size mismatch");
    expectError(
        [&] {
            loadVolume(
                writeFile("b5.nrrd", "NRRD0004\ntype: uint8\nsizes: 1000 1000 1000\nencoding: gzip\n\n" + gzip("abc")),
                quiet());
        },
        "cannot hold");
    std::string data(4096, '\0');
    for (size_t i = 0; i < data.size(); ++i) data[i] = char(i * 7);
    const std::string gz = gzip(data);
    expectError(
        [&] {
            loadVolume(writeFile("b6.nrrd", "NRRD0004\ntype: uint8\nsizes: 16 16 16\nencoding: gzip\n\n" +
                                                gz.substr(0, gz.size() / 2)),
                       quiet());
        },
        "truncated");
    std::string corrupt = gz;
    for (size_t i = 20; i < 60 && i < corrupt.size(); ++i) corrupt[i] = char(0xFF);
    expectError(
        [&] {
            loadVolume(writeFile("b7.nrrd", "NRRD0004\ntype: uint8\nsizes: 16 16 16\nencoding: gzip\n\n" + corrupt),
                       quiet());
        },
        "");
    expectError(
        [&] {
            loadVolume(writeFile("b8.nrrd", "NRRD0004\ntype: uint8\nsizes: 0 2 2\nencoding: raw\n\n01234567"), quiet());
        },
        "b8.nrrd");
    expectError(
        [&] {
            loadVolume(writeFile("b9.nrrd",
                                 "NRRD0004\ntype: uint8\nsizes: 4000000000 4000000000 4000000000\nencoding: raw\n\n0"),
                       quiet());
        },
        "b9.nrrd");
    expectError(
        [&] {
            loadVolume(
                writeFile("b10.nhdr", "NRRD0004\ntype: uint8\nsizes: 2 2 2\nencoding: raw\ndata file: nowhere.raw\n"),
                quiet());
        },
        "nowhere.raw");
    // Found by fuzz_volume_headers: the slice pattern went to printf ("%s" crashed).
    expectError(
        [&] {
            loadVolume(
                writeFile("b12.nhdr", "NRRD0004\ntype: uint8\nsizes: 2 2 2\nencoding: raw\ndata file: sl.%s 1 2 1\n"),
                quiet());
        },
        "one %d expected");
    expectError(
        [&] {
            loadVolume(writeFile("b13.nhdr",
                                 "NRRD0004\ntype: uint8\nsizes: 2 2 2\nencoding: raw\ndata file: sl.%d.%d 1 2 1\n"),
                       quiet());
        },
        "one %d expected");
    expectError(
        [&] {
            loadVolume(writeFile("b14.nhdr",
                                 "NRRD0004\ntype: uint8\nsizes: 2 2 2\nencoding: raw\ndata file: sl.%d 1 1e300 1\n"),
                       quiet());
        },
        "data file max");
    expectError(
        [&] {
            loadVolume(
                writeFile("b11.nhdr", "NRRD0004\ntype: uint8\nsizes: 2 2 2\nencoding: raw\ndata file: gone.%d 1 2 1\n"),
                quiet());
        },
        "gone.");
    // NIfTI written on a big-endian machine (byte-swapped header) whose dims lie.
    {
        std::string be = niftiHeader(16, 16, 16, 2, 8);
        auto swap = [&](int off, int n) { std::reverse(be.begin() + off, be.begin() + off + n); };
        swap(0, 4);
        for (int i = 0; i < 8; ++i) swap(40 + 2 * i, 2);
        swap(70, 2), swap(72, 2);
        for (int i = 0; i < 8; ++i) swap(76 + 4 * i, 4);
        swap(108, 4), swap(112, 4), swap(116, 4);
        EXPECT_EQ(loadVolume(writeFile("be.nii", be + data), quiet()).dims[2], 16);  // swapped but honest: loads
        const int16_t big = 30000;
        std::memcpy(&be[42], &big, 2);  // x dim 0x3075 read swapped
        expectError([&] { loadVolume(writeFile("be_lying.nii", be + data), quiet()); }, "be_lying.nii");
    }
    // NIfTI: bad sizeof_hdr, 4D, truncated gzip
    expectError([&] { loadVolume(writeFile("x.nii", std::string(400, '\0')), quiet()); }, "NIfTI");
    std::string four = niftiHeader(2, 2, 2, 2, 8);
    const int16_t dim4[5] = {4, 2, 2, 2, 3};
    std::memcpy(&four[40], dim4, 10);
    expectError([&] { loadVolume(writeFile("4d.nii", four + std::string(24, 'x')), quiet()); }, "only 3D");
    const std::string nii = gzip(niftiHeader(16, 16, 16, 2, 8) + data);
    expectError([&] { loadVolume(writeFile("t.nii.gz", nii.substr(0, nii.size() - 40)), quiet()); }, "truncated");
    // Float voxels that are infinite or NaN read as 0 (documented), they never reach the renderer.
    {
        VolumeLoadOptions f = quiet();
        f.dims = std::array<int, 3>{2, 1, 1};
        f.type = "f32";
        const float v[2] = {std::numeric_limits<float>::infinity(), std::nanf("")};
        const VolumeGrid g = loadVolume(writeFile("inf.raw", std::string(reinterpret_cast<const char*>(v), 8)), f);
        EXPECT_EQ(g.value(size_t(0)), 0.0f);
        EXPECT_EQ(g.value(size_t(1)), 0.0f);
    }
    // OpenVDB: garbage and a truncated header
    expectError([&] { loadVolume(writeFile("g.vdb", std::string(1000, 'z')), quiet()); }, "OpenVDB");
    expectError([&] { loadVolume(writeFile("e.vdb", ""), quiet()); }, "OpenVDB");
    // VTI / DICOM
    expectError(
        [&] {
            loadVolume(
                writeFile("x.vti", "<VTKFile type=\"ImageData\"><ImageData WholeExtent=\"0 99999 0 99999 0 99999\""),
                quiet());
        },
        "");
    fs::create_directories(tmpDir() + "/emptydicom");
    expectError([&] { loadVolume(tmpDir() + "/emptydicom", quiet()); }, "DICOM");
    // A file with the DICM marker and garbage after it: VTK's complaints become one line.
    fs::create_directories(tmpDir() + "/junkdicom");
    writeFile("junkdicom/a.dcm", std::string(128, '\0') + "DICM" + std::string(600, '\x33'));
    expectError([&] { loadVolume(tmpDir() + "/junkdicom", quiet()); }, "junkdicom: ");
    expectError([&] { loadVolume(tmpDir() + "/does-not-exist.mhd", quiet()); }, "no such file");
}

TEST(VolumeIO, RealDatasets) {
    const std::string d = std::string(RTFACT_SHARED_DATA) + "/volumes";
    if (!fs::exists(d)) GTEST_SKIP() << "shared datasets not present at " << d;
    {
        // detached NRRD slices: quarter.1 .. quarter.93, int16, anisotropic
        const VolumeGrid g = loadVolume(d + "/headsq_ct_nrrd/quarter.nhdr", quiet());
        EXPECT_EQ(g.dims[0], 64);
        EXPECT_EQ(g.dims[2], 93);
        EXPECT_FLOAT_EQ(g.spacing.x, 3.2f);
        EXPECT_FLOAT_EQ(g.spacing.z, 1.5f);
        const VolumeSummary s = summarize(g);
        EXPECT_FLOAT_EQ(s.lo, 0.0f);
        EXPECT_FLOAT_EQ(s.hi, 3926.0f);
    }
    {
        // NIfTI with scl_slope 2.20863, anisotropic spacing, kept as u8
        const VolumeGrid g = loadVolume(d + "/avm_cta.nii.gz", quiet());
        EXPECT_EQ(g.storage, Storage::U8);
        EXPECT_NEAR(g.scale, 2.20863f, 1e-5f);
        EXPECT_NEAR(g.spacing.x, 0.5469f, 1e-4f);
    }
    {
        const VolumeGrid g = loadVolume(d + "/head_mr_small_mhd/HeadMRVolume.mhd", quiet());
        EXPECT_EQ(g.dims[1], 62);
        EXPECT_FLOAT_EQ(g.spacing.x, 4.0f);
    }
    {
        VolumeLoadOptions o = quiet();
        o.grid = "density";
        const VolumeGrid g = loadVolume(d + "/bonsai_ct_density.vdb", o);
        EXPECT_EQ(g.dims[0], 256);
        EXPECT_EQ(g.dims[2], 234);  // active bbox 0..233
        o.grid = "nope";
        expectError([&] { loadVolume(d + "/bonsai_ct_density.vdb", o); }, "no grid named");
        // truncated copy of a real VDB
        std::ifstream f(d + "/bonsai_ct_density.vdb", std::ios::binary);
        std::string head(200000, '\0');
        f.read(head.data(), std::streamsize(head.size()));
        expectError([&] { loadVolume(writeFile("trunc.vdb", head), quiet()); }, "OpenVDB");
    }
    {
        const VolumeGrid g = loadVolume(d + "/dicom_mr_t1_vs_seg_001", quiet());
        EXPECT_EQ(g.dims[0], 512);
        EXPECT_EQ(g.dims[2], 120);
        EXPECT_NEAR(g.spacing.x, 0.41015625f, 1e-6f);
        EXPECT_NEAR(g.spacing.z, 1.5f, 1e-4f);
        // The same series with a note next to it loads; with truncated slices it does not.
        const std::string dir = d + "/dicom_mr_t1_vs_seg_001";
        const std::string mixed = tmpDir() + "/dicom_mixed", cut = tmpDir() + "/dicom_truncated";
        fs::remove_all(mixed);
        fs::remove_all(cut);
        fs::create_directories(mixed);
        fs::create_directories(cut);
        for (const char* n : {"1-001.dcm", "1-002.dcm", "1-003.dcm"}) {
            fs::copy_file(dir + "/" + n, mixed + "/" + n);
            std::ifstream f(dir + "/" + n, std::ios::binary);
            std::string bytes(300000, '\0');
            f.read(bytes.data(), std::streamsize(bytes.size()));
            writeFile(std::string("dicom_truncated/") + n, bytes);
        }
        writeFile("dicom_mixed/readme.txt", "scanned on a Tuesday\n");
        EXPECT_EQ(loadVolume(mixed, quiet()).dims[2], 3);
        expectError([&] { loadVolume(cut, quiet()); }, "truncated DICOM slice");
    }
}

TEST(VolumeIO, ShippedToothNamesItsDims) {
    const std::string p = std::string(RTFACT_DATASETS) + "/volumes/tooth_103x94x161_uint8.raw";
    ASSERT_TRUE(fs::exists(p)) << "tracked dataset missing: " << p;  // tracked data is never optional
    const VolumeGrid g = loadVolume(p, quiet());
    EXPECT_EQ(g.dims[0], 103);
    EXPECT_EQ(g.dims[1], 94);
    EXPECT_EQ(g.dims[2], 161);
    EXPECT_TRUE(looksLikeVolume(p));
    EXPECT_FALSE(looksLikeVolume("mesh.ply"));
}

// A gzip stream is complete only with its end marker and its CRC-32/length trailer. Cut
// anywhere inside the deflate data or the 8-byte trailer, or with a wrong CRC or length,
// it must be rejected, even where every voxel the header asks for was already decoded.
TEST(VolumeIO, GzipStreamsMustEndWithAValidTrailer) {
    std::string data(4096, '\0');
    for (size_t i = 0; i < data.size(); ++i) data[i] = char((i * 7) ^ (i >> 5));
    const std::string nrrdHead = "NRRD0004\ntype: uint8\nsizes: 16 16 16\nencoding: gzip\n\n";
    const std::string niiRaw = niftiHeader(16, 16, 16, 2, 8) + data;
    struct Case {
        const char* ext;
        std::string head, gz;
    };
    const Case cases[] = {{".nrrd", nrrdHead, gzip(data)}, {".nii.gz", "", gzip(niiRaw)}};
    int n = 0;
    for (const Case& c : cases) {
        const std::string& gz = c.gz;
        ASSERT_GT(gz.size(), 40u);
        const VolumeGrid intact = loadVolume(writeFile("intact" + std::string(c.ext), c.head + gz), quiet());
        EXPECT_EQ(std::memcmp(intact.bytes.data(), data.data(), data.size()), 0) << c.ext;
        // inside the deflate data (10-byte gzip header first), then every cut of the trailer
        std::vector<size_t> cuts = {12, gz.size() / 2, gz.size() - 10, gz.size() - 9};
        for (size_t k = 1; k <= 8; ++k) cuts.push_back(gz.size() - k);
        for (size_t cut : cuts) {
            const std::string name = "cut" + std::to_string(n++) + c.ext;
            expectError([&] { loadVolume(writeFile(name, c.head + gz.substr(0, cut)), quiet()); },
                        name + ": truncated");
        }
        // wrong CRC (first trailer byte), wrong length (last)
        for (size_t at : {gz.size() - 8, gz.size() - 1}) {
            std::string bad = gz;
            bad[at] = char(bad[at] ^ 0x5A);
            const std::string name = "badtrailer" + std::to_string(n++) + c.ext;
            expectError([&] { loadVolume(writeFile(name, c.head + bad), quiet()); },
                        name + ": corrupt compressed data");
        }
        // Two members (as `cat a.gz b.gz` makes) and zero padding after the stream load;
        // other bytes after it do not.
        const size_t half = c.head.empty() ? 2000 : 2048;
        const std::string raw = c.head.empty() ? niiRaw : data;
        const std::string twoMembers = gzip(raw.substr(0, half)) + gzip(raw.substr(half));
        const VolumeGrid two = loadVolume(writeFile("two" + std::string(c.ext), c.head + twoMembers), quiet());
        EXPECT_EQ(std::memcmp(two.bytes.data(), data.data(), data.size()), 0) << c.ext;
        EXPECT_NO_THROW(
            loadVolume(writeFile("padded" + std::string(c.ext), c.head + gz + std::string(100, '\0')), quiet()));
        const std::string junk = "junk" + std::string(c.ext);
        expectError([&] { loadVolume(writeFile(junk, c.head + gz + std::string(4, '\0') + "junk"), quiet()); },
                    junk + ": ");
    }
    // MetaImage CompressedData is a zlib stream: its Adler-32 trailer is checked the same way.
    {
        uLongf len = compressBound(uLong(data.size()));
        std::string z(len, '\0');
        ASSERT_EQ(compress2(reinterpret_cast<Bytef*>(z.data()), &len, reinterpret_cast<const Bytef*>(data.data()),
                            uLong(data.size()), 6),
                  Z_OK);
        z.resize(len);
        const std::string head =
            "NDims = 3\nDimSize = 16 16 16\nElementType = MET_UCHAR\nCompressedData = True\nElementDataFile = LOCAL\n";
        const VolumeGrid ok = loadVolume(writeFile("z.mha", head + z), quiet());
        EXPECT_EQ(std::memcmp(ok.bytes.data(), data.data(), data.size()), 0);
        for (size_t k = 1; k <= 4; ++k)
            expectError([&] { loadVolume(writeFile("zcut.mha", head + z.substr(0, z.size() - k)), quiet()); },
                        "zcut.mha: truncated");
        std::string bad = z;
        bad.back() = char(bad.back() ^ 1);
        expectError([&] { loadVolume(writeFile("zbad.mha", head + bad), quiet()); },
                    "zbad.mha: corrupt compressed data");
    }
}

namespace {

// Runs f, which must reject the FIFO at `fifo` with a one-line rtfact::Error naming it,
// without opening it. Should f open it anyway (the bug: the open blocks until a writer
// comes), the watcher opens the write end, so the reader gets end of file instead of
// hanging the test, and records that it did.
void expectFifoRejected(const std::string& fifo, const std::function<void()>& f, const std::string& what) {
    std::atomic<bool> done{false}, opened{false};
    std::thread watcher([&] {
        while (!done) {
            const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);  // succeeds only while a reader has it open
            if (fd >= 0) {
                opened = true;
                ::close(fd);
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
    });
    try {
        f();
        ADD_FAILURE() << what << ": no error for the named pipe " << fifo;
    } catch (const Error& e) {
        EXPECT_EQ(e.file(), fifo) << what << ": " << e.message();
        EXPECT_NE(e.message().find("named pipe"), std::string::npos) << what << ": " << e.message();
        EXPECT_EQ(e.message().find('\n'), std::string::npos) << what << ": " << e.message();
    }
    done = true;
    watcher.join();
    EXPECT_FALSE(opened) << what << ": opened the named pipe";
}

std::string makeFifo(const std::string& name) {
    const std::string p = tmpDir() + "/" + name;
    fs::remove(p);
    EXPECT_EQ(::mkfifo(p.c_str(), 0600), 0) << p;
    return p;
}

}  // namespace

// A named pipe given as input would block a reader forever: every loader checks first.
TEST(VolumeIO, NamedPipesAreRejectedWithoutOpeningThem) {
    for (const char* ext : {".mhd", ".mha", ".nrrd", ".nhdr", ".nii", ".nii.gz", ".vti", ".vdb", "_8x8x8_uint8.raw"}) {
        const std::string p = makeFifo(std::string("pipe") + ext);
        expectFifoRejected(
            p, [&] { loadVolume(p, quiet()); }, std::string("loadVolume ") + ext);
        expectFifoRejected(
            p, [&] { loadBrickedVolume(p, quiet()); }, std::string("loadBrickedVolume ") + ext);
    }
    {
        const std::string p = makeFifo("pipe.bin");
        VolumeLoadOptions raw = quiet();
        raw.dims = std::array<int, 3>{2, 2, 2};
        raw.type = "u8";
        expectFifoRejected(
            p, [&] { loadVolume(p, raw); }, "raw with --dims");
    }
    // the format readers called directly
    const std::string vdb = makeFifo("direct.vdb"), vti = makeFifo("direct.vti");
    expectFifoRejected(
        vdb, [&] { loadVDB(vdb, quiet()); }, "loadVDB");
    expectFifoRejected(
        vdb, [&] { loadVDBBricked(vdb, quiet()); }, "loadVDBBricked");
    expectFifoRejected(
        vti, [&] { loadVTI(vti, quiet()); }, "loadVTI");
    // detached data files: MetaImage, NRRD (single file, slice pattern, LIST, line skip)
    const std::string data = makeFifo("pipedata.raw");
    expectFifoRejected(
        data,
        [&] {
            loadVolume(
                writeFile("det.mhd",
                          "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\nElementDataFile = pipedata.raw\n"),
                quiet());
        },
        "MetaImage data file");
    expectFifoRejected(
        data,
        [&] {
            loadVolume(
                writeFile("det.nhdr", "NRRD0004\ntype: uint8\nsizes: 2 2 2\nencoding: raw\ndata file: pipedata.raw\n"),
                quiet());
        },
        "NRRD data file");
    expectFifoRejected(
        data,
        [&] {
            loadVolume(writeFile("detgz.nhdr",
                                 "NRRD0004\ntype: uint8\nsizes: 2 2 2\nencoding: gzip\ndata file: pipedata.raw\n"),
                       quiet());
        },
        "NRRD gzip data file");
    expectFifoRejected(
        data,
        [&] {
            loadVolume(
                writeFile(
                    "detskip.nhdr",
                    "NRRD0004\ntype: uint8\nsizes: 2 2 2\nencoding: raw\nline skip: 1\ndata file: pipedata.raw\n"),
                quiet());
        },
        "NRRD data file with line skip");
    expectFifoRejected(
        data,
        [&] {
            loadVolume(writeFile("detlist.nhdr",
                                 "NRRD0004\ntype: uint8\nsizes: 2 2 2\nencoding: raw\ndata file: LIST\npipedata.raw\n"),
                       quiet());
        },
        "NRRD data file LIST");
    const std::string slice = makeFifo("pipeslice.2");
    writeFile("pipeslice.1", std::string(4, 'x'));
    expectFifoRejected(
        slice,
        [&] {
            loadVolume(writeFile("detpat.nhdr",
                                 "NRRD0004\ntype: uint8\nsizes: 2 2 2\nencoding: raw\ndata file: pipeslice.%d 1 2 1\n"),
                       quiet());
        },
        "NRRD slice pattern");
    // a DICOM directory holding a pipe: VTK's reader would open every file in it
    const std::string dir = tmpDir() + "/dicom_with_pipe";
    fs::remove_all(dir);
    fs::create_directories(dir);
    writeFile("dicom_with_pipe/a.dcm", std::string(128, '\0') + "DICM" + std::string(600, '\x33'));
    const std::string dpipe = dir + "/b.dcm";
    ASSERT_EQ(::mkfifo(dpipe.c_str(), 0600), 0);
    expectFifoRejected(
        dpipe, [&] { loadVolume(dir, quiet()); }, "DICOM directory");
    // --tf FILE.json and the DICOM modality reader
    const std::string tf = makeFifo("pipe_tf.json");
    expectFifoRejected(
        tf, [&] { loadTransferFunction(tf); }, "loadTransferFunction");
    expectFifoRejected(
        tf, [&] { resolveTransferFunction(tf); }, "resolveTransferFunction");
    expectFifoRejected(
        dpipe, [&] { readDicomModality(dpipe); }, "readDicomModality");
}
