// Compressor 3 (layered chunked, LAS point formats 6-10): each chunk holds its first
// point raw, the point count, the byte size of every layer, then the layers, each its own
// arithmetic-coded stream (XY and returns, Z, classification, flags, intensity, scan
// angle, user data, point source, GPS time, RGB, NIR, each extra byte). Predictions are
// kept per scanner channel (up to four contexts).
#pragma once
#include <cstdint>
#include <span>
#include <string>

#include "points/laz_decoder.h"

namespace rtfact::points::laz {

// Decodes `points` records of info.recordLength() bytes from `bytes` (one chunk) into
// `out`; throws Error(source, ...) naming `chunk` when its layers do not fit its bytes.
void decodeLayeredChunk(const LazInfo& info, std::span<const uint8_t> bytes, uint64_t points, uint8_t* out,
                        const std::string& source, uint64_t chunk);

}  // namespace rtfact::points::laz
