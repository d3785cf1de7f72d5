// Renders a whole image with a renderer: the image plane is split into tiles that TBB
// hands to worker threads dynamically (work stealing), for any number of samples.
#pragma once
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <functional>
#include <string>

#include "core/concepts/renderer.h"
#include "core/render/render_counters.h"
#include "core/util/progress.h"

namespace rtfact {

struct RenderOptions {
    int threads = 0;  // 0: all cores
    int tileSize = 32;
    int spp = 1;
    bool progress = true;
    std::string label = "render";
    int firstSample = 0;  // samples firstSample .. firstSample + spp - 1 (progressive passes)
    // What of the framebuffer each tile clears before its first sample (the framebuffer
    // accumulates): done by the thread that renders the tile, while its pixels are about to be
    // written, instead of one serial pass over the image before the render (16 MB at 1024^2);
    // a framebuffer with overwriteSample (RGBAFramebuffer) is not cleared at all, its first
    // sample's writes replace the pixels. Tiles not rendered (cancelled, or not handed out by
    // nextTile) are not cleared.
    enum class Clear { None, Color, ColorAndDepth } clear = Clear::None;
    // Set from any thread: no tile starts once it is true (a render stops within one tile
    // per thread); the stats then say cancelled.
    const std::atomic<bool>* cancel = nullptr;
    // Called after each tile with (tiles done, tiles in all samples), from worker threads.
    std::function<void(uint64_t, uint64_t)> onTile;
    // When set, only the tiles this source hands out are rendered: it returns the next
    // tile index (row-major over tileSize tiles, see TileGrid) or -1 when there are no
    // more; called from worker threads. Each tile gets all its samples in order, so its
    // pixels accumulate exactly as in a whole-image render (the MPI image-parallel mode).
    std::function<int()> nextTile;
};

// The tiles of a w x h image, row-major.
struct TileGrid {
    int width, height, size, columns, rows;
    TileGrid(int w, int h, int tileSize)
        : width(w),
          height(h),
          size(std::max(tileSize, 1)),
          columns((w + size - 1) / size),
          rows((h + size - 1) / size) {}
    int count() const { return columns * rows; }
    Region region(int t) const {
        const int x0 = (t % columns) * size, y0 = (t / columns) * size;
        return {x0, y0, std::min(x0 + size, width), std::min(y0 + size, height)};
    }
};

struct RenderStats {
    double ms = 0;
    uint64_t rays = 0;  // counters.rays
    int threads = 0;
    bool cancelled = false;
    RenderCounters counters;  // summed over every tile of the frame
};

inline int resolveThreads(int requested) { return requested > 0 ? requested : tbb::this_task_arena::max_concurrency(); }

template <int N, class R, class Scene, class Cam, class FB>
requires Renderer<R, Scene, Cam, FB> RenderStats renderImage(const R& renderer, const Scene& scene, const Cam& cam,
                                                             FB& fb, const RenderOptions& opt) {
    const TileGrid grid(fb.width(), fb.height(), opt.tileSize);
    const int tiles = grid.count();
    const int spp = std::max(opt.spp, 1);
    RenderStats st;
    st.threads = resolveThreads(opt.threads);
    std::atomic<uint64_t> done{0};
    const uint64_t total = uint64_t(tiles) * uint64_t(spp);
    auto cancelled = [&] { return opt.cancel && opt.cancel->load(std::memory_order_relaxed); };
    tbb::enumerable_thread_specific<RenderCounters> counted;
    Progress progress(opt.label, uint64_t(tiles) * uint64_t(spp), opt.progress);
    const auto t0 = std::chrono::steady_clock::now();
    // One tile with every sample of this frame (the nextTile source) or one sample.
    // A framebuffer that can overwrite (RGBAFramebuffer) takes the first sample's writes as
    // the clear: the renderers write each pixel of their region once per sample.
    constexpr bool overwrites = requires { fb.overwriteSample(0, true); };
    const bool clearing = opt.clear != RenderOptions::Clear::None;
    if constexpr (overwrites)
        fb.overwriteSample(clearing ? opt.firstSample : -1, opt.clear == RenderOptions::Clear::ColorAndDepth);
    auto renderTile = [&](int t, int s) {
        if (!overwrites && s == opt.firstSample && clearing)
            fb.clear(grid.region(t), opt.clear == RenderOptions::Clear::ColorAndDepth);
        renderer.template render<N>(scene, cam, fb, grid.region(t), s);
        progress.add();
        const uint64_t d = ++done;
        if (opt.onTile) opt.onTile(d, total);
    };
    tbb::task_arena arena(st.threads);
    arena.execute([&] {
        if (opt.nextTile) {
            // One task per thread, each pulling tiles until the source runs dry.
            tbb::parallel_for(
                0, st.threads,
                [&](int) {
                    const RenderCounters before = tlsCounters;
                    for (int t = 0; !cancelled() && (t = opt.nextTile()) >= 0;) {
                        if (t >= tiles) continue;
                        for (int s = opt.firstSample; s < opt.firstSample + spp; ++s) renderTile(t, s);
                    }
                    counted.local() += tlsCounters - before;
                },
                tbb::simple_partitioner());
            return;
        }
        for (int s = opt.firstSample; s < opt.firstSample + spp && !cancelled(); ++s) {
            tbb::parallel_for(
                tbb::blocked_range<int>(0, tiles, 1),
                [&](const tbb::blocked_range<int>& range) {
                    const RenderCounters before = tlsCounters;
                    for (int t = range.begin(); t != range.end() && !cancelled(); ++t) renderTile(t, s);
                    counted.local() += tlsCounters - before;
                },
                tbb::simple_partitioner());
        }
    });
    if constexpr (overwrites) fb.overwriteSample(-1, false);
    progress.finish();
    st.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    for (const RenderCounters& c : counted) st.counters += c;
    st.rays = st.counters.rays;
    st.cancelled = cancelled() && done.load() < total;
    return st;
}

}  // namespace rtfact
