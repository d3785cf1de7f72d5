// Reading a z-slab of a volume file (a data-parallel rank's part, docs/mpi.md): the
// payload pieces are trimmed to the slab's bytes before they are checked and read, so a
// rank seeks to its slab and reads only it; a compressed piece is decompressed up to the
// slab and the bytes before it are dropped as they stream by (never held). A file cut
// short fails only for the ranks whose slab it lacks.
#include <algorithm>
#include <string>
#include <vector>

#include "core/util/error.h"
#include "volume/volume_io_detail.h"

namespace rtfact::volume::detail {

void keepSlices(VolumeGrid& g, int sourceBytes, std::vector<Piece>& pieces, const std::string& header,
                std::array<int, 2> z) {
    if (z[0] < 0 || z[1] <= z[0] || z[1] > g.dims[2])
        throw Error(header, "slices [" + std::to_string(z[0]) + ", " + std::to_string(z[1]) +
                                ") are not inside the volume's " + std::to_string(g.dims[2]) + " slices");
    const uint64_t slice = uint64_t(g.dims[0]) * uint64_t(g.dims[1]) * uint64_t(sourceBytes);
    const uint64_t begin = uint64_t(z[0]) * slice, end = uint64_t(z[1]) * slice;  // in the concatenated payload
    std::vector<Piece> kept;
    uint64_t at = 0;  // where the piece starts in the payload
    for (Piece p : pieces) {
        const uint64_t lo = std::max(begin, at), hi = std::min(end, at + p.bytes);
        at += p.bytes;
        if (lo >= hi) continue;
        if (p.skipFromEnd)
            throw Error(header,
                        "data at the end of the file (byte skip -1) cannot be read by slices; use --distribute image");
        const uint64_t first = lo - (at - p.bytes);
        if (p.compressed) {
            p.skip += first;
        } else {
            p.offset += p.skip + first;
            p.skip = 0;
        }
        p.bytes = hi - lo;
        kept.push_back(p);
    }
    pieces = std::move(kept);
    g.dims[2] = z[1] - z[0];
}

}  // namespace rtfact::volume::detail
