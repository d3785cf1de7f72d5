// Sort-last compositing over MPI collectives (docs/mpi.md): every rank holds a full-size
// image of its part of the data; direct-send (one MPI_Alltoallv round, each rank
// receives one band of rows from every rank, the same S (1 - 1/P) bytes per rank as
// binary swap, for any P) composites each band in visibility order, and MPI_Gatherv
// assembles the bands on rank 0.
//   Over: premultiplied RGBA, composited front to back in `order` (ranks, nearest first;
//         the same for every pixel because the parts are convex and disjoint).
//   Depth: RGBA plus depth per pixel (5 floats); the nearest depth wins (ties: lower rank).
#pragma once
#include <mpi.h>

#include <cstdint>
#include <vector>

namespace rtfact::distributed {

enum class CompositeOp { Over, Depth };

struct CompositeFigures {
    double exchangeMs = 0, blendMs = 0, gatherMs = 0;
    uint64_t bytesSent = 0, bytesReceived = 0;
};

// Floats per pixel of an operation's images.
inline int channels(CompositeOp op) { return op == CompositeOp::Over ? 4 : 5; }

// Collective over `comm`. `image`: width * height * channels(op) floats on every rank.
// Returns the composited image on rank 0 (same layout), empty elsewhere. `order` (Over
// only) lists every rank once, nearest first. Throws std::bad_alloc only.
std::vector<float> composite(MPI_Comm comm, const std::vector<float>& image, int width, int height, CompositeOp op,
                             const std::vector<int>& order, CompositeFigures* figures = nullptr);

// The same composite on one process, from every rank's image: the reference the tests
// and the benchmark check the MPI one against.
std::vector<float> compositeSerial(const std::vector<std::vector<float>>& images, CompositeOp op,
                                   const std::vector<int>& order);

}  // namespace rtfact::distributed
