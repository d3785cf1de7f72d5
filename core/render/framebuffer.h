// Float RGBA framebuffer with an optional depth channel; samples accumulate, so
// progressive rendering is the sum divided by the sample count.
#pragma once
#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/concepts/framebuffer.h"
#include "core/simd/bitmask.h"
#include "core/util/aligned_allocator.h"

#if defined(__SSE2__)
#include <immintrin.h>
#endif

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
        const bool over = s.sample == overwriteSample_, overDepth = over && overwriteDepth_;
        simd::BitMask<N> bits(valid);
#if defined(__SSE2__)
        // Runs of 4 lanes on 4 consecutive pixels of a row (the renderers' packet blocks are
        // at least 4 wide): one 4x4 transpose and 4 vector stores instead of 16 scalar
        // read-modify-writes. At 1024^2 the scalar loop took 5% of a volume frame.
        const __m128i step = _mm_setr_epi32(0, 1, 2, 3);
        for (int i = 0; i + 4 <= N; i += 4) {
            if (((bits.w[i >> 6] >> (i & 63)) & 0xF) != 0xF) continue;
            const __m128i x = _mm_loadu_si128(reinterpret_cast<const __m128i*>(&s.px[i]));
            const __m128i y = _mm_loadu_si128(reinterpret_cast<const __m128i*>(&s.py[i]));
            const __m128i row = _mm_and_si128(_mm_cmpeq_epi32(x, _mm_add_epi32(_mm_set1_epi32(s.px[i]), step)),
                                              _mm_cmpeq_epi32(y, _mm_set1_epi32(s.py[i])));
            if (_mm_movemask_epi8(row) != 0xFFFF) continue;
            const size_t p = size_t(s.py[i]) * size_t(w_) + size_t(s.px[i]);
            __m128 c0 = _mm_loadu_ps(&r.color.x[i]), c1 = _mm_loadu_ps(&r.color.y[i]);
            __m128 c2 = _mm_loadu_ps(&r.color.z[i]), c3 = _mm_loadu_ps(&r.alpha[i]);
            _MM_TRANSPOSE4_PS(c0, c1, c2, c3);  // now pixel k's RGBA in ck
            float* d = &rgba_[p * 4];
            if (!over) {
                c0 = _mm_add_ps(c0, _mm_loadu_ps(d));
                c1 = _mm_add_ps(c1, _mm_loadu_ps(d + 4));
                c2 = _mm_add_ps(c2, _mm_loadu_ps(d + 8));
                c3 = _mm_add_ps(c3, _mm_loadu_ps(d + 12));
            }
            _mm_storeu_ps(d, c0);
            _mm_storeu_ps(d + 4, c1);
            _mm_storeu_ps(d + 8, c2);
            _mm_storeu_ps(d + 12, c3);
            if (!depth_.empty()) {
                const __m128 z = _mm_loadu_ps(&r.depth[i]);
                _mm_storeu_ps(&depth_[p], overDepth ? z : _mm_min_ps(z, _mm_loadu_ps(&depth_[p])));
            }
            bits.w[i >> 6] &= ~(uint64_t(0xF) << (i & 63));  // done
        }
#endif
        // the lanes left, by their bits (a test of all N lanes cost 1.5% of a volume frame)
        bits.forEach([&](int k) {
            const size_t p = size_t(s.py[k]) * size_t(w_) + size_t(s.px[k]);
            float* d = &rgba_[p * 4];
            const float c[4] = {r.color.x[k], r.color.y[k], r.color.z[k], r.alpha[k]};
            for (int j = 0; j < 4; ++j) d[j] = over ? c[j] : d[j] + c[j];
            if (!depth_.empty()) depth_[p] = overDepth ? float(r.depth[k]) : std::min(depth_[p], float(r.depth[k]));
        });
    }

    // Asks for the pixels of s (one cache line per run of 4 from x % 4 == 0) ahead of their
    // write, for writing: the renderer calls it before the integrator, so that the line
    // reads of a framebuffer larger than the caches overlap its work (at 1024^2 a volume
    // frame's stores otherwise waited on them: 5% of the frame).
    template <int N>
    void prefetch(const PixelSample<N>& s) const {
        // Lanes outside the image ask for lines outside it: prefetches do not fault. (GCC 12
        // drops the whole loop when the index is clamped, or a second loop prefetches the
        // depth: check the generated code before changing it.)
        const size_t w = size_t(w_);
        for (int i = 0; i < N; i += 4)
            __builtin_prefetch(rgba_.data() + (size_t(s.py[i]) * w + size_t(s.px[i])) * 4, 1, 3);
    }

    // From now on, writes of sample `sample` replace their pixels' colour (and their depth
    // when depthToo) instead of adding to it, so that a pass whose renderer writes each
    // pixel once per sample needs no clearing (RenderOptions::clear); -1: every write adds.
    void overwriteSample(int sample, bool depthToo) {
        overwriteSample_ = sample;
        overwriteDepth_ = depthToo;
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
    int overwriteSample_ = -1;
    bool overwriteDepth_ = false;
    std::vector<float, AlignedAllocator<float, 64>> rgba_;  // a 4-pixel run from x % 4 == 0: one line
    std::vector<float> depth_;
};
static_assert(Framebuffer<RGBAFramebuffer>);

}  // namespace rtfact
