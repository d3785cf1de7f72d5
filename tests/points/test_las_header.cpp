// The LAS header reader against the real files of ../shared (their layouts are listed in
// its MANIFEST) and against headers made to lie.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <vector>

#include "core/io/mapped_file.h"
#include "core/util/error.h"
#include "points/las_header.h"

using namespace rtfact;
using namespace rtfact::points;

namespace {

std::string shared(const std::string& name) { return std::string(RTFACT_SHARED_DATA) + "/points/las/" + name; }

std::span<const uint8_t> bytes(const io::MappedFile& m) {
    return {reinterpret_cast<const uint8_t*>(m.data()), m.size()};
}

// A valid LAS 1.2 header (format 0, 20-byte records) followed by `points` zero records.
std::vector<uint8_t> minimalLas(uint32_t points) {
    std::vector<uint8_t> f(227 + 20 * size_t(points), 0);
    std::memcpy(f.data(), "LASF", 4);
    f[24] = 1;
    f[25] = 2;
    auto put = [&](size_t pos, auto v) { std::memcpy(f.data() + pos, &v, sizeof v); };
    put(94, uint16_t(227));
    put(96, uint32_t(227));
    put(105, uint16_t(20));
    put(107, points);
    for (int a = 0; a < 3; ++a) put(131 + 8 * a, 0.01);
    return f;
}

std::string errorOf(const std::vector<uint8_t>& f) {
    try {
        las::readHeader(f, "t.las");
    } catch (const Error& e) {
        return e.message();
    }
    return "";
}

}  // namespace

TEST(LasHeader, SimpleLasIsLas12Format3) {
    if (!std::filesystem::exists(shared("simple.las"))) GTEST_SKIP() << "../shared/datasets is absent";
    io::MappedFile m(shared("simple.las"));
    const las::Header h = las::readHeader(bytes(m), m.name());
    EXPECT_EQ(h.versionMinor, 2);
    EXPECT_EQ(h.pointFormat, 3);
    EXPECT_FALSE(h.compressed);
    EXPECT_EQ(h.recordLength, 34);
    EXPECT_EQ(h.pointCount, 1065u);
    EXPECT_EQ(h.pointsByReturn[0], 925u);
    EXPECT_EQ(h.pointDataOffset, 227u);
    EXPECT_TRUE(h.vlrs.empty());
    EXPECT_NEAR(h.min[0], 635619.85, 1e-6);
    EXPECT_NEAR(h.max[2], 586.38, 1e-6);
}

TEST(LasHeader, Las14WithEvlrsAndLazFormatBits) {
    for (const char* name : {"1_4_w_evlr.las", "1_4_w_evlr.laz", "autzen_trim.laz", "simple_with_page.copc.laz"}) {
        if (!std::filesystem::exists(shared(name))) GTEST_SKIP() << "../shared/datasets is absent";
        io::MappedFile m(shared(name));
        const las::Header h = las::readHeader(bytes(m), m.name());
        const bool laz = std::string(name).ends_with(".laz");
        EXPECT_EQ(h.compressed, laz) << name;
        if (laz) {
            EXPECT_NE(las::findVlr(h, "laszip encoded", 22204), nullptr) << name;
        }
        EXPECT_GT(h.pointCount, 0u) << name;
        for (const las::Vlr& v : h.vlrs) EXPECT_LE(v.offset + v.size, m.size()) << name;
    }
    io::MappedFile copc(shared("simple_with_page.copc.laz"));
    const las::Header h = las::readHeader(bytes(copc), copc.name());
    EXPECT_EQ(h.pointFormat, 7);
    EXPECT_EQ(h.pointCount, 1065u);
    ASSERT_FALSE(h.vlrs.empty());
    EXPECT_EQ(h.vlrs.front().userId, "copc");
    EXPECT_NE(las::findVlr(h, "copc", 1000), nullptr);  // the hierarchy EVLR
}

TEST(LasHeader, LyingHeadersGiveOneLineErrors) {
    EXPECT_EQ(errorOf(minimalLas(3)), "");
    auto f = minimalLas(3);
    f[0] = 'X';
    EXPECT_NE(errorOf(f).find("LASF"), std::string::npos);
    f = minimalLas(3);
    f.resize(200);
    EXPECT_NE(errorOf(f).find("truncated"), std::string::npos);
    f = minimalLas(3);
    f[107] = 4;  // 4 points claimed, 3 present
    EXPECT_NE(errorOf(f).find("holds only 3"), std::string::npos);
    f = minimalLas(3);
    f[105] = 19;  // shorter than format 0's 20 bytes
    EXPECT_NE(errorOf(f).find("shorter than format 0"), std::string::npos);
    f = minimalLas(3);
    f[104] = 11;
    EXPECT_NE(errorOf(f).find("point data format 11"), std::string::npos);
    f = minimalLas(3);
    f[100] = 1;  // one VLR claimed, no room before the points
    EXPECT_NE(errorOf(f).find("VLR 1 of 1"), std::string::npos);
    f = minimalLas(3);
    f[96] = 0xFF;
    f[97] = 0xFF;  // point data beyond the end
    EXPECT_NE(errorOf(f).find("outside the file"), std::string::npos);
    f = minimalLas(3);
    std::memset(f.data() + 131, 0, 8);  // x scale 0
    EXPECT_NE(errorOf(f).find("scale factor"), std::string::npos);
    f = minimalLas(0);
    f[25] = 5;
    EXPECT_NE(errorOf(f).find("version 1.5"), std::string::npos);
}
