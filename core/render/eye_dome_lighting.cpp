#include "core/render/eye_dome_lighting.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>

namespace rtfact {

void applyEyeDomeLighting(std::vector<float>& rgba, const std::vector<float>& depth, int w, int h, float strength,
                          float radius) {
    const size_t n = size_t(w) * size_t(h);
    if (!(strength > 0) || depth.size() != n || rgba.size() != 4 * n) return;
    // log2 depth: the response depends on depth ratios, not on the scene's scale.
    std::vector<float> ld(n);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, size_t(1) << 14), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i < r.end(); ++i) {
            const float d = depth[i];
            ld[i] = std::isfinite(d) && d > 0 ? std::log2(d) : INFINITY;
        }
    });
    const int r = std::max(1, int(std::lround(radius)));
    static constexpr int dirs[8][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, 1}, {-1, -1}, {1, -1}, {-1, 1}};
    // exp(-k * mean positive log2-depth step) with Potree's k = 300: the sub-percent steps
    // across a sloped surface shade it a little, steps between objects make dark outlines.
    const float k = 300.0f * strength;
    tbb::parallel_for(tbb::blocked_range<int>(0, h, 8), [&](const tbb::blocked_range<int>& rows) {
        for (int y = rows.begin(); y < rows.end(); ++y)
            for (int x = 0; x < w; ++x) {
                const size_t p = size_t(y) * size_t(w) + size_t(x);
                const float c = ld[p];
                if (!std::isfinite(c)) continue;
                float sum = 0;
                for (const auto& d : dirs) {
                    const int nx = x + d[0] * r, ny = y + d[1] * r;
                    if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
                    const float q = ld[size_t(ny) * size_t(w) + size_t(nx)];
                    if (std::isfinite(q)) sum += std::max(0.0f, c - q);  // background neighbours: no step
                }
                const float shade = std::exp(-k * sum * (1.0f / 8.0f));
                for (int ch = 0; ch < 3; ++ch) rgba[4 * p + size_t(ch)] *= shade;
            }
    });
}

}  // namespace rtfact
