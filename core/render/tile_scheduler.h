// Renders a whole image with a renderer: the image plane is split into tiles that TBB
// hands to worker threads dynamically (work stealing), for any number of samples.
#pragma once
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <chrono>

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
};

struct RenderStats {
    double ms = 0;
    uint64_t rays = 0;  // counters.rays
    int threads = 0;
    RenderCounters counters;  // summed over every tile of the frame
};

inline int resolveThreads(int requested) { return requested > 0 ? requested : tbb::this_task_arena::max_concurrency(); }

template <int N, class R, class Scene, class Cam, class FB>
requires Renderer<R, Scene, Cam, FB> RenderStats renderImage(const R& renderer, const Scene& scene, const Cam& cam,
                                                             FB& fb, const RenderOptions& opt) {
    const int w = fb.width(), h = fb.height();
    const int ts = std::max(opt.tileSize, 1);
    const int tx = (w + ts - 1) / ts, ty = (h + ts - 1) / ts, tiles = tx * ty;
    const int spp = std::max(opt.spp, 1);
    RenderStats st;
    st.threads = resolveThreads(opt.threads);
    tbb::enumerable_thread_specific<RenderCounters> counted;
    Progress progress(opt.label, uint64_t(tiles) * uint64_t(spp), opt.progress);
    const auto t0 = std::chrono::steady_clock::now();
    tbb::task_arena arena(st.threads);
    arena.execute([&] {
        for (int s = 0; s < spp; ++s) {
            tbb::parallel_for(
                tbb::blocked_range<int>(0, tiles, 1),
                [&](const tbb::blocked_range<int>& range) {
                    const RenderCounters before = tlsCounters;
                    for (int t = range.begin(); t != range.end(); ++t) {
                        const int x0 = (t % tx) * ts, y0 = (t / tx) * ts;
                        const Region region{x0, y0, std::min(x0 + ts, w), std::min(y0 + ts, h)};
                        renderer.template render<N>(scene, cam, fb, region, s);
                        progress.add();
                    }
                    counted.local() += tlsCounters - before;
                },
                tbb::simple_partitioner());
        }
    });
    progress.finish();
    st.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    for (const RenderCounters& c : counted) st.counters += c;
    st.rays = st.counters.rays;
    return st;
}

}  // namespace rtfact
