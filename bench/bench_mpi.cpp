// rtfact-bench mpi (under mpirun -np P): the sort-last compositor and data-parallel volume
// rendering on the ranks at hand.
//   1. Compositing per frame against image size: direct-send (rtfact::distributed) next
//      to the naive reference (every rank sends its whole image to rank 0, which blends
//      them), as a ratio; with the bytes each rank moves.
//   2. Strong scaling (with FILE): the volume rendered whole by rank 0 alone, then by
//      the P ranks each holding a slab (load, render, composite), as a speedup.
// Figures are the slowest rank's, best of --repeat frames.
#include <mpi.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "bench/bench_commands.h"
#include "bench/bench_common.h"
#include "core/render/pinhole_camera.h"
#include "distributed/sort_last_compositor.h"
#include "distributed/volume_parts.h"
#include "engine/render_session.h"
#include "engine/volume_part.h"

namespace rtfact::bench {

namespace {

// The slowest rank's time of `f` (ms), best of `repeat`; every rank calls it.
template <class F>
double slowestMs(int repeat, F&& f) {
    double best = 1e300;
    for (int i = 0; i < repeat; ++i) {
        MPI_Barrier(MPI_COMM_WORLD);
        const auto t0 = Clock::now();
        f();
        double ms = msSince(t0);
        MPI_Allreduce(MPI_IN_PLACE, &ms, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
        best = std::min(best, ms);
    }
    return best;
}

// The naive reference: rank 0 receives every rank's whole image and blends them.
std::vector<float> gatherAndBlend(const std::vector<float>& image, int ranks, int rank, const std::vector<int>& order) {
    std::vector<float> all(rank == 0 ? image.size() * size_t(ranks) : 0);
    MPI_Gather(image.data(), int(image.size()), MPI_FLOAT, all.data(), int(image.size()), MPI_FLOAT, 0, MPI_COMM_WORLD);
    if (rank != 0) return {};
    std::vector<std::vector<float>> images;
    for (int r = 0; r < ranks; ++r)
        images.emplace_back(all.begin() + std::ptrdiff_t(size_t(r) * image.size()),
                            all.begin() + std::ptrdiff_t(size_t(r + 1) * image.size()));
    return distributed::compositeSerial(images, distributed::CompositeOp::Over, order);
}

}  // namespace

int benchMpi(int argc, char** argv) {
    CLI::App app{"rtfact-bench mpi (under mpirun): sort-last compositing and data-parallel volume scaling"};
    std::string file, size = "1024x1024";
    int repeat = 5, threads = 1;
    app.add_option("FILE", file, "Volume for the strong-scaling figure (optional)");
    app.add_option("--size", size, "Render size WxH of the scaling figure")->capture_default_str();
    app.add_option("--repeat", repeat, "Timed frames (best counts)")->capture_default_str()->check(CLI::Range(1, 1000));
    app.add_option("--threads", threads, "Render threads per rank")->capture_default_str();
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return usageExit(app, e);
    }
    int provided = 0;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
    int rank = 0, ranks = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    const bool root = rank == 0;
    if (root) std::printf("rtfact-bench mpi: %d ranks, CPU: %s\n", ranks, cpuModel().c_str());

    // 1. Compositing against image size.
    std::vector<int> order(static_cast<size_t>(ranks));
    for (int r = 0; r < ranks; ++r) order[size_t(r)] = ranks - 1 - r;
    if (root)
        std::printf("%-10s %12s %10s %10s %10s %12s %12s %8s\n", "image", "direct_ms", "exchange", "blend", "gather",
                    "bytes/rank", "naive_ms", "ratio");
    for (const auto& wh : {std::pair{512, 512}, std::pair{1024, 1024}, std::pair{1920, 1080}, std::pair{3840, 2160}}) {
        const auto [w, h] = wh;
        std::vector<float> image(size_t(w) * size_t(h) * 4);
        std::mt19937 rng(unsigned(rank + 1));
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        for (size_t p = 0; p < image.size(); p += 4) {
            const float a = u(rng);
            image[p] = image[p + 1] = image[p + 2] = 0.5f * a;
            image[p + 3] = a;
        }
        distributed::CompositeFigures f, best;
        double bestMs = 1e300;
        for (int i = 0; i < repeat; ++i) {
            MPI_Barrier(MPI_COMM_WORLD);
            const auto t0 = Clock::now();
            distributed::composite(MPI_COMM_WORLD, image, w, h, distributed::CompositeOp::Over, order, &f);
            double ms = msSince(t0);
            MPI_Allreduce(MPI_IN_PLACE, &ms, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
            if (ms < bestMs) bestMs = ms, best = f;
        }
        const double naive = slowestMs(repeat, [&] { gatherAndBlend(image, ranks, rank, order); });
        if (root)
            std::printf("%4dx%-5d %12.2f %10.2f %10.2f %10.2f %12llu %12.2f %8.2f\n", w, h, bestMs, best.exchangeMs,
                        best.blendMs, best.gatherMs, (unsigned long long)(best.bytesSent + best.bytesReceived), naive,
                        naive / bestMs);
    }

    // 2. Strong scaling on a volume.
    if (!file.empty()) {
        int w = 0, h = 0;
        if (std::sscanf(size.c_str(), "%dx%d", &w, &h) != 2 || w < 1 || h < 1) throw Error("--size", "expected WxH");
        engine::OpenOptions oo;
        oo.progress = false;
        engine::FrameOptions frame;
        frame.width = w;
        frame.height = h;
        frame.threads = threads;
        engine::Settings s;
        double single = 0;
        engine::Stats ignored;
        // Rank 0 alone, the whole volume (the others wait).
        if (root) {
            engine::VolumePart whole = engine::loadVolumePart(file, oo, 0, 1);
            distributed::agreeOnTransferFunction(MPI_COMM_SELF, whole, s);
            const CameraFrame cam = fitCamera(engine::wholeClippedBox(whole, s.volume), 45.0f, float(w) / float(h),
                                              {0.45f, -1.0f, 0.35f}, {0, 0, 1});
            const engine::Scene scene = engine::partScene(whole);
            const engine::Settings ps = *engine::partSettings(whole, s);
            single = 1e300;
            for (int i = 0; i < repeat; ++i) {
                const auto t0 = Clock::now();
                engine::renderToImage(scene, ps, frame, cam, 1, ignored);
                single = std::min(single, msSince(t0));
            }
        }
        MPI_Barrier(MPI_COMM_WORLD);
        engine::Settings sp;
        engine::VolumePart part;
        const double loadMs = slowestMs(1, [&] { part = engine::loadVolumePart(file, oo, rank, ranks); });
        distributed::agreeOnTransferFunction(MPI_COMM_WORLD, part, sp);
        const CameraFrame cam = fitCamera(engine::wholeClippedBox(part, sp.volume), 45.0f, float(w) / float(h),
                                          {0.45f, -1.0f, 0.35f}, {0, 0, 1});
        const std::vector<int> vis = distributed::slabVisibilityOrder(part, ranks, cam.eye);
        const std::optional<engine::Settings> ps = engine::partSettings(part, sp);
        const engine::Scene scene = engine::partScene(part);
        engine::Frame img;
        const double renderMs = slowestMs(repeat, [&] {
            if (ps)
                img = engine::renderToImage(scene, *ps, frame, cam, 1, ignored);
            else
                img.rgba.assign(size_t(w) * size_t(h) * 4, 0.0f);
        });
        const double compMs = slowestMs(repeat, [&] {
            distributed::composite(MPI_COMM_WORLD, img.rgba, w, h, distributed::CompositeOp::Over, vis);
        });
        if (root)
            std::printf(
                "strong scaling, %s at %dx%d, %d thread(s) per rank: one rank %.1f ms; %d ranks: load %.1f ms, "
                "render %.1f ms + composite %.1f ms = %.1f ms per frame; speedup %.2f\n",
                file.c_str(), w, h, threads, single, ranks, loadMs, renderMs, compMs, renderMs + compMs,
                single / (renderMs + compMs));
    }
    MPI_Finalize();
    return 0;
}

}  // namespace rtfact::bench
