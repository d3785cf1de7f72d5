// What every rtfact-bench subcommand needs: a clock, x,y,z option parsing and a tiled
// parallel frame timer that runs both sides (RTfact and its peer) the same way.
#pragma once
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <time.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>

#include "core/math/vec3f.h"
#include "core/simd/vec3.h"
#include "core/util/error.h"

namespace rtfact::bench {

// A command-line error: CLI11's message, exit status 2 (bad usage) like rtfact's; --help: 0.
// (CLI::App and CLI::ParseError as template parameters: CLI11 is not included here, where
// X11's `Success` macro may already be defined.)
template <class App, class ParseError>
int usageExit(const App& app, const ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
}

using Clock = std::chrono::steady_clock;
inline double msSince(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// "x,y,z" for option `opt`.
inline Vec3f parseVec(const std::string& s, const char* opt) {
    Vec3f v;
    char c1 = 0, c2 = 0;
    std::istringstream in(s);
    if (!(in >> v.x >> c1 >> v.y >> c2 >> v.z) || c1 != ',' || c2 != ',')
        throw Error("", std::string(opt) + ": expected x,y,z, got '" + s + "'");
    return v;
}

// The CPU's model name, printed next to every figure.
inline std::string cpuModel() {
    std::ifstream in("/proc/cpuinfo");
    for (std::string line; std::getline(in, line);)
        if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
    return "unknown CPU";
}

inline constexpr int kTile = 32;

// Sample positions of the BW-wide block of N pixels at (x, y), lane i at pixel
// (x + i % BW, y + i / BW) plus (sx, sy): one vector add to constant lane offsets, as the
// renderer does (lanes written one by one and read back as a vector stall store
// forwarding: ~2% of a points frame, on both sides of a comparison).
template <int N, int BW>
inline void blockPixels(int x, int y, float sx, float sy, Packet<N>& px, Packet<N>& py) {
    static const auto offsets = [] {
        std::pair<Packet<N>, Packet<N>> o;
        for (int i = 0; i < N; ++i) o.first[i] = float(i % BW), o.second[i] = float(i / BW);
        return o;
    }();
    px = Packet<N>(float(x) + sx) + offsets.first;
    py = Packet<N>(float(y) + sy) + offsets.second;
}

// RTFACT_BENCH_CLOCK=cpu: one-thread figures are the calling thread's CPU time instead of
// wall time. On a machine shared with other jobs the wall time of one thread swings by 2x
// with the load (time slices), its CPU time far less; several threads keep wall time.
inline bool cpuClockForOneThread() {
    static const bool on = [] {
        const char* e = std::getenv("RTFACT_BENCH_CLOCK");
        const bool cpu = e != nullptr && std::string(e) == "cpu";
        if (cpu) std::printf("clock: 1-thread figures are thread CPU time (RTFACT_BENCH_CLOCK=cpu)\n");
        return cpu;
    }();
    return on;
}
inline double threadCpuMs() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
}

// Runs body() in a task arena of `threads` threads; returns its time in ms (wall time, or
// with one thread and RTFACT_BENCH_CLOCK=cpu the calling thread's CPU time: a one-thread
// arena runs its work in the thread that calls execute).
template <class F>
double timeArena(int threads, F&& body) {
    tbb::task_arena arena(threads);
    if (threads == 1 && cpuClockForOneThread()) {
        const double c0 = threadCpuMs();
        arena.execute(body);
        return threadCpuMs() - c0;
    }
    const auto t0 = Clock::now();
    arena.execute(body);
    return msSince(t0);
}

// Calls tile(x0, y0) for every kTile x kTile tile of a w x h image on `threads` threads;
// returns the time in ms (timeArena).
template <class F>
double timeTiles(int threads, int w, int h, F&& tile) {
    const int tx = (w + kTile - 1) / kTile, ty = (h + kTile - 1) / kTile;
    return timeArena(threads, [&] {
        tbb::parallel_for(tbb::blocked_range<int>(0, tx * ty, 1), [&](const tbb::blocked_range<int>& r) {
            for (int i = r.begin(); i != r.end(); ++i) tile((i % tx) * kTile, (i / tx) * kTile);
        });
    });
}

}  // namespace rtfact::bench
