// The LAZ chunk table: where each compressed chunk starts, how many bytes it has and how
// many points it decodes to (fixed chunk size, or per-chunk counts for variable chunks,
// as COPC writes them).
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "points/laz_decoder.h"

namespace rtfact::points::laz {

struct Chunk {
    uint64_t offset = 0, bytes = 0;       // in the file
    uint64_t firstPoint = 0, points = 0;  // in the point records
};

// Reads and checks the table (chunks inside the file, between the point data and the
// table, counts adding up to `pointCount`); throws Error(source, ...) otherwise.
std::vector<Chunk> readChunkTable(const LazInfo& info, std::span<const uint8_t> file, uint64_t pointDataOffset,
                                  uint64_t pointCount, const std::string& source);

}  // namespace rtfact::points::laz
