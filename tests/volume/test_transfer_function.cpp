// Transfer functions: presets, interpolation, window/level, opacity correction, JSON.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "core/util/error.h"
#include "volume/tf_range_extrema.h"
#include "volume/transfer_function.h"

using namespace rtfact;
using namespace rtfact::volume;

TEST(TransferFunction, PresetsAreValid) {
    for (const std::string& name : transferFunctionPresets()) {
        const TransferFunction tf = transferFunctionPreset(name);
        EXPECT_NO_THROW(tf.validate(name)) << name;
        EXPECT_EQ(tf.name, name);
    }
    EXPECT_THROW(transferFunctionPreset("no-such-preset"), Error);
}

TEST(TransferFunction, PiecewiseLinear) {
    const TransferFunction tf = parseTransferFunctionJson(
        R"({"name":"t","colors":[[0,0,0,0],[1,1,0.5,0]],"opacity":[[0,0],[0.5,0.2],[1,1]]})", "t.json");
    EXPECT_NEAR(tf.alpha(0.25f), 0.1f, 1e-6f);
    EXPECT_NEAR(tf.alpha(0.75f), 0.6f, 1e-6f);
    EXPECT_NEAR(tf.alpha(-1.0f), 0.0f, 1e-6f);  // clamped at the ends
    EXPECT_NEAR(tf.alpha(2.0f), 1.0f, 1e-6f);
    EXPECT_NEAR(tf.color(0.5f).x, 0.5f, 1e-6f);
    EXPECT_NEAR(tf.color(0.5f).y, 0.25f, 1e-6f);
}

TEST(TransferFunction, WindowLevelAndHounsfield) {
    const TransferFunction bone = transferFunctionPreset("ct-bone");
    // CT-like data (air at -1000 HU): the preset's Hounsfield window
    auto w = resolveWindow(bone, -1024.0f, 3000.0f, std::nullopt, std::nullopt);
    EXPECT_FLOAT_EQ(w.first, -1000.0f);
    EXPECT_FLOAT_EQ(w.second, 2000.0f);
    // other data: the data range
    w = resolveWindow(bone, 0.0f, 255.0f, std::nullopt, std::nullopt);
    EXPECT_FLOAT_EQ(w.first, 0.0f);
    EXPECT_FLOAT_EQ(w.second, 255.0f);
    // explicit window/level
    w = resolveWindow(bone, 0.0f, 255.0f, 400.0f, 40.0f);
    EXPECT_FLOAT_EQ(w.first, -160.0f);
    EXPECT_FLOAT_EQ(w.second, 240.0f);
    EXPECT_THROW(resolveWindow(bone, 0, 1, -5.0f, 0.0f), Error);
}

TEST(TransferFunction, OpacityCorrectedForStep) {
    const TransferFunction tf =
        parseTransferFunctionJson(R"({"colors":[[0,1,1,1],[1,1,1,1]],"opacity":[[0,0.3],[1,0.3]]})", "c");
    for (float step : {0.25f, 0.5f, 1.0f, 2.0f}) {
        const TFTable t = buildTable(tf, {0.0f, 1.0f}, step, 256);
        // n steps of size `step` must attenuate like n*step voxels of size 1
        EXPECT_NEAR(t.a[10], 1.0f - std::pow(0.7f, step), 1e-6f) << step;
    }
}

TEST(TransferFunction, VisibilityRangeQuery) {
    const TransferFunction tf = parseTransferFunctionJson(
        R"({"space":"data","colors":[[0,1,1,1],[100,1,1,1]],"opacity":[[0,0],[40,0],[41,0.5],[60,0.5],[61,0],[100,0]]})",
        "v");
    const TFTable t = buildTable(tf, {0, 0}, 0.5f, 1024);
    EXPECT_FALSE(t.visible(0.0f, 39.5f));
    EXPECT_TRUE(t.visible(0.0f, 45.0f));
    EXPECT_TRUE(t.visible(50.0f, 50.0f));
    EXPECT_FALSE(t.visible(62.0f, 100.0f));
    EXPECT_TRUE(t.visible(-100.0f, 1000.0f));
}

TEST(TransferFunction, ParaViewPreset) {
    const TransferFunction tf = parseTransferFunctionJson(R"([{"ColorSpace":"Diverging","Name":"Cool to Warm",
        "RGBPoints":[-1,0.23,0.299,0.754, 0,0.865,0.865,0.865, 1,0.706,0.016,0.15],
        "Points":[-1,0,0.5,0, 1,0.8,0.5,0]}])",
                                                          "pv.json");
    EXPECT_EQ(tf.name, "Cool to Warm");
    ASSERT_EQ(tf.colors.size(), 3u);
    EXPECT_FLOAT_EQ(tf.colors[1].x, 0.5f);  // rescaled to [0, 1]
    EXPECT_NEAR(tf.alpha(0.5f), 0.4f, 1e-6f);
    // colour map only: a default opacity ramp
    const TransferFunction c =
        parseTransferFunctionJson(R"({"Name":"gray","RGBPoints":[0,0,0,0,255,1,1,1]})", "pv2.json");
    EXPECT_GT(c.alpha(1.0f), 0.0f);
}

TEST(TransferFunction, BadJsonGivesOneLineError) {
    const char* bad[] = {
        "{",                                                            // not JSON
        "[]",                                                           // empty array
        R"({"colors":[[0,1,1,1]]})",                                    // no opacity
        R"({"colors":[[0,1,1]],"opacity":[[0,1]]})",                    // short colour point
        R"({"colors":[[1,1,1,1],[0,1,1,1]],"opacity":[[0,1]]})",        // unsorted
        R"({"colors":[[0,2,1,1]],"opacity":[[0,1]]})",                  // colour out of range
        R"({"colors":[[0,1,1,1]],"opacity":[[0,"a"]]})",                // not a number
        R"({"colors":[[0,1,1,1]],"opacity":[[0,1]],"space":"weird"})",  // bad space
        R"({"RGBPoints":[0,1,1]})",                                     // ParaView, bad length
    };
    for (const char* s : bad) {
        try {
            parseTransferFunctionJson(s, "bad.json");
            ADD_FAILURE() << "accepted: " << s;
        } catch (const Error& e) {
            EXPECT_EQ(e.file(), "bad.json");
            EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
        }
    }
    EXPECT_THROW(loadTransferFunction("/nonexistent/tf.json"), Error);
}

// The sparse tables against brute force: every channel's minimum and maximum over random
// entry ranges (single entries, whole table, power-of-two and odd lengths) of a table with
// noisy channels, and of one whose size is not a power of two.
TEST(TFRangeExtrema, MatchesBruteForce) {
    std::mt19937 rng(12);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int size : {1, 7, 256, 4096}) {
        TFTable t;
        t.size = size;
        for (auto* ch : {&t.r, &t.g, &t.b, &t.a}) {
            ch->resize(size_t(size));
            for (float& x : *ch) x = u(rng);
        }
        const TFRangeExtrema e(t);
        const std::vector<float>* ch[4] = {&t.r, &t.g, &t.b, &t.a};
        for (int it = 0; it < 500; ++it) {
            int i0 = int(rng() % uint32_t(size)), i1 = int(rng() % uint32_t(size));
            if (it == 0) i0 = 0, i1 = size - 1;
            if (i0 > i1) std::swap(i0, i1);
            const TFRangeExtrema::Extrema x = e.range(i0, i1);
            for (size_t c = 0; c < 4; ++c) {
                const auto b = ch[c]->begin();
                ASSERT_EQ(x.lo[c], *std::min_element(b + i0, b + i1 + 1)) << size << " " << i0 << " " << i1;
                ASSERT_EQ(x.hi[c], *std::max_element(b + i0, b + i1 + 1)) << size << " " << i0 << " " << i1;
            }
        }
    }
}
