// PointCloud: what the loaders produce and the preparation step completes. Plain
// arrays (structure of arrays) so that PCL stays out of every header but a few .cpp.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/math/aabb.h"

namespace rtfact::points {

// A named per-point scalar the colouring can map (LAS extra bytes and GPS time, PLY
// scalar_*, PCD label ...): value i is offset + values[i] (the offset keeps large values
// such as GPS seconds precise in float).
struct ScalarField {
    std::string name;
    std::vector<float> values;
    double offset = 0;
};

struct PointCloud {
    std::vector<Vec3f> positions;
    std::vector<Vec3f> normals;                  // empty: none in the file
    std::vector<std::array<uint8_t, 3>> colors;  // empty: none
    std::vector<float> radii;                    // empty: none
    std::vector<float> intensities;              // empty: none
    std::vector<uint8_t> classes;                // ASPRS classification; empty: none
    std::vector<uint8_t> returnNumbers;          // 1-based return number; empty: none
    std::vector<uint8_t> returnCounts;           // number of returns of the pulse; empty: none
    std::vector<ScalarField> scalars;            // further named attributes
    std::string crs;                             // coordinate reference system as text (WKT, GeoTIFF keys); empty: none
    std::array<double, 3> origin{0, 0, 0};       // subtracted (in double) from the file's coordinates
    Vec3f viewpoint{0, 0, 0};                    // sensor position (PCD VIEWPOINT), after the shift
    bool hasViewpoint = false;
    size_t droppedNonFinite = 0;          // points with NaN/inf (or beyond 1e18) coordinates dropped on load
    std::string format;                   // e.g. "ply binary_little_endian"
    std::vector<std::string> properties;  // property names found in the file

    size_t size() const { return positions.size(); }
    const ScalarField* scalar(const std::string& name) const {
        for (const ScalarField& f : scalars)
            if (f.name == name) return &f;
        return nullptr;
    }
    AABB bounds() const {
        AABB b;
        for (const Vec3f& p : positions) b.extend(p);
        return b;
    }
};

}  // namespace rtfact::points
