// The "laszip encoded" VLR: compressor, coder, chunk size and the item list that says
// how each point record is split into separately compressed items.
#include <string>

#include "core/util/error.h"
#include "points/laz_arithmetic_decoder.h"
#include "points/laz_decoder.h"
#include "points/laz_items.h"

namespace rtfact::points::laz {

uint32_t LazInfo::recordLength() const {
    uint32_t n = 0;
    for (const Item& i : items) n += i.size;
    return n;
}

LazInfo parseLazVlr(std::span<const uint8_t> payload, const std::string& source) {
    auto fail = [&](const std::string& what) { throw Error(source, "LAZ: " + what); };
    if (payload.size() < 34)
        fail("laszip VLR is " + std::to_string(payload.size()) + " bytes, shorter than its 34-byte header");
    const uint8_t* p = payload.data();
    LazInfo info;
    info.compressor = loadU16(p);
    info.coder = loadU16(p + 2);
    info.versionMajor = p[4];
    info.versionMinor = p[5];
    info.revision = loadU16(p + 6);
    info.options = loadU32(p + 8);
    info.chunkSize = loadU32(p + 12);
    info.specialEvlrCount = int64_t(loadU64(p + 16));
    info.specialEvlrOffset = int64_t(loadU64(p + 24));
    const uint16_t count = loadU16(p + 32);
    if (payload.size() != 34 + 6 * size_t(count))
        fail("laszip VLR lists " + std::to_string(count) + " items in " + std::to_string(payload.size()) +
             " bytes (expected " + std::to_string(34 + 6 * size_t(count)) + ")");
    if (info.coder != 0) fail("unknown entropy coder " + std::to_string(info.coder) + " (only 0, arithmetic, exists)");
    if (info.compressor != 2 && info.compressor != 3)
        fail("compressor " + std::to_string(info.compressor) +
             (info.compressor == 1 ? " (LASzip 1.x point-wise, without a chunk table) is not supported"
                                   : " is not supported (2 point-wise chunked and 3 layered chunked are)"));
    if (info.chunkSize == 0) fail("chunk size 0");
    if (count == 0) fail("laszip VLR lists no items");
    for (uint16_t i = 0; i < count; ++i) {
        const uint8_t* q = p + 34 + 6 * size_t(i);
        info.items.push_back({loadU16(q), loadU16(q + 2), loadU16(q + 4)});
    }
    checkItems(info, source);
    return info;
}

}  // namespace rtfact::points::laz

namespace rtfact::points::laz {

namespace {
const char* itemName(uint16_t type) {
    switch (type) {
        case kByte:
            return "BYTE";
        case kPoint10:
            return "POINT10";
        case kGpsTime11:
            return "GPSTIME11";
        case kRgb12:
            return "RGB12";
        case kWavePacket13:
            return "WAVEPACKET13";
        case kPoint14:
            return "POINT14";
        case kRgb14:
            return "RGB14";
        case kRgbNir14:
            return "RGBNIR14";
        case kWavePacket14:
            return "WAVEPACKET14";
        case kByte14:
            return "BYTE14";
        default:
            return nullptr;
    }
}
}  // namespace

void checkItems(const LazInfo& info, const std::string& source) {
    auto fail = [&](const std::string& what) { throw Error(source, "LAZ: " + what); };
    const bool layered = info.compressor == 3;
    for (size_t i = 0; i < info.items.size(); ++i) {
        const Item& it = info.items[i];
        const char* name = itemName(it.type);
        if (!name) fail("unknown item type " + std::to_string(it.type) + " (item " + std::to_string(i) + ")");
        const std::string what = std::string(name) + " v" + std::to_string(it.version);
        uint16_t size = 0, version = layered ? 3 : 2;
        switch (it.type) {
            case kPoint10:
                size = 20;
                break;
            case kGpsTime11:
                size = 8;
                break;
            case kRgb12:
                size = 6;
                break;
            case kPoint14:
                size = 30;
                break;
            case kRgb14:
                size = 6;
                break;
            case kRgbNir14:
                size = 8;
                break;
            case kWavePacket14:
                size = 29;
                break;
            case kByte:
            case kByte14:
                size = it.size;
                break;
            default:
                fail(what + " items are not supported");
        }
        const bool layeredItem = it.type >= kPoint14;
        if (layeredItem != layered)
            fail(what + " item with compressor " + std::to_string(info.compressor) +
                 (layered ? " (layered: only POINT14, RGB14, RGBNIR14, WAVEPACKET14, BYTE14)"
                          : " (point-wise: only POINT10, GPSTIME11, RGB12, BYTE)"));
        if (it.version != version)
            fail(what + " is not supported (version " + std::to_string(version) + " is, with compressor " +
                 std::to_string(info.compressor) + ")");
        if (size == 0 || it.size != size)
            fail(what + " item has size " + std::to_string(it.size) + " (expected " +
                 (size ? std::to_string(size) : std::string("at least 1")) + ")");
        // Point-wise items share one stream: decoded in the order POINT10, GPSTIME11, RGB12,
        // BYTE. Layered items have a stream each, but at most one of every kind.
        for (size_t j = 0; j < i; ++j) {
            const uint16_t prev = info.items[j].type;
            const bool rgbTwice = (prev == kRgb14 || prev == kRgbNir14) && (it.type == kRgb14 || it.type == kRgbNir14);
            if ((prev == it.type && it.type != kByte) || rgbTwice) fail("a second " + what + " item");
            auto rank = [](uint16_t t) { return t == kByte ? 3 : t == kRgb12 ? 2 : t == kGpsTime11 ? 1 : 0; };
            if (!layered && rank(prev) > rank(it.type))
                fail(what + " item after " + itemName(prev) + " (point-wise order: POINT10, GPSTIME11, RGB12, BYTE)");
        }
        if ((i == 0) != (it.type == kPoint10 || it.type == kPoint14))
            fail(i == 0 ? what + " as first item (the core point, POINT10 or POINT14, must come first)"
                        : "a second core point item (" + what + ")");
    }
}

}  // namespace rtfact::points::laz
