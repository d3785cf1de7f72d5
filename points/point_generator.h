// Samples a triangle mesh into a point cloud of any size (uniform by area, face
// normals, one radius chosen so that the random discs cover the surface), so that 1M to
// 32M point versions of the same real object can be made on any machine.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "points/point_cloud.h"

namespace rtfact::points {

// The generator's input: vertices and triangles (the app loads any mesh file through
// the engine; points never reads meshes itself).
struct TriangleMesh {
    std::vector<Vec3f> vertices;
    std::vector<std::array<uint32_t, 3>> triangles;
};

// radiusFactor scales the radius of a disc of area (mesh area / count): 2.2 leaves
// about 1% of the surface uncovered by the random discs.
PointCloud samplePointsOnMesh(const TriangleMesh& mesh, size_t count, uint64_t seed = 1, float radiusFactor = 2.2f);

}  // namespace rtfact::points
