// libFuzzer harness: the LAZ decoder on a whole file in memory (LAS header and VLR walk,
// laszip VLR, chunk table, point-wise and layered chunks). The output is capped so that a
// lying point count costs the harness no more than the LAS reader's memory check would let
// through.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/util/error.h"
#include "points/las_header.h"
#include "points/laz_decoder.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace rtfact::points;
    const std::span<const uint8_t> file(data, size);
    try {
        const las::Header h = las::readHeader(file, "fuzz.laz");
        const las::Vlr* vlr = las::findVlr(h, "laszip encoded", 22204);
        if (!vlr) return 0;
        const laz::LazInfo info = laz::parseLazVlr(las::payload(file, *vlr), "fuzz.laz");
        const uint64_t bytes = h.pointCount * info.recordLength();
        if (h.pointCount > (uint64_t(1) << 22) || bytes > (uint64_t(1) << 26)) return 0;
        std::vector<uint8_t> out(bytes);
        laz::decompress(info, file, h.pointDataOffset, h.pointCount, out, 1, "fuzz.laz");
    } catch (const rtfact::Error&) {
    }
    return 0;
}
