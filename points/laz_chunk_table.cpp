// The chunk table sits after the last chunk; the 8 bytes at the start of the point data
// point to it (or, for a writer that could not seek back, are -1 and the pointer is the
// file's last 8 bytes). Its sizes and counts are compressed as differences from the
// previous chunk's with the integer decompressor.
#include "points/laz_chunk_table.h"

#include <algorithm>

#include "core/util/error.h"
#include "points/laz_arithmetic_decoder.h"

namespace rtfact::points::laz {

std::vector<Chunk> readChunkTable(const LazInfo& info, std::span<const uint8_t> file, uint64_t pointDataOffset,
                                  uint64_t pointCount, const std::string& source) {
    auto fail = [&](const std::string& what) { throw Error(source, "LAZ chunk table: " + what); };
    const uint64_t size = file.size();
    if (pointDataOffset > size || size - pointDataOffset < 8)
        fail("the point data offset " + std::to_string(pointDataOffset) + " leaves no room for the table pointer");
    const uint64_t firstChunk = pointDataOffset + 8;
    int64_t tableOffset = int64_t(loadU64(file.data() + pointDataOffset));
    if (tableOffset == -1) {  // streamed writer: the pointer is at the end of the file
        tableOffset = int64_t(loadU64(file.data() + size - 8));
    }
    if (tableOffset < int64_t(firstChunk) || uint64_t(tableOffset) > size || size - uint64_t(tableOffset) < 8)
        fail("offset " + std::to_string(tableOffset) + " is outside the file's point data [" +
             std::to_string(firstChunk) + ", " + std::to_string(size) + ")");
    const uint8_t* t = file.data() + tableOffset;
    const uint32_t version = loadU32(t), count = loadU32(t + 4);
    if (version != 0) fail("unknown version " + std::to_string(version));
    const bool variable = info.chunkSize == 0xFFFFFFFFu;
    if (!variable) {
        const uint64_t expected = (pointCount + info.chunkSize - 1) / info.chunkSize;
        if (count != expected)
            fail(std::to_string(count) + " chunks for " + std::to_string(pointCount) + " points in chunks of " +
                 std::to_string(info.chunkSize) + " (expected " + std::to_string(expected) + ")");
    }
    // Every chunk starts with a raw point: a count that cannot fit between the point data
    // and the table is a lie (checked before allocating).
    const uint64_t tableBytes = size - uint64_t(tableOffset) - 8;
    const uint64_t recordLength = info.recordLength();
    if (recordLength == 0 || count > (uint64_t(tableOffset) - firstChunk) / recordLength)
        fail(std::to_string(count) + " chunks do not fit in " + std::to_string(uint64_t(tableOffset) - firstChunk) +
             " bytes of point data");
    std::vector<Chunk> chunks(count);
    if (count == 0) {
        if (pointCount) fail("no chunks for " + std::to_string(pointCount) + " points");
        return chunks;
    }
    ArithmeticDecoder dec(std::span<const uint8_t>(t + 8, tableBytes));
    IntegerDecompressor ic(32, 2);
    uint32_t lastCount = 0, lastBytes = 0;
    uint64_t offset = firstChunk, point = 0;
    for (uint32_t i = 0; i < count; ++i) {
        Chunk& c = chunks[i];
        if (variable) {
            lastCount = uint32_t(ic.decompress(dec, int32_t(lastCount), 0));
            c.points = lastCount;
        } else {
            c.points = std::min<uint64_t>(info.chunkSize, pointCount - point);
        }
        lastBytes = uint32_t(ic.decompress(dec, int32_t(lastBytes), 1));
        c.bytes = lastBytes;
        c.offset = offset;
        c.firstPoint = point;
        if (c.bytes > uint64_t(tableOffset) - offset)
            fail("chunk " + std::to_string(i) + " (" + std::to_string(c.bytes) + " bytes at " + std::to_string(offset) +
                 ") runs past the table at " + std::to_string(tableOffset));
        if (c.points == 0 && pointCount) fail("chunk " + std::to_string(i) + " has no points");
        if (c.bytes < recordLength)
            fail("chunk " + std::to_string(i) + " has " + std::to_string(c.bytes) +
                 " bytes, less than its first (raw) point");
        offset += c.bytes;
        point += c.points;
        if (point > pointCount) fail("chunks hold more than the header's " + std::to_string(pointCount) + " points");
    }
    if (dec.overrun() > 4) fail("truncated (" + std::to_string(count) + " entries announced)");
    if (point != pointCount)
        fail("chunks hold " + std::to_string(point) + " points, the header says " + std::to_string(pointCount));
    return chunks;
}

}  // namespace rtfact::points::laz
