// PathMaterial: the material kinds the Whitted and path integrators tell apart per
// material id (Lambert, mirror, glass, each optionally emitting), resolved once from
// MTL-style data (kd, ks, Ke, Ni, d, illum), and the material models they stand for.
#pragma once
#include <concepts>
#include <cstdint>
#include <iterator>
#include <type_traits>
#include <vector>

#include "core/render/materials/emissive_material.h"
#include "core/render/materials/glass_material.h"
#include "core/render/materials/lambert_material.h"
#include "core/render/materials/mirror_material.h"

namespace rtfact {

// Wavefront MTL parameters, as a mesh loader keeps them.
template <class M>
concept MtlStyleMaterial = requires(const M& m) {
    { m.kd } -> std::convertible_to<Vec3f>;
    { m.ks } -> std::convertible_to<Vec3f>;
    { m.ke } -> std::convertible_to<Vec3f>;
    { m.ior } -> std::convertible_to<float>;
    { m.dissolve } -> std::convertible_to<float>;
    { m.illum } -> std::convertible_to<int>;
};

struct PathMaterial {
    enum Kind : int32_t { Lambert, Mirror, Glass } kind = Lambert;
    Vec3f albedo{0.8f};
    Vec3f emission{0.0f};
    float ior = 1.5f;

    MirrorMaterial mirror() const { return {albedo}; }
    GlassMaterial glass() const { return {albedo, ior}; }
    EmissiveMaterial emissive() const { return {emission}; }

    template <MtlStyleMaterial M>
    static PathMaterial from(const M& m) {
        PathMaterial p;
        p.emission = m.ke;
        p.ior = m.ior > 1.0f ? m.ior : 1.5f;
        if (m.dissolve < 1.0f || m.illum == 7 || m.illum == 4 || m.illum == 6) {
            p.kind = Glass;
            p.albedo = Vec3f(1.0f);
        } else if (m.illum == 3 || m.illum == 5) {
            p.kind = Mirror;
            p.albedo = maxComponent(m.ks) > 0.0f ? m.ks : Vec3f(1.0f);
        } else {
            p.albedo = m.kd;
        }
        return p;
    }
};

// The material of an id; ids out of range (and an empty table) get the default Lambert.
inline const PathMaterial& pathMaterialOf(const std::vector<PathMaterial>& table, int32_t id) {
    static const PathMaterial kDefault{};
    return table.empty() || id < 0 || size_t(id) >= table.size() ? kDefault : table[size_t(id)];
}

// One PathMaterial per material of a mesh (anything with MTL-style `materials`).
template <class MeshLike>
requires requires(const MeshLike& m) {
    requires MtlStyleMaterial<std::remove_cvref_t<decltype(*std::begin(m.materials))>>;
}
std::vector<PathMaterial> pathMaterials(const MeshLike& m) {
    std::vector<PathMaterial> r;
    for (const auto& mm : m.materials) r.push_back(PathMaterial::from(mm));
    return r;
}

}  // namespace rtfact
