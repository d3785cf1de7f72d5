// What every rtfact-bench subcommand needs: a clock, x,y,z option parsing and a tiled
// parallel frame timer that runs both sides (RTfact and its peer) the same way.
#pragma once
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <string>

#include "core/math/vec3f.h"
#include "core/util/error.h"

namespace rtfact::bench {

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

// Calls tile(x0, y0) for every kTile x kTile tile of a w x h image on `threads` threads;
// returns the wall time in ms.
template <class F>
double timeTiles(int threads, int w, int h, F&& tile) {
    const int tx = (w + kTile - 1) / kTile, ty = (h + kTile - 1) / kTile;
    tbb::task_arena arena(threads);
    const auto t0 = Clock::now();
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<int>(0, tx * ty, 1), [&](const tbb::blocked_range<int>& r) {
            for (int i = r.begin(); i != r.end(); ++i) tile((i % tx) * kTile, (i / tx) * kTile);
        });
    });
    return msSince(t0);
}

}  // namespace rtfact::bench
