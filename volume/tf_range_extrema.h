// TFRangeExtrema: the minimum and maximum of each transfer-function channel over any
// range of table entries, in O(1) per query (sparse tables: per level l the extrema over
// 2^l entries). The opacity-adaptive step reads them for every brick's value range.
#pragma once
#include <algorithm>
#include <array>
#include <bit>
#include <vector>

#include "volume/transfer_function.h"

namespace rtfact::volume {

class TFRangeExtrema {
   public:
    // Channels in the order r, g, b, a.
    struct Extrema {
        std::array<float, 4> lo, hi;
    };

   private:
    int size_ = 0;
    // level l, channel c: lo_[l][c][i] = min over entries [i, i + 2^l)
    std::vector<std::array<std::vector<float>, 4>> lo_, hi_;

   public:
    explicit TFRangeExtrema(const TFTable& t) : size_(t.size) {
        const std::vector<float>* ch[4] = {&t.r, &t.g, &t.b, &t.a};
        const int levels = size_ > 0 ? std::bit_width(unsigned(size_)) : 0;
        lo_.resize(size_t(levels));
        hi_.resize(size_t(levels));
        for (int c = 0; c < 4 && levels > 0; ++c) lo_[0][size_t(c)] = hi_[0][size_t(c)] = *ch[c];
        for (int l = 1; l < levels; ++l) {
            const size_t n = size_t(size_) - (size_t(1) << l) + 1, half = size_t(1) << (l - 1);
            for (size_t c = 0; c < 4; ++c) {
                const std::vector<float>&plo = lo_[size_t(l) - 1][c], &phi = hi_[size_t(l) - 1][c];
                std::vector<float>&qlo = lo_[size_t(l)][c], &qhi = hi_[size_t(l)][c];
                qlo.resize(n);
                qhi.resize(n);
                for (size_t i = 0; i < n; ++i) {
                    qlo[i] = std::min(plo[i], plo[i + half]);
                    qhi[i] = std::max(phi[i], phi[i + half]);
                }
            }
        }
    }

    // Extrema over entries [i0, i1] (0 <= i0 <= i1 < size).
    Extrema range(int i0, int i1) const {
        const int l = std::bit_width(unsigned(i1 - i0 + 1)) - 1;
        const size_t a = size_t(i0), b = size_t(i1 + 1 - (1 << l));
        Extrema e;
        for (size_t c = 0; c < 4; ++c) {
            e.lo[c] = std::min(lo_[size_t(l)][c][a], lo_[size_t(l)][c][b]);
            e.hi[c] = std::max(hi_[size_t(l)][c][a], hi_[size_t(l)][c][b]);
        }
        return e;
    }
};

}  // namespace rtfact::volume
