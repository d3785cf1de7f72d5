// Colouring a cloud by what it carries: file colours, elevation, intensity, ASPRS
// classification, return number, or any named scalar (LAS extra bytes, PLY scalar_*,
// PCD label ...) through a perceptual colormap over a robust (percentile) range.
#pragma once
#include <array>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/math/vec3f.h"
#include "points/point_cloud.h"

namespace rtfact::points {

// Auto: Rgb when the file has real colours, else Elevation. Lod and Normal are computed
// at shading time (the discs stay white).
enum class ColorMode { Auto, Rgb, Elevation, Intensity, Classification, Return, Attribute, Lod, Normal };

struct ColorOptions {
    ColorMode mode = ColorMode::Auto;
    std::string attribute;                      // Attribute: the scalar's name
    std::string colormap;                       // empty: viridis (grayscale for intensity)
    std::optional<std::array<float, 2>> range;  // none: 2nd to 98th percentile
};

// "rgb", "elevation", ..., "attr:NAME"; throws Error("--color", ...) on others.
ColorOptions parseColorOptions(const std::string& s);
// The names --color accepts (attr:NAME aside) and --colormap accepts.
const std::vector<std::string>& colorModeNames();
// The name parseColorOptions reads back as `mode` ("attr" for Attribute: add ":NAME").
std::string colorModeName(ColorMode mode);
const std::vector<std::string>& colormapNames();

// A colormap at t in [0, 1] (clamped), linear RGB; throws Error("--colormap", ...) on an
// unknown name.
Vec3f colormap(const std::string& name, float t);
// The ASPRS standard class colours (LAS 1.4 table of classes), linear RGB.
Vec3f classificationColor(int cls);
// 2nd and 98th percentile of the finite values (a sample of at most 1M of them): a range
// that outliers (noise points, birds, no-data values) do not stretch.
std::array<float, 2> robustRange(std::span<const float> values);

// The mode Auto stands for with this cloud.
ColorMode resolveColorMode(const PointCloud& cloud, ColorMode mode);
// One linear RGB colour per point; throws Error(source, ...) when the cloud lacks what the
// mode colours by (e.g. classification of a PLY without a class field).
std::vector<Vec3f> pointColors(const PointCloud& cloud, const ColorOptions& opt, const std::string& source = "");

}  // namespace rtfact::points
