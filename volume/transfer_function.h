// TransferFunction: 1D piecewise-linear colour and opacity over the data value, with
// built-in presets, window/level and JSON import (ParaView colour-map presets and our
// own format). Colours are given in sRGB like ParaView's; the lookup table holds linear
// colour and opacity corrected for the ray-marching step.
#pragma once
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/math/vec3f.h"

namespace rtfact::volume {

struct ColorPoint {
    float x;
    Vec3f rgb;
};
struct OpacityPoint {
    float x, a;
};

struct TransferFunction {
    std::string name;
    // Control points in [0, 1] over the window (normalized) or in data units.
    bool normalized = true;
    std::vector<ColorPoint> colors;
    std::vector<OpacityPoint> opacity;
    // Window of normalized points when the data are in Hounsfield units (CT presets).
    std::optional<std::pair<float, float>> huWindow;

    Vec3f color(float x) const;  // sRGB
    float alpha(float x) const;  // opacity per voxel of distance
    // Throws rtfact::Error(source, ...) when points are missing, unsorted or out of range.
    void validate(const std::string& source) const;
};

std::vector<std::string> transferFunctionPresets();
// Throws rtfact::Error("--tf", ...) for unknown names.
TransferFunction transferFunctionPreset(const std::string& name);
// Our format or a ParaView preset (array or object with RGBPoints / Points).
TransferFunction parseTransferFunctionJson(const std::string& text, const std::string& source);
TransferFunction loadTransferFunction(const std::string& path);
// A preset name or a .json file.
TransferFunction resolveTransferFunction(const std::string& presetOrFile);

// The data-value window [lo, hi] a TF applies to: --window/--level if given, else the
// preset's Hounsfield window for CT-like data (values below -500), else the data range.
std::pair<float, float> resolveWindow(const TransferFunction& tf, float dataLo, float dataHi,
                                      std::optional<float> window, std::optional<float> level);

// Lookup table: entry i is the TF at data value lo + i * (hi - lo) / (size - 1), colours
// linear, opacity corrected for a step of `stepVoxels` voxels: 1 - (1 - a)^step.
struct TFTable {
    float lo = 0, hi = 1;
    int size = 0;
    std::vector<float> r, g, b, a;
    std::vector<int32_t> visiblePrefix;  // count of entries with a > 0 in [0, i)
    // Index of data value v (nearest entry, clamped).
    int index(float v) const;
    // Any visible entry for data values in [vlo, vhi]?
    bool visible(float vlo, float vhi) const;
};
TFTable buildTable(const TransferFunction& tf, std::pair<float, float> window, float stepVoxels, int size = 4096);

}  // namespace rtfact::volume
