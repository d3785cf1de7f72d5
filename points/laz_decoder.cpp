// LAZ decompression driver: reads the chunk table, then decodes the chunks (independent by
// design: every chunk restarts its models) in parallel straight into the output records.
#include "points/laz_decoder.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <exception>
#include <mutex>

#include "core/util/error.h"
#include "points/laz_chunk_table.h"
#include "points/laz_items.h"
#include "points/laz_point10.h"
#include "points/laz_point14.h"

namespace rtfact::points::laz {

void decompress(const LazInfo& info, std::span<const uint8_t> file, uint64_t pointDataOffset, uint64_t pointCount,
                std::span<uint8_t> out, int threads, const std::string& source) {
    checkItems(info, source);
    const uint64_t recordLength = info.recordLength();
    if (recordLength == 0 || pointCount > out.size() / recordLength)
        throw Error(source, "LAZ: the output holds " + std::to_string(out.size()) + " bytes, not " +
                                std::to_string(pointCount) + " records of " + std::to_string(recordLength));
    const std::vector<Chunk> chunks = readChunkTable(info, file, pointDataOffset, pointCount, source);
    const auto decodeChunk = [&](size_t i) {
        const Chunk& c = chunks[i];
        const auto bytes = file.subspan(c.offset, c.bytes);
        uint8_t* dst = out.data() + c.firstPoint * recordLength;
        if (info.compressor == 3)
            decodeLayeredChunk(info, bytes, c.points, dst, source, i);
        else
            decodePointwiseChunk(info, bytes, c.points, dst, source, i);
    };
    // The first error (lowest chunk reported first would need ordering; any one line is
    // enough) is rethrown after the other chunks stop.
    std::exception_ptr error;
    std::mutex errorMutex;
    std::atomic<bool> failed{false};
    const auto body = [&](size_t i) {
        if (failed.load(std::memory_order_relaxed)) return;
        try {
            decodeChunk(i);
        } catch (...) {
            std::lock_guard lock(errorMutex);
            if (!error) error = std::current_exception();
            failed = true;
        }
    };
    if (threads == 1 || chunks.size() < 2) {
        for (size_t i = 0; i < chunks.size() && !failed; ++i) body(i);
    } else {
        tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
        arena.execute([&] { tbb::parallel_for(size_t(0), chunks.size(), body, tbb::simple_partitioner()); });
    }
    if (error) std::rethrow_exception(error);
}

}  // namespace rtfact::points::laz
