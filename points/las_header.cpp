#include "points/las_header.h"

#include <cmath>
#include <cstring>

#include "core/io/scalar_type.h"
#include "core/util/error.h"

namespace rtfact::points::las {

namespace {

template <typename T>
T at(std::span<const uint8_t> f, uint64_t pos) {
    return io::loadScalar<T>(f.data() + pos, false);  // LAS is little-endian throughout
}

std::string text(std::span<const uint8_t> f, uint64_t pos, size_t n) {
    std::string s(reinterpret_cast<const char*>(f.data() + pos), n);
    s.resize(std::strlen(s.c_str()));
    while (!s.empty() && s.back() == ' ') s.pop_back();
    return s;
}

// Header sizes the versions define; a writer may append bytes after them.
uint16_t requiredHeaderSize(int minor) { return minor >= 4 ? 375 : minor == 3 ? 235 : 227; }

}  // namespace

uint16_t minimumRecordLength(int pointFormat) {
    static constexpr uint16_t sizes[] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
    return pointFormat >= 0 && pointFormat <= 10 ? sizes[pointFormat] : 0;
}

Header readHeader(std::span<const uint8_t> f, const std::string& source) {
    auto fail = [&](const std::string& what) { throw Error(source, what); };
    if (f.size() < 227 || std::memcmp(f.data(), "LASF", 4) != 0)
        fail(f.size() < 4 || std::memcmp(f.data(), "LASF", 4) != 0 ? "not a LAS file (no LASF signature)"
                                                                   : "LAS header truncated");
    Header h;
    h.fileSourceId = at<uint16_t>(f, 4);
    h.globalEncoding = at<uint16_t>(f, 6);
    h.versionMajor = f[24];
    h.versionMinor = f[25];
    if (h.versionMajor != 1 || h.versionMinor > 4)
        fail("unsupported LAS version " + std::to_string(h.versionMajor) + "." + std::to_string(h.versionMinor) +
             " (1.0 to 1.4 are read)");
    h.systemId = text(f, 26, 32);
    h.software = text(f, 58, 32);
    h.headerSize = at<uint16_t>(f, 94);
    h.pointDataOffset = at<uint32_t>(f, 96);
    const uint32_t vlrCount = at<uint32_t>(f, 100);
    const uint8_t formatByte = f[104];
    h.recordLength = at<uint16_t>(f, 105);
    const uint32_t legacyCount = at<uint32_t>(f, 107);
    for (int i = 0; i < 5; ++i) h.pointsByReturn[i] = at<uint32_t>(f, 111 + 4 * i);
    for (int a = 0; a < 3; ++a) {
        h.scale[a] = at<double>(f, 131 + 8 * a);
        h.offset[a] = at<double>(f, 155 + 8 * a);
        h.max[a] = at<double>(f, 179 + 16 * a);
        h.min[a] = at<double>(f, 187 + 16 * a);
    }

    const uint16_t required = requiredHeaderSize(h.versionMinor);
    if (h.headerSize < required)
        fail("LAS " + std::to_string(h.versionMinor) + " header size " + std::to_string(h.headerSize) +
             " is below the " + std::to_string(required) + " bytes the version defines");
    if (h.headerSize > f.size()) fail("LAS header size " + std::to_string(h.headerSize) + " exceeds the file");
    if (h.pointDataOffset < h.headerSize || h.pointDataOffset > f.size())
        fail("offset to point data " + std::to_string(h.pointDataOffset) + " lies outside the file (header " +
             std::to_string(h.headerSize) + " bytes, file " + std::to_string(f.size()) + ")");

    // Bit 7 marks LAZ (LASzip); some writers also set bit 6.
    h.compressed = (formatByte & 0xC0) != 0;
    h.pointFormat = formatByte & 0x3F;
    if (h.pointFormat > 10) fail("unknown point data format " + std::to_string(h.pointFormat));
    if (h.recordLength < minimumRecordLength(h.pointFormat))
        fail("point record length " + std::to_string(h.recordLength) + " is shorter than format " +
             std::to_string(h.pointFormat) + " needs (" + std::to_string(minimumRecordLength(h.pointFormat)) + ")");
    for (int a = 0; a < 3; ++a) {
        if (!std::isfinite(h.scale[a]) || h.scale[a] == 0.0)
            fail("scale factor of axis " + std::to_string(a) + " is 0 or not finite");
        if (!std::isfinite(h.offset[a])) fail("offset of axis " + std::to_string(a) + " is not finite");
    }

    uint64_t evlrStart = 0;
    uint32_t evlrCount = 0;
    h.pointCount = legacyCount;
    if (h.versionMinor >= 3) h.waveformOffset = at<uint64_t>(f, 227);
    if (h.versionMinor >= 4) {
        evlrStart = at<uint64_t>(f, 235);
        evlrCount = at<uint32_t>(f, 243);
        const uint64_t count64 = at<uint64_t>(f, 247);
        if (count64 != 0) h.pointCount = count64;
        if (legacyCount != 0 && count64 != 0 && legacyCount != count64)
            fail("legacy point count " + std::to_string(legacyCount) + " differs from the 64-bit count " +
                 std::to_string(count64));
        for (int i = 0; i < 15; ++i) h.pointsByReturn[i] = at<uint64_t>(f, 255 + 8 * i);
    }

    // VLRs: between the header and the point data.
    uint64_t pos = h.headerSize;
    for (uint32_t i = 0; i < vlrCount; ++i) {
        if (pos + 54 > h.pointDataOffset)
            fail("VLR " + std::to_string(i + 1) + " of " + std::to_string(vlrCount) +
                 " runs past the point data offset");
        Vlr v;
        v.userId = text(f, pos + 2, 16);
        v.recordId = at<uint16_t>(f, pos + 18);
        v.size = at<uint16_t>(f, pos + 20);
        v.description = text(f, pos + 22, 32);
        v.offset = pos + 54;
        if (v.offset + v.size > h.pointDataOffset)
            fail("VLR " + std::to_string(i + 1) + " ('" + v.userId + "' " + std::to_string(v.recordId) + ") of " +
                 std::to_string(v.size) + " bytes runs past the point data offset");
        pos = v.offset + v.size;
        h.vlrs.push_back(std::move(v));
    }

    // Uncompressed point data must fit before the EVLRs / end of file; the size of LAZ
    // data is only known from its chunk table.
    const uint64_t dataEnd = evlrStart != 0 && evlrCount != 0 ? evlrStart : f.size();
    if (!h.compressed) {
        const uint64_t room = dataEnd >= h.pointDataOffset ? dataEnd - h.pointDataOffset : 0;
        if (h.pointCount > room / h.recordLength)
            fail("header claims " + std::to_string(h.pointCount) + " points of " + std::to_string(h.recordLength) +
                 " bytes but the file holds only " + std::to_string(room / h.recordLength));
    }

    // EVLRs (LAS 1.4): after the point data, to the end of the file.
    if (evlrCount != 0) {
        if (evlrStart < h.pointDataOffset || evlrStart > f.size())
            fail("start of the EVLRs " + std::to_string(evlrStart) + " lies outside the file");
        pos = evlrStart;
        for (uint32_t i = 0; i < evlrCount; ++i) {
            if (pos + 60 > f.size())
                fail("EVLR " + std::to_string(i + 1) + " of " + std::to_string(evlrCount) +
                     " runs past the end of the file");
            Vlr v;
            v.extended = true;
            v.userId = text(f, pos + 2, 16);
            v.recordId = at<uint16_t>(f, pos + 18);
            v.size = at<uint64_t>(f, pos + 20);
            v.description = text(f, pos + 28, 32);
            v.offset = pos + 60;
            if (v.size > f.size() - v.offset)
                fail("EVLR " + std::to_string(i + 1) + " ('" + v.userId + "' " + std::to_string(v.recordId) +
                     ") runs past the end of the file");
            pos = v.offset + v.size;
            h.vlrs.push_back(std::move(v));
        }
    }
    return h;
}

const Vlr* findVlr(const Header& h, std::string_view userId, uint16_t recordId) {
    for (const Vlr& v : h.vlrs)
        if (v.userId == userId && v.recordId == recordId) return &v;
    return nullptr;
}

}  // namespace rtfact::points::las
