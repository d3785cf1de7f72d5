// Mesh: an indexed triangle mesh as loaded from a file, with optional per-vertex normals,
// texture coordinates and colours, and per-triangle material ids.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "core/math/aabb.h"

namespace rtfact::surfaces {

// A material as described by an OBJ/MTL file (or defaults for other formats).
struct MeshMaterial {
    std::string name = "default";
    Vec3f kd{0.8f, 0.8f, 0.8f};  // diffuse reflectance
    Vec3f ks{0.0f, 0.0f, 0.0f};  // specular reflectance
    Vec3f ke{0.0f, 0.0f, 0.0f};  // emission
    float ns = 1.0f;             // Phong exponent
    float ior = 1.0f;            // index of refraction (Ni)
    float dissolve = 1.0f;       // opacity (d); < 1 means glass-like
    int illum = 2;
    std::string diffuseMap;  // map_Kd, resolved to a path next to the MTL file
};

struct Mesh {
    std::string source;  // file it came from
    std::vector<Vec3f> positions;
    std::vector<Vec3f> normals;        // per vertex, empty or positions.size()
    std::vector<float> uvs;            // 2 per vertex, empty or 2 * positions.size()
    std::vector<Vec3f> colors;         // per vertex in [0,1], empty or positions.size()
    std::vector<uint32_t> indices;     // 3 per triangle
    std::vector<int32_t> materialIds;  // per triangle, empty or triangles()
    std::vector<MeshMaterial> materials;
    bool normalsComputed = false;  // true when the file had none

    size_t triangles() const { return indices.size() / 3; }
    AABB bounds() const;
    // Area-weighted vertex normals from the faces (used when the file has none).
    void computeNormals();
    // Throws Error(source, ...) on NaN/inf coordinates, out-of-range indices, no triangles.
    void validate() const;
    // Appends another mesh (materials are appended and ids offset).
    void append(const Mesh& other);
};

}  // namespace rtfact::surfaces
