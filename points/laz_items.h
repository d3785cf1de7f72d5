// LAZ item types (the "type" of a laszip VLR item) and the checks a layout must pass
// before a chunk is decoded with it.
#pragma once
#include <cstdint>
#include <string>

#include "points/laz_decoder.h"

namespace rtfact::points::laz {

enum ItemType : uint16_t {
    kByte = 0,           // extra bytes, point-wise
    kPoint10 = 6,        // LAS 1.0-1.3 core point (20 bytes)
    kGpsTime11 = 7,      // GPS time (8 bytes)
    kRgb12 = 8,          // RGB (6 bytes)
    kWavePacket13 = 9,   // wave packet (29 bytes)
    kPoint14 = 10,       // LAS 1.4 core point (30 bytes)
    kRgb14 = 11,         // RGB, layered
    kRgbNir14 = 12,      // RGB + NIR, layered (8 bytes)
    kWavePacket14 = 13,  // wave packet, layered
    kByte14 = 14,        // extra bytes, layered
};

// Throws Error(source, ...) unless every item is one this decoder implements, with its
// fixed size, in an order the compressor allows (the core point first).
void checkItems(const LazInfo& info, const std::string& source);

}  // namespace rtfact::points::laz
