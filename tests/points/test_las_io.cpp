// The LAS/LAZ reader: the shipped simple.las always; every real LAS of ../shared against
// the layouts its MANIFEST lists (skipped when absent); LAZ twins point by point against
// their LAS (skipped while the LAZ decoder is not built in); records of every format 0-10
// written here field by field; hostile files; the load filters.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include "core/util/error.h"
#include "points/las_io.h"
#include "points/point_cloud_io.h"

using namespace rtfact;
using namespace rtfact::points;

namespace {

std::string shared(const std::string& name) { return std::string(RTFACT_SHARED_DATA) + "/points/las/" + name; }
std::string shipped(const std::string& name) { return std::string(RTFACT_POINTS_DATA) + "/" + name; }

std::string writeTemp(const std::string& name, const std::vector<uint8_t>& bytes) {
    std::filesystem::create_directories(RTFACT_TEST_OUT);
    const std::string path = std::string(RTFACT_TEST_OUT) + "/" + name;
    std::ofstream(path, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    return path;
}

template <class T>
void put(std::vector<uint8_t>& f, size_t pos, T v) {
    std::memcpy(f.data() + pos, &v, sizeof v);
}

// A LAS file of `records` (each recordLength bytes) behind a 1.2 (formats 0-5) or 1.4
// header, with the VLRs given as (user id, record id, payload).
struct Vlr {
    std::string user;
    uint16_t id;
    std::vector<uint8_t> data;
};
std::vector<uint8_t> makeLas(int format, uint16_t recordLength, const std::vector<std::vector<uint8_t>>& records,
                             const std::vector<Vlr>& vlrs = {}) {
    const bool v14 = format > 5;
    const uint16_t headerSize = v14 ? 375 : 227;
    std::vector<uint8_t> f(headerSize, 0);
    std::memcpy(f.data(), "LASF", 4);
    f[24] = 1;
    f[25] = v14 ? 4 : 2;
    put(f, 94, headerSize);
    put(f, 100, uint32_t(vlrs.size()));
    f[104] = uint8_t(format);
    put(f, 105, recordLength);
    if (v14)
        put(f, 247, uint64_t(records.size()));
    else
        put(f, 107, uint32_t(records.size()));
    for (int a = 0; a < 3; ++a) put(f, 131 + 8 * a, 0.01);
    put(f, 155, 1000.0);  // x offset
    for (const Vlr& v : vlrs) {
        std::vector<uint8_t> h(54, 0);
        std::memcpy(h.data() + 2, v.user.data(), std::min<size_t>(16, v.user.size()));
        put(h, 18, v.id);
        put(h, 20, uint16_t(v.data.size()));
        f.insert(f.end(), h.begin(), h.end());
        f.insert(f.end(), v.data.begin(), v.data.end());
    }
    put(f, 96, uint32_t(f.size()));
    for (const auto& r : records) {
        std::vector<uint8_t> rec(recordLength, 0);
        std::memcpy(rec.data(), r.data(), std::min(r.size(), rec.size()));
        f.insert(f.end(), rec.begin(), rec.end());
    }
    return f;
}

std::string errorOf(const std::string& file) {
    try {
        loadLas(file);
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

const ScalarField& scalarOf(const PointCloud& c, const std::string& name) {
    const ScalarField* s = c.scalar(name);
    if (!s) throw std::runtime_error("no scalar " + name);
    return *s;
}

// Bounds of the cloud in the file's coordinates.
void expectBounds(const PointCloud& c, std::array<double, 3> lo, std::array<double, 3> hi, double tol) {
    const AABB b = c.bounds();
    for (int a = 0; a < 3; ++a) {
        EXPECT_NEAR(double(b.lo[a]) + c.origin[a], lo[a], tol) << "axis " << a;
        EXPECT_NEAR(double(b.hi[a]) + c.origin[a], hi[a], tol) << "axis " << a;
    }
}

}  // namespace

TEST(LasIo, ShippedSimpleLas) {
    const PointCloud c = loadPointCloud(shipped("simple.las"));
    ASSERT_EQ(c.size(), 1065u);
    EXPECT_EQ(c.format, "las 1.2 format 3");
    expectBounds(c, {635619.85, 848899.70, 406.59}, {638982.55, 853535.43, 586.38}, 0.02);
    EXPECT_NE(c.origin[0], 0.0);  // georeferenced: shifted in double
    ASSERT_EQ(c.returnNumbers.size(), 1065u);
    int byReturn[8] = {};
    for (uint8_t r : c.returnNumbers) ++byReturn[r & 7];
    EXPECT_EQ(byReturn[1], 925);
    EXPECT_EQ(byReturn[2], 114);
    EXPECT_EQ(byReturn[3], 21);
    EXPECT_EQ(byReturn[4], 5);
    EXPECT_EQ(c.colors.size(), 1065u);
    EXPECT_EQ(c.intensities.size(), 1065u);
    EXPECT_GT(*std::max_element(c.intensities.begin(), c.intensities.end()), 0.0f);
    EXPECT_TRUE(c.scalar("gps_time"));
    EXPECT_TRUE(c.scalar("point_source_id"));
    EXPECT_TRUE(c.crs.empty());  // no VLRs
    // Ground (2) and unclassified (1) points, as ASPRS codes.
    EXPECT_TRUE(std::count(c.classes.begin(), c.classes.end(), 2) > 0);
    const las::Summary s = las::summarize(shipped("simple.las"));
    EXPECT_EQ(s.byReturn.at(1), 925u);
    uint64_t total = 0;
    for (auto [k, v] : s.byClass) total += v;
    EXPECT_EQ(total, 1065u);
}

TEST(LasIo, RealLasFilesOfTheManifest) {
    struct Case {
        const char* name;
        size_t count;
        std::array<double, 3> lo, hi;
        const char* format;
    };
    const Case cases[] = {
        {"autzen_trim.las", 110000, {636001.76, 848935.20, 406.26}, {637179.22, 849497.90, 520.51}, "las 1.2 format 3"},
        {"autzen_trim_7.las",
         110000,
         {636001.76, 848935.20, 406.26},
         {637179.22, 849497.90, 520.51},
         "las 1.4 format 7"},
        {"extrabytes.las", 1065, {635619.85, 848899.70, 406.59}, {638982.55, 853535.43, 586.38}, "las 1.4 format 3"},
        {"1_4_w_evlr.las",
         1000,
         {1694038.45, 1816492.71, 5592.75},
         {1694539.68, 1816497.98, 5599.07},
         "las 1.4 format 6"},
        {"epsg_4326.las", 5380, {-94.68347, 31.03673, 39.08}, {-94.66063, 31.04733, 78.12}, "las 1.2 format 0"},
        {"vegetation_1_3.las",
         10683,
         {-98451.21, -55975.42, -81460.09},
         {-98447.45, -55969.41, -81455.20},
         "las 1.3 format 1"},
    };
    for (const Case& k : cases) {
        if (!std::filesystem::exists(shared(k.name))) GTEST_SKIP() << "../shared/datasets is absent";
        SCOPED_TRACE(k.name);
        const PointCloud c = loadLas(shared(k.name));
        EXPECT_EQ(c.size(), k.count);
        EXPECT_EQ(c.format, k.format);
        expectBounds(c, k.lo, k.hi, 0.011);
    }
    // The same points as 1.2 format 3 and 1.4 format 7: every attribute equal, record by record.
    const PointCloud a = loadLas(shared("autzen_trim.las")), b = loadLas(shared("autzen_trim_7.las"));
    ASSERT_EQ(a.size(), b.size());
    EXPECT_EQ(a.origin, b.origin);
    EXPECT_EQ(a.classes, b.classes);
    EXPECT_EQ(a.returnNumbers, b.returnNumbers);
    EXPECT_EQ(a.returnCounts, b.returnCounts);
    EXPECT_EQ(a.intensities, b.intensities);
    EXPECT_EQ(a.colors, b.colors);
    EXPECT_EQ(scalarOf(a, "gps_time").values, scalarOf(b, "gps_time").values);
    EXPECT_EQ(scalarOf(a, "point_source_id").values, scalarOf(b, "point_source_id").values);
    for (size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a.positions[i], b.positions[i]) << i;
    EXPECT_NE(a.crs.find("PROJCS"), std::string::npos);  // the WKT VLR
    const las::Summary s = las::summarize(shared("autzen_trim.las"));
    EXPECT_EQ(s.byReturn.at(1), 99257u);
    EXPECT_EQ(s.byReturn.at(4), 99u);
    // 1.4 with legacy count 0 and an EVLR after the points.
    const las::Summary e = las::summarize(shared("1_4_w_evlr.las"));
    EXPECT_EQ(e.header.pointCount, 1000u);
    EXPECT_EQ(e.byReturn.at(2), 23u);
}

TEST(LasIo, ExtraBytesAreNamedScalars) {
    if (!std::filesystem::exists(shared("extrabytes.las"))) GTEST_SKIP() << "../shared/datasets is absent";
    const PointCloud c = loadLas(shared("extrabytes.las"));
    for (const char* n : {"Colors[0]", "Colors[1]", "Colors[2]", "Flags[0]", "Flags[1]", "Intensity", "Time"})
        EXPECT_TRUE(c.scalar(n)) << n;
    EXPECT_FALSE(c.scalar("Reserved"));  // undocumented bytes take room but are no attribute
    // The same points as simple.las in the same order.
    const PointCloud s = loadLas(shipped("simple.las"));
    ASSERT_EQ(c.size(), s.size());
    EXPECT_EQ(c.classes, s.classes);
    EXPECT_EQ(c.intensities, s.intensities);
}

// The shipped twins (datasets/points): always runs.
TEST(LasIo, ShippedLazEqualsItsLasTwin) {
    const PointCloud a = loadLas(shipped("simple.laz")), b = loadLas(shipped("simple.las"));
    ASSERT_EQ(a.size(), 1065u);
    ASSERT_EQ(a.size(), b.size());
    EXPECT_EQ(a.positions, b.positions);
    EXPECT_EQ(a.colors, b.colors);
    EXPECT_EQ(a.classes, b.classes);
    EXPECT_EQ(a.intensities, b.intensities);
}

TEST(LasIo, LazTwinsEqualTheirLasPointByPoint) {
    const std::pair<const char*, const char*> twins[] = {{"simple.laz", "simple.las"},
                                                         {"autzen_trim.laz", "autzen_trim.las"},
                                                         {"extra.laz", "extrabytes.las"},
                                                         {"1_4_w_evlr.laz", "1_4_w_evlr.las"}};
    for (auto [laz, las] : twins) {
        if (!std::filesystem::exists(shared(laz))) GTEST_SKIP() << "../shared/datasets is absent";
        SCOPED_TRACE(laz);
        const PointCloud a = loadLas(shared(laz)), b = loadLas(shared(las));
        ASSERT_EQ(a.size(), b.size());
        EXPECT_EQ(a.positions, b.positions);
        EXPECT_EQ(a.colors, b.colors);
        EXPECT_EQ(a.classes, b.classes);
        EXPECT_EQ(a.intensities, b.intensities);
        ASSERT_EQ(a.scalars.size(), b.scalars.size());
        for (size_t k = 0; k < a.scalars.size(); ++k) EXPECT_EQ(a.scalars[k].values, b.scalars[k].values);
    }
}

TEST(LasIo, LazFilesOfTheManifest) {
    struct Case {
        const char* name;
        size_t count;
    };
    const Case cases[] = {{"lone-star.laz", 518862},
                          {"lone-star.copc.laz", 518862},
                          {"Megaplot.laz", 81590},
                          {"Topography.laz", 73403},
                          {"fullwave.laz", 10750},
                          {"las_with_several_extra_byte_bloc.laz", 697721},
                          {"simple_with_page.copc.laz", 1065}};
    for (const Case& k : cases) {
        if (!std::filesystem::exists(shared(k.name))) GTEST_SKIP() << "../shared/datasets is absent";
        SCOPED_TRACE(k.name);
        const PointCloud c = loadLas(shared(k.name));
        EXPECT_EQ(c.size(), k.count);
    }
    if (!std::filesystem::exists(shared("las_with_several_extra_byte_bloc.laz"))) return;
    const PointCloud c = loadLas(shared("las_with_several_extra_byte_bloc.laz"));
    EXPECT_TRUE(c.scalar("Deviation"));
    EXPECT_TRUE(c.scalar("confidence"));
    EXPECT_TRUE(c.scalar("nir"));
}

// One record of each format with known values: every field lands where the format puts it.
TEST(LasIo, EveryFormatDecodesEveryField) {
    for (int format = 0; format <= 10; ++format) {
        SCOPED_TRACE(format);
        const uint16_t len = las::minimumRecordLength(format);
        std::vector<uint8_t> r(len, 0);
        put(r, 0, int32_t(150));   // x = 1.5 + offset 1000
        put(r, 4, int32_t(-250));  // y = -2.5
        put(r, 8, int32_t(1234));  // z = 12.34
        put(r, 12, uint16_t(777));
        const bool legacy = format <= 5;
        if (legacy) {
            r[14] = uint8_t(2 | (3 << 3));  // return 2 of 3
            r[15] = 6;                      // building
            r[16] = uint8_t(int8_t(-12));   // scan angle rank
            r[17] = 42;
            put(r, 18, uint16_t(9));
        } else {
            r[14] = uint8_t(7 | (9 << 4));  // return 7 of 9 (only 1.4 has more than 5)
            r[16] = 64;                     // an extended class
            r[17] = 42;
            put(r, 18, int16_t(1000));  // 6 degrees
            put(r, 20, uint16_t(9));
        }
        const int gps = legacy ? (format == 1 || format >= 3 ? 20 : -1) : 22;
        if (gps >= 0) put(r, size_t(gps), 1.0e6 + 0.25);
        const int rgb = format == 2                                  ? 20
                        : format == 3 || format == 5                 ? 28
                        : format == 7 || format == 8 || format == 10 ? 30
                                                                     : -1;
        if (rgb >= 0) {
            put(r, size_t(rgb), uint16_t(0xFF00));
            put(r, size_t(rgb) + 2, uint16_t(0x8000));
            put(r, size_t(rgb) + 4, uint16_t(0x1000));
        }
        if (format == 8 || format == 10) put(r, 36, uint16_t(5555));
        const std::string file = writeTemp("format" + std::to_string(format) + ".las", makeLas(format, len, {r, r}));
        const PointCloud c = loadLas(file);
        ASSERT_EQ(c.size(), 2u);
        EXPECT_NEAR(double(c.positions[0].x) + c.origin[0], 1001.5, 1e-9);
        EXPECT_NEAR(double(c.positions[0].y) + c.origin[1], -2.5, 1e-6);
        EXPECT_NEAR(double(c.positions[0].z) + c.origin[2], 12.34, 1e-6);
        EXPECT_EQ(c.intensities[0], 777.0f);
        EXPECT_EQ(c.returnNumbers[0], legacy ? 2 : 7);
        EXPECT_EQ(c.returnCounts[0], legacy ? 3 : 9);
        EXPECT_EQ(c.classes[0], legacy ? 6 : 64);
        EXPECT_EQ(scalarOf(c, "user_data").values[0], 42.0f);
        EXPECT_EQ(scalarOf(c, "point_source_id").values[0], 9.0f);
        EXPECT_NEAR(scalarOf(c, "scan_angle").values[0], legacy ? -12.0f : 6.0f, 1e-5);
        if (gps >= 0) {
            const ScalarField& g = scalarOf(c, "gps_time");
            EXPECT_EQ(g.offset + double(g.values[0]), 1.0e6 + 0.25);
        } else {
            EXPECT_FALSE(c.scalar("gps_time"));
        }
        if (rgb >= 0) {
            ASSERT_EQ(c.colors.size(), 2u);
            EXPECT_EQ(c.colors[0], (std::array<uint8_t, 3>{0xFF, 0x80, 0x10}));  // 16-bit colours, high bytes
        } else {
            EXPECT_TRUE(c.colors.empty());
        }
        EXPECT_EQ(c.scalar("nir") != nullptr, format == 8 || format == 10);
        if (format == 8 || format == 10) {
            EXPECT_EQ(scalarOf(c, "nir").values[0], 5555.0f);
        }
    }
}

TEST(LasIo, EightBitColoursAndExtraBytesWithScale) {
    // Format 2 with 8-bit colours stored unscaled, 3 extra bytes: a scaled u16 and an i8.
    std::vector<uint8_t> desc(2 * 192, 0);
    desc[2] = 3;  // u16
    desc[3] = 8;  // scale given
    std::memcpy(desc.data() + 4, "Deviation", 9);
    put(desc, 112, 0.5);
    desc[192 + 2] = 2;  // i8
    std::memcpy(desc.data() + 192 + 4, "conf", 4);
    std::vector<uint8_t> r(29, 0);
    put(r, 20, uint16_t(200));
    put(r, 22, uint16_t(100));
    put(r, 24, uint16_t(50));
    put(r, 26, uint16_t(10));  // Deviation 10 * 0.5
    r[28] = uint8_t(int8_t(-3));
    const std::string file = writeTemp("extra8.las", makeLas(2, 29, {r}, {{"LASF_Spec", 4, desc}}));
    const PointCloud c = loadLas(file);
    EXPECT_EQ(c.colors.at(0), (std::array<uint8_t, 3>{200, 100, 50}));
    EXPECT_EQ(scalarOf(c, "Deviation").values[0], 5.0f);
    EXPECT_EQ(scalarOf(c, "conf").values[0], -3.0f);
}

TEST(LasIo, HostileFilesGiveOneLineErrors) {
    std::vector<uint8_t> r(20, 0);
    const auto good = makeLas(0, 20, {r, r, r});
    EXPECT_EQ(errorOf(writeTemp("good.las", good)), "");
    auto expectError = [](const std::string& name, std::vector<uint8_t> f, const std::string& what) {
        const std::string e = errorOf(writeTemp(name, f));
        EXPECT_NE(e.find(what), std::string::npos) << name << ": " << e;
        EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    };
    auto f = good;
    put(f, 107, uint32_t(1000000));  // lying count
    expectError("count.las", f, "claims 1000000 points");
    f = good;
    put(f, 96, uint32_t(1u << 30));  // offset beyond the file
    expectError("offset.las", f, "outside the file");
    f = good;
    put(f, 105, uint16_t(12));  // record shorter than format 0
    expectError("short.las", f, "shorter than format 0");
    f = good;
    f[104] = 13;  // no such format
    expectError("format.las", f, "unknown point data format 13");
    f = good;
    f[104] = 0x80;  // compressed bit without the LASzip VLR
    expectError("lazbit.las", f, "laszip encoded");
    f = good;
    put(f, 131, 1e300);  // coordinates beyond any float
    expectError("scale.las", f, "beyond 1e18");
    f = good;
    put(f, 107, uint32_t(0));
    expectError("empty.las", f, "no points");
    // A VLR whose length runs past the point data.
    f = makeLas(0, 20, {r}, {{"x", 1, std::vector<uint8_t>(8)}});
    put(f, 227 + 20, uint16_t(60000));
    expectError("vlr.las", f, "runs past");
    // Extra bytes described beyond the record.
    std::vector<uint8_t> desc(192, 0);
    desc[2] = 10;  // f64: 8 bytes, the record has 2 extra
    expectError("extra.las", makeLas(0, 22, {std::vector<uint8_t>(22)}, {{"LASF_Spec", 4, desc}}), "Extra Bytes");
    desc.resize(100);
    expectError("extra2.las", makeLas(0, 22, {std::vector<uint8_t>(22)}, {{"LASF_Spec", 4, desc}}), "192-byte");
}

TEST(LasIo, LoadFilters) {
    const PointCloud all = loadLas(shipped("simple.las"));
    LoadFilter ground;
    ground.classes = {2};
    const PointCloud g = loadPointCloud(shipped("simple.las"), ground);
    EXPECT_EQ(g.size(), size_t(std::count(all.classes.begin(), all.classes.end(), 2)));
    EXPECT_TRUE(std::all_of(g.classes.begin(), g.classes.end(), [](uint8_t k) { return k == 2; }));
    EXPECT_EQ(g.colors.size(), g.size());
    LoadFilter first;
    first.returns = LoadFilter::Returns::First;
    EXPECT_EQ(loadLas(shipped("simple.las"), first).size(), 925u);
    LoadFilter last;
    last.returns = LoadFilter::Returns::Last;
    const PointCloud l = loadLas(shipped("simple.las"), last);
    for (size_t i = 0; i < l.size(); ++i) EXPECT_EQ(l.returnNumbers[i], l.returnCounts[i]);
    LoadFilter crop;
    crop.crop = std::array<double, 4>{636000, 849000, 637000, 850000};
    const PointCloud cr = loadLas(shipped("simple.las"), crop);
    ASSERT_GT(cr.size(), 0u);
    ASSERT_LT(cr.size(), all.size());
    expectBounds(cr, {636000, 849000, 0}, {637000, 850000, 0}, 1e9);  // origin kept
    for (const Vec3f& p : cr.positions) {
        EXPECT_GE(double(p.x) + cr.origin[0], 636000 - 1e-3);
        EXPECT_LE(double(p.y) + cr.origin[1], 850000 + 1e-3);
    }
    LoadFilter none;
    none.classes = {31};
    EXPECT_THROW(loadLas(shipped("simple.las"), none), Error);
}
