// LAZ: the decoder of LASzip-compressed point data, written from the published LAZ
// specification. It turns the compressed chunks of a .laz (or COPC) file back into the
// LAS point records the uncompressed twin holds, byte for byte; the LAS reader
// (points/las_io.cpp) then decodes those records as it does for .las files.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace rtfact::points::laz {

// One item of the point layout (POINT10, GPSTIME11, RGB12, BYTE, POINT14, RGB14,
// RGBNIR14, BYTE14, WAVEPACKET13/14 ...) with its size in bytes and coder version.
struct Item {
    uint16_t type = 0, size = 0, version = 0;
};

// The "laszip encoded" VLR (user id "laszip encoded", record id 22204).
struct LazInfo {
    uint16_t compressor = 0;  // 0 none, 1 pointwise, 2 pointwise chunked, 3 layered chunked
    uint16_t coder = 0;       // 0: arithmetic
    uint8_t versionMajor = 0, versionMinor = 0;
    uint16_t revision = 0;
    uint32_t options = 0;
    uint32_t chunkSize = 0;  // points per chunk; 0xFFFFFFFF: variable (counts in the chunk table)
    int64_t specialEvlrCount = -1, specialEvlrOffset = -1;
    std::vector<Item> items;

    // Sum of the items' sizes: the LAS record length the layout decodes to.
    uint32_t recordLength() const;
};

// Parses the VLR's payload; throws Error(source, ...) when it is malformed or names a
// compressor, coder or item this decoder does not know.
LazInfo parseLazVlr(std::span<const uint8_t> payload, const std::string& source);

// Decodes `pointCount` points stored from `pointDataOffset` of `file` (the whole file,
// mapped) into `out` (pointCount x info.recordLength() bytes), chunks in parallel on up
// to `threads` threads (0: all cores). Throws Error(source, ...) on a corrupt or
// truncated chunk table or chunk; never reads outside `file` or writes outside `out`.
void decompress(const LazInfo& info, std::span<const uint8_t> file, uint64_t pointDataOffset, uint64_t pointCount,
                std::span<uint8_t> out, int threads, const std::string& source);

}  // namespace rtfact::points::laz
