// Image regression for tests: compares a rendered RGBA float image with a reference
// PNG. Metric: 8-bit sRGB values; a pixel is "different" when any channel differs by
// more than `channelTolerance`/255; the test fails when more than `maxDifferentFraction`
// of the pixels differ or the PSNR falls below `minPsnr`. On failure the actual image,
// the reference and a x4 amplified difference image are written to RTFACT_TEST_OUT.
// RTFACT_UPDATE_REFERENCES=1 in the environment rewrites the reference instead.
#pragma once
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "core/render/image_io.h"
#include "core/render/srgb.h"

namespace rtfact::test {

struct ImageTolerance {
    int channelTolerance = 8;
    double maxDifferentFraction = 0.005;
    double minPsnr = 35.0;
};

struct ImageDiff {
    double differentFraction = 0;
    double psnr = 0;
    int maxChannelDiff = 0;
};

inline int toByte(float linear) { return linearToSrgb8(linear); }

// Compares two RGBA float images (same size) with the metric above.
inline ImageDiff compareRGBA(const std::vector<float>& a, const std::vector<float>& b, int w, int h, int tol) {
    ImageDiff d;
    double se = 0;
    size_t bad = 0;
    for (size_t p = 0, n = size_t(w) * size_t(h); p < n; ++p) {
        int worst = 0;
        for (int c = 0; c < 3; ++c) {
            const int x = toByte(a[p * 4 + size_t(c)]), y = toByte(b[p * 4 + size_t(c)]);
            worst = std::max(worst, std::abs(x - y));
            se += double(x - y) * double(x - y);
        }
        d.maxChannelDiff = std::max(d.maxChannelDiff, worst);
        if (worst > tol) ++bad;
    }
    const double mse = se / (3.0 * double(w) * double(h));
    d.psnr = mse == 0 ? 99.0 : 10.0 * std::log10(255.0 * 255.0 / mse);
    d.differentFraction = double(bad) / (double(w) * double(h));
    return d;
}

inline std::string testOutDir() {
    const char* env = std::getenv("RTFACT_TEST_OUT");
#ifdef RTFACT_TEST_OUT
    std::string dir = env ? env : RTFACT_TEST_OUT;
#else
    std::string dir = env ? env : "test-output";
#endif
    std::filesystem::create_directories(dir);
    return dir;
}

// Asserts that `rgba` (linear, background composited) matches the reference PNG.
inline void expectMatchesReference(const std::string& referencePath, int w, int h, const std::vector<float>& rgba,
                                   const ImageTolerance& tol = {}) {
    const char* update = std::getenv("RTFACT_UPDATE_REFERENCES");
    if (update && std::string(update) == "1") {
        writeImage(referencePath, w, h, rgba);
        GTEST_SKIP() << "reference rewritten: " << referencePath;
    }
    ASSERT_TRUE(std::filesystem::exists(referencePath))
        << "missing reference " << referencePath << " (run with RTFACT_UPDATE_REFERENCES=1)";
    const Image ref = readImage(referencePath);
    ASSERT_EQ(ref.width, w);
    ASSERT_EQ(ref.height, h);
    std::vector<float> refRGBA(size_t(w) * size_t(h) * 4, 1.0f);
    for (size_t p = 0; p < size_t(w) * size_t(h); ++p)
        for (int c = 0; c < 3; ++c)
            refRGBA[p * 4 + size_t(c)] = ref.pixels[p * size_t(ref.channels) + size_t(std::min(c, ref.channels - 1))];
    const ImageDiff d = compareRGBA(rgba, refRGBA, w, h, tol.channelTolerance);
    const bool ok = d.differentFraction <= tol.maxDifferentFraction && d.psnr >= tol.minPsnr;
    if (!ok) {
        const std::string stem = testOutDir() + "/" + std::filesystem::path(referencePath).stem().string();
        writeImage(stem + ".actual.png", w, h, rgba);
        writeImage(stem + ".reference.png", w, h, refRGBA);
        std::vector<float> diff(rgba.size(), 1.0f);
        for (size_t i = 0; i < rgba.size(); ++i)
            if (i % 4 != 3) diff[i] = std::min(1.0f, 4.0f * std::fabs(rgba[i] - refRGBA[i]));
        writeImage(stem + ".diff.png", w, h, diff);
    }
    EXPECT_TRUE(ok) << referencePath << ": " << d.differentFraction * 100.0 << "% pixels differ by more than "
                    << tol.channelTolerance << "/255 (allowed " << tol.maxDifferentFraction * 100.0 << "%), PSNR "
                    << d.psnr << " dB (min " << tol.minPsnr << "), max channel diff " << d.maxChannelDiff
                    << "; images written to " << testOutDir();
}

}  // namespace rtfact::test
