#include "apps/view/preview_scale.h"

#include <algorithm>
#include <cmath>

namespace rtfact::viewer {

void PreviewScale::observe(double ms, double pixels) {
    if (!(ms > 0) || !(pixels > 0)) return;
    const double m = ms / pixels;
    // Smoothed so that one slow frame (a page fault, another tab) does not halve the
    // resolution; the first observation is taken as it is.
    msPerPixel_ = msPerPixel_ == 0 ? m : 0.7 * msPerPixel_ + 0.3 * m;
}

int PreviewScale::scaleFor(double fullPixels) const {
    if (msPerPixel_ == 0) return maxScale_ >= 4 ? 4 : maxScale_;
    const double fullMs = msPerPixel_ * fullPixels;
    const int s = int(std::ceil(std::sqrt(fullMs / targetMs_)));
    return std::clamp(s, 1, maxScale_);
}

}  // namespace rtfact::viewer
