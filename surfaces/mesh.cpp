#include "surfaces/mesh.h"

#include <cmath>

#include "core/util/error.h"

namespace rtfact::surfaces {

AABB Mesh::bounds() const {
    AABB b;
    for (const Vec3f& p : positions) b.extend(p);
    return b;
}

void Mesh::computeNormals() {
    normals.assign(positions.size(), Vec3f(0.0f));
    for (size_t t = 0; t < triangles(); ++t) {
        const uint32_t a = indices[3 * t], b = indices[3 * t + 1], c = indices[3 * t + 2];
        // The unnormalised cross product weights each face by its area.
        const Vec3f n = cross(positions[b] - positions[a], positions[c] - positions[a]);
        normals[a] += n;
        normals[b] += n;
        normals[c] += n;
    }
    for (Vec3f& n : normals) {
        const float l = length(n);
        n = l > 0.0f ? n / l : Vec3f(0.0f, 0.0f, 1.0f);
    }
    normalsComputed = true;
}

void Mesh::validate() const {
    if (positions.empty()) throw Error(source, "mesh has no vertices");
    if (indices.empty()) throw Error(source, "mesh has no triangles");
    if (indices.size() % 3) throw Error(source, "index count is not a multiple of 3");
    for (const Vec3f& p : positions)
        if (!isFinite(p)) throw Error(source, "vertex coordinate is NaN or infinite");
    const uint32_t nv = uint32_t(positions.size());
    for (uint32_t i : indices)
        if (i >= nv) throw Error(source, "face refers to vertex " + std::to_string(i) + " of " + std::to_string(nv));
    if (!normals.empty() && normals.size() != positions.size())
        throw Error(source, "normal count differs from vertex count");
    if (!uvs.empty() && uvs.size() != 2 * positions.size()) throw Error(source, "uv count differs from vertex count");
    if (!colors.empty() && colors.size() != positions.size())
        throw Error(source, "colour count differs from vertex count");
    if (!materialIds.empty()) {
        if (materialIds.size() != triangles()) throw Error(source, "material id count differs from triangle count");
        for (int32_t m : materialIds)
            if (m < 0 || size_t(m) >= materials.size()) throw Error(source, "material id out of range");
    }
}

void Mesh::append(const Mesh& o) {
    if (positions.empty()) {
        *this = o;
        return;
    }
    Mesh rhs = o;
    // Attributes present in only one part are filled with neutral values.
    if (!normals.empty() || !rhs.normals.empty()) {
        if (normals.empty()) computeNormals();
        if (rhs.normals.empty()) rhs.computeNormals();
    }
    if (!uvs.empty() || !rhs.uvs.empty()) {
        if (uvs.empty()) uvs.assign(2 * positions.size(), 0.0f);
        if (rhs.uvs.empty()) rhs.uvs.assign(2 * rhs.positions.size(), 0.0f);
    }
    if (!colors.empty() || !rhs.colors.empty()) {
        if (colors.empty()) colors.assign(positions.size(), Vec3f(1.0f));
        if (rhs.colors.empty()) rhs.colors.assign(rhs.positions.size(), Vec3f(1.0f));
    }
    for (Mesh* m : {this, &rhs}) {
        if (m->materials.empty()) m->materials.push_back({});
        if (m->materialIds.empty()) m->materialIds.assign(m->triangles(), 0);
    }
    const uint32_t base = uint32_t(positions.size());
    const int32_t matBase = int32_t(materials.size());
    materials.insert(materials.end(), rhs.materials.begin(), rhs.materials.end());
    for (int32_t m : rhs.materialIds) materialIds.push_back(m + matBase);
    positions.insert(positions.end(), rhs.positions.begin(), rhs.positions.end());
    normals.insert(normals.end(), rhs.normals.begin(), rhs.normals.end());
    uvs.insert(uvs.end(), rhs.uvs.begin(), rhs.uvs.end());
    colors.insert(colors.end(), rhs.colors.begin(), rhs.colors.end());
    for (uint32_t i : rhs.indices) indices.push_back(i + base);
    normalsComputed = normalsComputed || rhs.normalsComputed;
}

}  // namespace rtfact::surfaces
