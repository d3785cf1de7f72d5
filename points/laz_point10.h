// Compressor 2 (point-wise chunked, LAS point formats 0-5): each chunk starts with its
// first point raw, then one arithmetic-coded stream in which every item of every point
// is predicted from the previous point (POINT10, GPSTIME11, RGB12, BYTE; version 2).
#pragma once
#include <cstdint>
#include <span>
#include <string>

#include "points/laz_decoder.h"

namespace rtfact::points::laz {

// Decodes `points` records of info.recordLength() bytes from `bytes` (one chunk) into
// `out`; throws Error(source, ...) naming `chunk` when the chunk is too short.
void decodePointwiseChunk(const LazInfo& info, std::span<const uint8_t> bytes, uint64_t points, uint8_t* out,
                          const std::string& source, uint64_t chunk);

}  // namespace rtfact::points::laz
