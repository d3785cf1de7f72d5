// Axis-aligned bounding box: what every acceleration structure builder works on.
#pragma once
#include <limits>

#include "core/math/vec3f.h"

namespace rtfact {

struct AABB {
    Vec3f lo{std::numeric_limits<float>::infinity()};
    Vec3f hi{-std::numeric_limits<float>::infinity()};

    static AABB empty() { return {}; }
    AABB& extend(Vec3f p) {
        lo = vmin(lo, p);
        hi = vmax(hi, p);
        return *this;
    }
    AABB& extend(const AABB& b) {
        lo = vmin(lo, b.lo);
        hi = vmax(hi, b.hi);
        return *this;
    }
    bool isEmpty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
    Vec3f extent() const { return hi - lo; }
    Vec3f center() const { return (lo + hi) * 0.5f; }
    float surfaceArea() const {
        if (isEmpty()) return 0.0f;
        const Vec3f d = extent();
        return 2.0f * (d.x * d.y + d.y * d.z + d.z * d.x);
    }
    int maxAxis() const {
        const Vec3f d = extent();
        return d.x >= d.y && d.x >= d.z ? 0 : (d.y >= d.z ? 1 : 2);
    }
    bool contains(const AABB& b, float eps = 0.0f) const {
        return b.lo.x >= lo.x - eps && b.lo.y >= lo.y - eps && b.lo.z >= lo.z - eps && b.hi.x <= hi.x + eps &&
               b.hi.y <= hi.y + eps && b.hi.z <= hi.z + eps;
    }
    bool contains(Vec3f p) const {
        return p.x >= lo.x && p.y >= lo.y && p.z >= lo.z && p.x <= hi.x && p.y <= hi.y && p.z <= hi.z;
    }
    friend AABB merge(AABB a, const AABB& b) { return a.extend(b); }
    friend AABB intersection(const AABB& a, const AABB& b) { return {vmax(a.lo, b.lo), vmin(a.hi, b.hi)}; }
};

}  // namespace rtfact
