#include "distributed/sort_last_compositor.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <cstddef>

namespace rtfact::distributed {

namespace {

double msSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// dst = dst over-or-nearest src for `pixels` pixels; for Over, dst is in front. Pixels
// are independent: blocks of them on all cores (the same floats as one thread).
void blend(float* dst, const float* src, size_t pixels, CompositeOp op) {
    const size_t ch = size_t(channels(op));
    tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels, 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
        float* d = dst + r.begin() * ch;
        const float* s = src + r.begin() * ch;
        if (op == CompositeOp::Over) {
            for (size_t i = r.begin(); i < r.end(); ++i, d += 4, s += 4) {
                const float t = 1.0f - d[3];
                for (int c = 0; c < 4; ++c) d[c] += t * s[c];
            }
        } else {
            for (size_t i = r.begin(); i < r.end(); ++i, d += 5, s += 5)
                if (s[4] < d[4])
                    for (int c = 0; c < 5; ++c) d[c] = s[c];
        }
    });
}

// The rows of band b of `bands` (balanced).
int bandStart(int height, int b, int bands) { return int(int64_t(height) * b / bands); }

}  // namespace

std::vector<float> composite(MPI_Comm comm, const std::vector<float>& image, int width, int height, CompositeOp op,
                             const std::vector<int>& order, CompositeFigures* figures) {
    int rank = 0, size = 1;
    MPI_Comm_rank(comm, &rank);
    MPI_Comm_size(comm, &size);
    const int ch = channels(op);
    const int rowFloats = width * ch;
    // Band b (rows [bandStart(b), bandStart(b+1))) is composited by rank b.
    const size_t ranks = size_t(size);
    std::vector<int> sendCounts(ranks), sendOffsets(ranks), recvCounts(ranks), recvOffsets(ranks);
    const int myRows = bandStart(height, rank + 1, size) - bandStart(height, rank, size);
    for (int b = 0; b < size; ++b) {
        sendOffsets[size_t(b)] = bandStart(height, b, size) * rowFloats;
        sendCounts[size_t(b)] = (bandStart(height, b + 1, size) - bandStart(height, b, size)) * rowFloats;
        recvCounts[size_t(b)] = myRows * rowFloats;
        recvOffsets[size_t(b)] = b * myRows * rowFloats;
    }
    CompositeFigures f;
    auto t0 = std::chrono::steady_clock::now();
    std::vector<float> pieces(size_t(size) * size_t(myRows) * size_t(rowFloats));
    MPI_Alltoallv(image.data(), sendCounts.data(), sendOffsets.data(), MPI_FLOAT, pieces.data(), recvCounts.data(),
                  recvOffsets.data(), MPI_FLOAT, comm);
    f.exchangeMs = msSince(t0);
    for (int b = 0; b < size; ++b)
        if (b != rank) {
            f.bytesSent += uint64_t(sendCounts[size_t(b)]) * sizeof(float);
            f.bytesReceived += uint64_t(recvCounts[size_t(b)]) * sizeof(float);
        }

    // Front to back (Over) or in rank order (Depth).
    t0 = std::chrono::steady_clock::now();
    const size_t bandFloats = size_t(myRows) * size_t(rowFloats);
    const int first = op == CompositeOp::Over ? order[0] : 0;
    std::vector<float> band(pieces.begin() + std::ptrdiff_t(size_t(first) * bandFloats),
                            pieces.begin() + std::ptrdiff_t(size_t(first + 1) * bandFloats));
    for (int i = 1; i < size; ++i) {
        const int r = op == CompositeOp::Over ? order[size_t(i)] : i;
        blend(band.data(), pieces.data() + size_t(r) * bandFloats, size_t(myRows) * size_t(width), op);
    }
    pieces = {};
    f.blendMs = msSince(t0);

    t0 = std::chrono::steady_clock::now();
    std::vector<float> out(rank == 0 ? size_t(width) * size_t(height) * size_t(ch) : 0);
    std::vector<int> counts(ranks), offsets(ranks);
    for (int b = 0; b < size; ++b) {
        counts[size_t(b)] = sendCounts[size_t(b)];
        offsets[size_t(b)] = sendOffsets[size_t(b)];
    }
    MPI_Gatherv(band.data(), int(band.size()), MPI_FLOAT, out.data(), counts.data(), offsets.data(), MPI_FLOAT, 0,
                comm);
    f.gatherMs = msSince(t0);
    if (rank != 0) f.bytesSent += band.size() * sizeof(float);
    if (rank == 0) f.bytesReceived += (out.size() - band.size()) * sizeof(float);
    if (figures) *figures = f;
    return out;
}

std::vector<float> compositeSerial(const std::vector<std::vector<float>>& images, CompositeOp op,
                                   const std::vector<int>& order) {
    const size_t n = images.size();
    const int first = op == CompositeOp::Over ? order[0] : 0;
    std::vector<float> out = images[size_t(first)];
    const size_t pixels = out.size() / size_t(channels(op));
    for (size_t i = 1; i < n; ++i)
        blend(out.data(), images[size_t(op == CompositeOp::Over ? order[i] : int(i))].data(), pixels, op);
    return out;
}

}  // namespace rtfact::distributed
