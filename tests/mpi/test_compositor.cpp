// The sort-last compositor under mpirun (-np 1..4): every rank composites synthetic
// premultiplied RGBA (Over, in a shuffled visibility order) and RGBA+depth (Depth) images
// with rtfact::distributed::composite; rank 0 checks the result against the serial
// composite of all ranks' images, float for float, for image heights that do not divide
// into the ranks (and fewer rows than ranks). Exit 0 when every case matches.
#include <mpi.h>

#include <algorithm>
#include <cstdio>
#include <random>
#include <vector>

#include "distributed/sort_last_compositor.h"

using namespace rtfact::distributed;

namespace {

// Rank r's image, the same on every rank that makes it.
std::vector<float> imageOf(int r, int w, int h, CompositeOp op) {
    std::mt19937 rng(unsigned(1000 + r * 7 + w * 13 + h));
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const int ch = channels(op);
    std::vector<float> img(size_t(w) * size_t(h) * size_t(ch));
    for (size_t p = 0; p < size_t(w) * size_t(h); ++p) {
        float* px = &img[p * size_t(ch)];
        const float a = u(rng) < 0.3f ? 0.0f : u(rng);  // some empty pixels
        for (int c = 0; c < 3; ++c) px[c] = a * u(rng);
        px[3] = a;
        if (op == CompositeOp::Depth) px[4] = u(rng) < 0.2f ? 1e30f : u(rng) * 10.0f;
    }
    return img;
}

}  // namespace

int main(int argc, char** argv) {
    MPI_Init(&argc, &argv);
    int rank = 0, size = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    int failures = 0, cases = 0;
    const int sizes[][2] = {{17, 37}, {64, 3}, {5, 1}, {128, 64}};
    for (const auto& wh : sizes)
        for (CompositeOp op : {CompositeOp::Over, CompositeOp::Depth}) {
            const int w = wh[0], h = wh[1];
            std::vector<int> order(static_cast<size_t>(size));
            for (int i = 0; i < size; ++i) order[size_t(i)] = i;
            std::shuffle(order.begin(), order.end(), std::mt19937(unsigned(w + h)));
            CompositeFigures f;
            const std::vector<float> got = composite(MPI_COMM_WORLD, imageOf(rank, w, h, op), w, h, op, order, &f);
            ++cases;
            if (rank != 0) continue;
            std::vector<std::vector<float>> all;
            for (int r = 0; r < size; ++r) all.push_back(imageOf(r, w, h, op));
            const std::vector<float> want = compositeSerial(all, op, order);
            if (got != want) {
                std::printf("FAIL: %s %dx%d on %d ranks differs from the serial composite\n",
                            op == CompositeOp::Over ? "over" : "depth", w, h, size);
                ++failures;
            }
            // Direct-send: every rank but one sends and receives its share.
            if (size > 1 && h >= size && (f.bytesSent == 0 || f.bytesReceived == 0)) {
                std::printf("FAIL: no bytes moved on %d ranks\n", size);
                ++failures;
            }
        }
    // Over is not commutative: a reversed order must give another image (the test can fail).
    if (size > 1) {
        std::vector<int> fwd(static_cast<size_t>(size)), rev(static_cast<size_t>(size));
        for (int i = 0; i < size; ++i) fwd[size_t(i)] = i, rev[size_t(i)] = size - 1 - i;
        const auto a =
            composite(MPI_COMM_WORLD, imageOf(rank, 32, 8, CompositeOp::Over), 32, 8, CompositeOp::Over, fwd);
        const auto b =
            composite(MPI_COMM_WORLD, imageOf(rank, 32, 8, CompositeOp::Over), 32, 8, CompositeOp::Over, rev);
        if (rank == 0 && a == b) {
            std::printf("FAIL: front-to-back and back-to-front orders give the same image\n");
            ++failures;
        }
    }
    if (rank == 0 && failures == 0) std::printf("compositor: %d cases on %d ranks ok\n", cases, size);
    MPI_Bcast(&failures, 1, MPI_INT, 0, MPI_COMM_WORLD);
    MPI_Finalize();
    return failures ? 1 : 0;
}
