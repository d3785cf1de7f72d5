// Internals shared by the point cloud loaders (not part of the public interface).
#pragma once
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "core/io/mapped_file.h"
#include "core/io/scalar_type.h"
#include "points/point_cloud.h"
#include "points/point_cloud_io.h"

namespace rtfact::points::detail {

using io::MappedFile;
using io::ScalarType;

enum class Attr { None, X, Y, Z, NX, NY, NZ, R, G, B, Radius, Intensity, Count };
Attr attrOf(const std::string& name);
uint8_t colorByte(double v, ScalarType t);

// Decoded points before the finite check and the origin shift.
struct PointSink {
    std::vector<std::array<double, 3>> pos;
    std::vector<Vec3f> nrm;
    std::vector<std::array<uint8_t, 3>> col;
    std::vector<float> rad, inten;
    std::vector<ScalarField> scalars;  // named attributes (scalarAttribute names), sized by reserve()
    // Checks the memory the load needs (core/util/memory_budget.h), then sizes the arrays.
    void reserve(const std::string& file, size_t n, bool normals, bool colors, bool radius, bool intensity);
    // Drops non-finite points, shifts the origin, moves everything into `out`; throws
    // when nothing is left.
    void finish(const std::string& file, PointCloud& out);
};

// Whether a property is kept as a named scalar (PLY scalar_*, class/classification/label).
bool scalarAttribute(const std::string& name);

// Stores one decoded property value of point i (shared by the PLY and PCD readers).
void storeAttr(PointSink& sink, size_t i, Attr a, double x, ScalarType type, bool hasN, bool hasC);

}  // namespace rtfact::points::detail

namespace rtfact::points {
std::optional<PointFileInfo> probePly(const std::string& file);
std::optional<PointFileInfo> probePcd(const std::string& file);
std::optional<PointFileInfo> probeXyz(const std::string& file);
std::optional<PointFileInfo> probeLas(const std::string& file);
}  // namespace rtfact::points
