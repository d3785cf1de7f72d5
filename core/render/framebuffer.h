// Float RGBA framebuffer with an optional depth channel; samples accumulate, so
// progressive rendering is the sum divided by the sample count.
#pragma once
#include <algorithm>
#include <vector>

#include "core/concepts/framebuffer.h"

namespace rtfact {

class RGBAFramebuffer {
   public:
    RGBAFramebuffer(int w, int h, bool depth = false)
        : w_(w), h_(h), rgba_(size_t(w) * size_t(h) * 4, 0.0f), depth_(depth ? size_t(w) * size_t(h) : 0, kInfinity) {}

    int width() const { return w_; }
    int height() const { return h_; }
    bool hasDepth() const { return !depth_.empty(); }

    template <int N>
    void write(const PixelSample<N>& s, const Radiance<N>& r, const Mask<N>& valid) {
        for (int i = 0; i < N; ++i) {
            if (!valid[i]) continue;
            const size_t p = size_t(s.py[i]) * size_t(w_) + size_t(s.px[i]);
            float* d = &rgba_[p * 4];
            d[0] += r.color.x[i];
            d[1] += r.color.y[i];
            d[2] += r.color.z[i];
            d[3] += r.alpha[i];
            if (!depth_.empty()) depth_[p] = std::min(depth_[p], float(r.depth[i]));
        }
    }

    // Averaged pixel i (RGBA) after `samples` accumulated samples.
    const float* rawRGBA() const { return rgba_.data(); }
    std::vector<float> resolved(int samples) const {
        std::vector<float> out(rgba_.size());
        const float inv = 1.0f / float(samples > 0 ? samples : 1);
        for (size_t i = 0; i < rgba_.size(); ++i) out[i] = rgba_[i] * inv;
        return out;
    }
    const std::vector<float>& depth() const { return depth_; }
    // The pixels of r (clipped to the image); the depth too when depthToo (without it the
    // depth keeps its minimum over the passes of one accumulation).
    void clear(const Region& r, bool depthToo) {
        const int x0 = std::max(r.x0, 0), x1 = std::min(r.x1, w_);
        if (x0 >= x1) return;
        for (int y = std::max(r.y0, 0); y < std::min(r.y1, h_); ++y) {
            const size_t p = size_t(y) * size_t(w_);
            std::fill(&rgba_[(p + size_t(x0)) * 4], &rgba_[(p + size_t(x1)) * 4], 0.0f);
            if (depthToo && !depth_.empty()) std::fill(&depth_[p + size_t(x0)], &depth_[p + size_t(x1)], kInfinity);
        }
    }

   private:
    int w_, h_;
    std::vector<float> rgba_;
    std::vector<float> depth_;
};
static_assert(Framebuffer<RGBAFramebuffer>);

}  // namespace rtfact
