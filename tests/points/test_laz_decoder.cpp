// The LAZ decoder against the LAS twins of the same points (byte-identical records, as
// LASzip and laz-perf decode them: see ../shared's MANIFEST), COPC against its source as a
// multiset, every point of the other files inside their header bounds, and hostile
// files (corrupt chunk tables, truncated chunks, lying counts, unknown items).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <vector>

#include "core/io/mapped_file.h"
#include "core/util/error.h"
#include "points/las_header.h"
#include "points/laz_decoder.h"

using namespace rtfact;
using namespace rtfact::points;

namespace {

std::string shared(const std::string& name) { return std::string(RTFACT_SHARED_DATA) + "/points/las/" + name; }
std::string shipped(const std::string& name) { return std::string(RTFACT_POINTS_DATA) + "/" + name; }

std::span<const uint8_t> bytes(const io::MappedFile& m) {
    return {reinterpret_cast<const uint8_t*>(m.data()), m.size()};
}
std::span<const uint8_t> bytes(const std::vector<uint8_t>& v) { return {v.data(), v.size()}; }

#define REQUIRE_SHARED(name)                    \
    if (!std::filesystem::exists(shared(name))) \
    GTEST_SKIP() << shared(name)                \
                 << " is absent "               \
                    "(../shared not mounted)"

struct Decoded {
    las::Header header;
    laz::LazInfo info;
    std::vector<uint8_t> records;
};

Decoded decodeBytes(std::span<const uint8_t> file, const std::string& name, int threads = 0) {
    Decoded d;
    d.header = las::readHeader(file, name);
    const las::Vlr* vlr = las::findVlr(d.header, "laszip encoded", 22204);
    if (!vlr) throw Error(name, "no laszip VLR");
    d.info = laz::parseLazVlr(las::payload(file, *vlr), name);
    d.records.assign(d.header.pointCount * d.info.recordLength(), 0);
    laz::decompress(d.info, file, d.header.pointDataOffset, d.header.pointCount, d.records, threads, name);
    return d;
}
Decoded decodeFile(const std::string& path, int threads = 0) {
    io::MappedFile m(path);
    return decodeBytes(bytes(m), path, threads);
}

// The point records of an uncompressed LAS file.
std::vector<uint8_t> lasRecords(const std::string& path) {
    io::MappedFile m(path);
    const las::Header h = las::readHeader(bytes(m), path);
    const auto* p = reinterpret_cast<const uint8_t*>(m.data()) + h.pointDataOffset;
    return {p, p + h.pointCount * h.recordLength};
}

void expectSameRecords(const std::vector<uint8_t>& got, const std::vector<uint8_t>& want, size_t recordLength) {
    ASSERT_EQ(got.size(), want.size());
    for (size_t i = 0; i < got.size(); i += recordLength)
        ASSERT_EQ(0, std::memcmp(got.data() + i, want.data() + i, recordLength)) << "record " << i / recordLength;
}

// Every point's scaled coordinates inside the header bounds (with half a unit of slack);
// `attained`: the extremes are the header's (true for every file but lone-star.laz, whose
// bounds are rounded outward).
void expectInsideBounds(const Decoded& d, bool attained = false) {
    const uint32_t len = d.info.recordLength();
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (uint64_t i = 0; i < d.header.pointCount; ++i)
        for (int a = 0; a < 3; ++a) {
            int32_t raw;
            std::memcpy(&raw, d.records.data() + i * len + 4 * a, 4);
            const double v = raw * d.header.scale[a] + d.header.offset[a];
            const double slack = 0.5 * std::abs(d.header.scale[a]);
            ASSERT_GE(v, d.header.min[a] - slack) << "point " << i << " axis " << a;
            ASSERT_LE(v, d.header.max[a] + slack) << "point " << i << " axis " << a;
            lo[a] = std::min(lo[a], v);
            hi[a] = std::max(hi[a], v);
        }
    if (attained)
        for (int a = 0; a < 3; ++a) {
            EXPECT_NEAR(lo[a], d.header.min[a], std::abs(d.header.scale[a])) << "axis " << a;
            EXPECT_NEAR(hi[a], d.header.max[a], std::abs(d.header.scale[a])) << "axis " << a;
        }
}

// Points by return number as the header counts them (when its counts add up).
void expectReturnCounts(const Decoded& d) {
    uint64_t sum = 0;
    for (uint64_t c : d.header.pointsByReturn) sum += c;
    if (sum != d.header.pointCount) return;
    std::array<uint64_t, 16> counts{};
    const uint32_t len = d.info.recordLength();
    for (uint64_t i = 0; i < d.header.pointCount; ++i) {
        const uint8_t b = d.records[i * len + 14];
        ++counts[d.header.pointFormat >= 6 ? b & 15 : b & 7];
    }
    for (int r = 1; r <= 15; ++r) EXPECT_EQ(counts[r], d.header.pointsByReturn[r - 1]) << "return " << r;
}

std::string errorOf(const std::vector<uint8_t>& file) {
    try {
        decodeBytes(bytes(file), "hostile.laz");
    } catch (const Error& e) {
        return e.message();
    }
    return "";
}

std::vector<uint8_t> readAll(const std::string& path) {
    io::MappedFile m(path);
    return {m.data(), m.data() + m.size()};
}

}  // namespace

// Always runs: the shipped twins (laspy's simple.las/simple.laz).
TEST(LazDecoder, ShippedSimpleEqualsItsLasTwin) {
    const Decoded d = decodeFile(shipped("simple.laz"));
    EXPECT_EQ(d.info.compressor, 2);
    EXPECT_EQ(d.header.pointCount, 1065u);
    EXPECT_EQ(d.info.recordLength(), 34u);
    expectSameRecords(d.records, lasRecords(shipped("simple.las")), 34);
}

TEST(LazDecoder, OneThreadAndManyAgree) {
    REQUIRE_SHARED("lone-star.laz");
    const Decoded one = decodeFile(shared("lone-star.laz"), 1);
    const Decoded two = decodeFile(shared("lone-star.laz"), 2);
    EXPECT_EQ(one.records, two.records);
    expectInsideBounds(one);
}

TEST(LazDecoder, PointwiseTwinsAreByteIdentical) {
    REQUIRE_SHARED("autzen_trim.laz");
    for (const auto& [laz, las] : {std::pair{"autzen_trim.laz", "autzen_trim.las"}, {"extra.laz", "extrabytes.las"}}) {
        SCOPED_TRACE(laz);
        const Decoded d = decodeFile(shared(laz));
        expectSameRecords(d.records, lasRecords(shared(las)), d.info.recordLength());
    }
}

TEST(LazDecoder, LayeredTwinIsByteIdentical) {
    REQUIRE_SHARED("1_4_w_evlr.laz");
    const Decoded d = decodeFile(shared("1_4_w_evlr.laz"));
    EXPECT_EQ(d.info.compressor, 3);
    expectSameRecords(d.records, lasRecords(shared("1_4_w_evlr.las")), 30);
}

// The fields every point format shares, in a comparable form: XYZ in units of the scale
// (twins share scales, not offsets), intensity, return number and count, classification,
// user data, point source, GPS time bits (0 for formats 0 and 2), RGB (0 without).
using PointKey = std::array<int64_t, 11>;
std::vector<PointKey> pointKeys(const las::Header& h, const std::vector<uint8_t>& records, size_t recordLength) {
    auto get = [](const uint8_t* p, int n) {
        int64_t v = 0;
        std::memcpy(&v, p, n);
        return v;
    };
    const int f = h.pointFormat;
    const bool modern = f >= 6;
    const bool gps = f == 1 || f >= 3;
    const int rgbAt = f == 2 ? 20 : (f == 3 || f == 5) ? 28 : (f == 7 || f == 8 || f == 10) ? 30 : -1;
    std::vector<PointKey> keys;
    for (size_t i = 0; i < h.pointCount; ++i) {
        const uint8_t* p = records.data() + i * recordLength;
        PointKey k{};
        for (int c = 0; c < 3; ++c)
            k[c] = std::llround((int32_t(get(p + 4 * c, 4)) * h.scale[c] + h.offset[c]) / h.scale[c]);
        k[3] = get(p + 12, 2);
        k[4] = modern ? p[14] & 15 : p[14] & 7;
        k[5] = modern ? p[14] >> 4 : (p[14] >> 3) & 7;
        k[6] = modern ? p[16] : p[15] & 31;
        k[7] = p[17];
        k[8] = get(p + (modern ? 20 : 18), 2);
        k[9] = gps ? get(p + (modern ? 22 : 20), 8) : 0;
        k[10] = rgbAt >= 0 ? get(p + rgbAt, 6) : 0;
        keys.push_back(k);
    }
    std::sort(keys.begin(), keys.end());
    return keys;
}

// COPC: variable chunks (one per octree node), the same points as the source file in
// another order and another point format.
TEST(LazDecoder, CopcVariableChunksHoldTheSamePoints) {
    const std::string simple = shipped("simple.las");
    REQUIRE_SHARED("simple_with_page.copc.laz");
    const Decoded copc = decodeFile(shared("simple_with_page.copc.laz"));
    EXPECT_EQ(copc.info.chunkSize, 0xFFFFFFFFu);
    io::MappedFile lasFile(simple);
    const las::Header lh = las::readHeader(bytes(lasFile), simple);
    EXPECT_EQ(pointKeys(copc.header, copc.records, copc.info.recordLength()),
              pointKeys(lh, lasRecords(simple), lh.recordLength));

    const Decoded star = decodeFile(shared("lone-star.copc.laz"));
    const Decoded starLaz = decodeFile(shared("lone-star.laz"));
    EXPECT_EQ(star.header.pointCount, 518862u);
    EXPECT_EQ(pointKeys(star.header, star.records, star.info.recordLength()),
              pointKeys(starLaz.header, starLaz.records, starLaz.info.recordLength()));
}

TEST(LazDecoder, OtherFilesDecodeInsideTheirBounds) {
    REQUIRE_SHARED("Megaplot.laz");
    for (const char* name : {"Megaplot.laz", "Topography.laz", "lone-star.copc.laz", "extra.laz",
                             "las_with_several_extra_byte_bloc.laz", "autzen_trim.laz"}) {
        SCOPED_TRACE(name);
        const Decoded d = decodeFile(shared(name));
        EXPECT_GT(d.header.pointCount, 0u);
        expectInsideBounds(d, true);
        expectReturnCounts(d);
    }
}

// Full waveform (PDRF 10: POINT14, RGBNIR14, WAVEPACKET14): every point refers to
// descriptor 1 with 4,968-byte packets; returns of one pulse share a waveform, so the
// 10,750 points have 7,124 distinct offsets (one per first return), in order.
TEST(LazDecoder, WavePacketsDecode) {
    REQUIRE_SHARED("fullwave.laz");
    const Decoded d = decodeFile(shared("fullwave.laz"));
    ASSERT_EQ(d.header.pointCount, 10750u);
    ASSERT_EQ(d.info.recordLength(), 67u);
    expectInsideBounds(d, true);
    expectReturnCounts(d);
    std::vector<uint64_t> offsets;
    for (uint64_t i = 0; i < d.header.pointCount; ++i) {
        const uint8_t* w = d.records.data() + i * 67 + 38;
        ASSERT_EQ(w[0], 1) << "point " << i;
        uint32_t size;
        std::memcpy(&size, w + 9, 4);
        ASSERT_EQ(size, 4968u) << "point " << i;
        uint64_t offset;
        std::memcpy(&offset, w + 1, 8);
        offsets.push_back(offset);
    }
    std::sort(offsets.begin(), offsets.end());
    EXPECT_EQ(std::unique(offsets.begin(), offsets.end()) - offsets.begin(), 7124);
}

// Hostile files, made from the shipped simple.laz: a chunk table pointer, the table, the
// chunk bytes, the item list that lie, each a one-line error naming the file.
TEST(LazDecoder, HostileFilesGiveOneLineErrors) {
    const std::vector<uint8_t> good = readAll(shipped("simple.laz"));
    const las::Header h = las::readHeader(bytes(good), "simple.laz");
    const las::Vlr* vlr = las::findVlr(h, "laszip encoded", 22204);
    ASSERT_NE(vlr, nullptr);
    ASSERT_EQ(errorOf(good), "");
    auto expectError = [](const std::vector<uint8_t>& f, const std::string& part) {
        const std::string e = errorOf(f);
        EXPECT_NE(e.find("hostile.laz: "), std::string::npos) << e;
        EXPECT_NE(e.find(part), std::string::npos) << e;
        EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    };
    int64_t table;
    std::memcpy(&table, good.data() + h.pointDataOffset, 8);
    {  // table pointer past the end of the file
        auto f = good;
        const int64_t bad = int64_t(f.size()) + 100;
        std::memcpy(f.data() + h.pointDataOffset, &bad, 8);
        expectError(f, "chunk table: offset");
    }
    {  // table pointer into the header
        auto f = good;
        const int64_t bad = 10;
        std::memcpy(f.data() + h.pointDataOffset, &bad, 8);
        expectError(f, "chunk table");
    }
    {  // a table claiming a million chunks
        auto f = good;
        const uint32_t many = 1000000;
        std::memcpy(f.data() + table + 4, &many, 4);
        expectError(f, "chunks");
    }
    {  // chunk bytes cut short: the file ends in the middle of the chunk, table re-appended
        auto f = good;
        std::vector<uint8_t> tail(f.begin() + table, f.end());
        f.resize(size_t(table) - 6000);
        const int64_t newTable = int64_t(f.size());
        f.insert(f.end(), tail.begin(), tail.end());
        std::memcpy(f.data() + h.pointDataOffset, &newTable, 8);
        expectError(f, "chunk");
    }
    {  // garbage in the compressed chunk: decodes without crashing, or fails with an error
        auto f = good;
        for (size_t i = h.pointDataOffset + 8 + 40; i < size_t(table); i += 7) f[i] ^= 0x5A;
        const std::string e = errorOf(f);
        EXPECT_EQ(e.find('\n'), std::string::npos);
    }
    {  // unknown item type
        auto f = good;
        const uint16_t bad = 77;
        std::memcpy(f.data() + vlr->offset + 34 + 6, &bad, 2);
        expectError(f, "unknown item type 77");
    }
    {  // point-wise items out of their decoding order (RGB12 before GPSTIME11)
        auto f = good;
        std::swap_ranges(f.begin() + vlr->offset + 40, f.begin() + vlr->offset + 46, f.begin() + vlr->offset + 46);
        expectError(f, "GPSTIME11 v2 item after RGB12");
    }
    {  // unknown compressor
        auto f = good;
        const uint16_t bad = 9;
        std::memcpy(f.data() + vlr->offset, &bad, 2);
        expectError(f, "compressor 9");
    }
    {  // item size that disagrees with the type
        auto f = good;
        const uint16_t bad = 21;
        std::memcpy(f.data() + vlr->offset + 34 + 2, &bad, 2);
        expectError(f, "POINT10 v2 item has size 21");
    }
    // more points than the chunk table holds
    {
        auto d = decodeBytes(bytes(good), "simple.laz");
        std::vector<uint8_t> out(2000 * 34);
        try {
            laz::decompress(d.info, bytes(good), h.pointDataOffset, 2000, out, 1, "hostile.laz");
            ADD_FAILURE() << "a lying point count decoded";
        } catch (const Error& e) {
            EXPECT_NE(e.message().find("hostile.laz: LAZ chunk 0: truncated"), std::string::npos) << e.message();
        }
    }
}
