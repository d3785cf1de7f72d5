// Plain scalar 3-vector for scene data (vertices, bounds, camera parameters).
#pragma once
#include <algorithm>
#include <cmath>

namespace rtfact {

struct Vec3f {
    float x = 0, y = 0, z = 0;

    constexpr Vec3f() = default;
    constexpr Vec3f(float a, float b, float c) : x(a), y(b), z(c) {}
    constexpr explicit Vec3f(float s) : x(s), y(s), z(s) {}

    constexpr float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
    constexpr float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }

    friend constexpr Vec3f operator+(Vec3f a, Vec3f b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
    friend constexpr Vec3f operator-(Vec3f a, Vec3f b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
    friend constexpr Vec3f operator*(Vec3f a, Vec3f b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
    friend constexpr Vec3f operator/(Vec3f a, Vec3f b) { return {a.x / b.x, a.y / b.y, a.z / b.z}; }
    friend constexpr Vec3f operator*(Vec3f a, float s) { return {a.x * s, a.y * s, a.z * s}; }
    friend constexpr Vec3f operator*(float s, Vec3f a) { return {a.x * s, a.y * s, a.z * s}; }
    friend constexpr Vec3f operator/(Vec3f a, float s) { return a * (1.0f / s); }
    friend constexpr Vec3f operator-(Vec3f a) { return {-a.x, -a.y, -a.z}; }
    constexpr Vec3f& operator+=(Vec3f b) { return *this = *this + b; }
    constexpr Vec3f& operator-=(Vec3f b) { return *this = *this - b; }
    constexpr Vec3f& operator*=(float s) { return *this = *this * s; }
    friend constexpr bool operator==(Vec3f a, Vec3f b) { return a.x == b.x && a.y == b.y && a.z == b.z; }
};

constexpr float dot(Vec3f a, Vec3f b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
constexpr Vec3f cross(Vec3f a, Vec3f b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float length(Vec3f a) { return std::sqrt(dot(a, a)); }
inline Vec3f normalize(Vec3f a) {
    const float l = length(a);
    return l > 0 ? a / l : a;
}
constexpr Vec3f vmin(Vec3f a, Vec3f b) { return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)}; }
constexpr Vec3f vmax(Vec3f a, Vec3f b) { return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)}; }
constexpr float maxComponent(Vec3f a) { return std::max(a.x, std::max(a.y, a.z)); }
constexpr float minComponent(Vec3f a) { return std::min(a.x, std::min(a.y, a.z)); }
inline bool isFinite(Vec3f a) { return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z); }

}  // namespace rtfact
