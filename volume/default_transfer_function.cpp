#include "volume/default_transfer_function.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace rtfact::volume {

namespace {

std::string num(float v) {
    char b[32];
    std::snprintf(b, sizeof(b), "%g", double(v));
    return b;
}

// For data without a preset, over the histogram window, with the median of the voxels
// above the background at m (0..1 in the window). Unshaded DVR: translucent on purpose,
// since an opaque ramp shows only the outer surface, flat (a featureless blob); at these
// opacities a head-sized MRI is seen through to the brain, and the dark bottom makes faint
// tissue darken rather than fog what lies behind it.
TransferFunction histogramRamp(float m) {
    TransferFunction tf;
    tf.name = "histogram-ramp";
    tf.colors = {{0.0f, {0.1f, 0.05f, 0.05f}},
                 {m, {0.6f, 0.35f, 0.25f}},
                 {0.5f * (m + 1.0f), {0.95f, 0.85f, 0.7f}},
                 {1.0f, {1, 1, 1}}};
    tf.opacity = {{0.0f, 0.0f}, {m, 0.006f}, {0.5f * (m + 1.0f), 0.025f}, {1.0f, 0.1f}};
    return tf;
}
// Shaded DVR and iso: gradient shading shows surfaces, so the ramp turns opaque by the
// median (the skin of a head, the enamel and dentin of the tooth).
TransferFunction histogramRampOpaque(float m) {
    TransferFunction tf;
    tf.name = "histogram-ramp-opaque";
    tf.colors = {{0.0f, {0.55f, 0.3f, 0.2f}},
                 {m, {0.85f, 0.7f, 0.55f}},
                 {0.5f * (m + 1.0f), {0.97f, 0.92f, 0.85f}},
                 {1.0f, {1, 1, 1}}};
    tf.opacity = {{0.0f, 0.0f}, {0.4f * m, 0.02f}, {m, 0.25f}, {1.0f, 0.8f}};
    return tf;
}

// Keeps the optical depth of a ramp across the volume: a' = 1 - (1 - a)^(reference / depth).
void scaleOpacityToDepth(TransferFunction& tf, float depthVoxels) {
    const float e = std::clamp(kReferenceDepthVoxels / std::max(depthVoxels, 1.0f), 0.25f, 8.0f);
    for (OpacityPoint& p : tf.opacity) p.a = 1.0f - std::pow(1.0f - p.a, e);
}

}  // namespace

float typicalDepthVoxels(const int dims[3], Vec3f spacing) {
    const float smallest = std::min({spacing.x, spacing.y, spacing.z});
    if (!(smallest > 0)) return kReferenceDepthVoxels;
    float extent = 0;
    for (int a = 0; a < 3; ++a) extent += float(std::max(dims[a] - 1, 1)) * spacing[a];
    return extent / 3.0f / smallest;
}

bool looksLikeHounsfield(const ValueHistogram& h) {
    if (!(h.lo <= -500.0f && h.hi > 0.0f) || h.total == 0) return false;
    const size_t last = h.binOf(-500.0f);
    return double(h.count(0, last)) >= 0.001 * double(h.total);
}

RampPlacement placeHistogramRamp(const ValueHistogram& h) {
    RampPlacement r;
    const size_t n = h.bins.size();
    if (n == 0 || h.total == 0 || !(h.hi > h.lo)) {
        r.background = r.lo = h.lo;
        r.hi = h.lo + 1.0f;
        return r;
    }
    // Background: the most common value in the lower half of the range (backgrounds are
    // dark: air, zero outside a skull-stripped brain, the noise floor of a raw CT).
    const size_t searchEnd = std::max<size_t>(1, std::min(n, h.binOf(h.lo + 0.5f * (h.hi - h.lo)) + 1));
    size_t peak = 0;
    for (size_t i = 1; i < searchEnd; ++i)
        if (h.bins[i] > h.bins[peak]) peak = i;
    r.background = std::clamp(h.binCenter(peak), h.lo, h.hi);
    // End of the background peak: the first bin above it holding under 5% of the peak's
    // count, then on down its tail to the valley (the count stops falling, measured over a
    // few bins so that single-bin noise does not stop it early), but never past the first
    // quarter of the voxels above it (a histogram falling all the way has no valley).
    const double peakCount = double(h.bins[peak]);
    size_t end = peak + 1;
    while (end < n && double(h.bins[end]) >= 0.05 * peakCount) ++end;
    const size_t cap = end < n ? h.binOf(h.percentile(0.25, end)) : n;
    const size_t w = std::max<size_t>(2, n / 128);
    auto windowSum = [&](size_t i) { return h.count(i, std::min(n - 1, i + w - 1)); };
    while (end + w < n && end + w <= cap && windowSum(end + w) < windowSum(end)) end += w;
    if (end >= n) end = n - 1;
    r.lo = std::clamp(h.binLo(end), h.lo, h.hi);
    // Top: the 99.5th percentile of the voxels above the background, so a few hot voxels
    // (vessels, artefacts) do not squeeze the tissue into the bottom of the ramp.
    r.hi = h.percentile(0.995, end);
    if (!(r.hi > r.lo)) r.hi = h.hi > r.lo ? h.hi : r.lo + std::max(h.width, 1e-6f);
    r.median = std::clamp(h.percentile(0.5, end), r.lo, r.hi);
    return r;
}

DefaultTransferFunction chooseDefaultTransferFunction(const VolumeMetadata& meta, const ValueHistogram& h,
                                                      VolumeMode mode, float depthVoxels) {
    DefaultTransferFunction d;
    const bool mip = mode == VolumeMode::MIP;
    const bool hu = looksLikeHounsfield(h);
    const std::string range = num(h.lo) + ".." + num(h.hi);
    const std::string stated = meta.modality.empty() ? std::string() : meta.modalitySource + " " + meta.modality;
    if (meta.modality == "CT" || (meta.modality.empty() && hu)) {
        d.tf = transferFunctionPreset(mip ? "grayscale" : "ct-bone");
        // the CT presets' Hounsfield window when the values are Hounsfield units, else the range
        d.window =
            hu && d.tf.huWindow ? *d.tf.huWindow : std::pair<float, float>{h.lo, h.hi > h.lo ? h.hi : h.lo + 1.0f};
        if (!stated.empty())
            d.reason = stated + (hu ? "" : "; values " + range + " are not Hounsfield units: preset over the range");
        else
            d.reason = "values " + range + " look like Hounsfield units: air at -1000";
        if (mip) d.reason = "MIP over " + num(d.window.first) + ".." + num(d.window.second) + "; " + d.reason;
        return d;
    }
    const RampPlacement p = placeHistogramRamp(h);
    const float m = std::clamp((p.median - p.lo) / (p.hi - p.lo), 0.1f, 0.9f);
    d.tf = mip                       ? transferFunctionPreset("grayscale")
           : mode == VolumeMode::DVR ? histogramRamp(m)
                                     : histogramRampOpaque(m);
    if (!mip) scaleOpacityToDepth(d.tf, depthVoxels);
    d.window = {p.lo, p.hi};
    d.reason = (mip ? std::string("MIP; ") : std::string()) + (stated.empty() ? std::string() : stated + "; ") +
               num(p.lo) + ".." + num(p.hi) + " from the histogram: above the background peak at " + num(p.background) +
               ", up to the 99.5th percentile";
    return d;
}

}  // namespace rtfact::volume
