// Vec3<N>: a structure of three packets (x, y, z) for N rays or points at once.
#pragma once
#include "core/math/vec3f.h"
#include "core/simd/bitmask.h"
#include "core/simd/packet.h"

namespace rtfact::simd {

template <int N>
struct Vec3 {
    using P = Packet<N>;
    static constexpr int W = P::W;
    static constexpr int C = P::C;
    P x, y, z;

    Vec3() = default;
    RTFACT_INLINE Vec3(const P& a, const P& b, const P& c) : x(a), y(b), z(c) {}
    RTFACT_INLINE Vec3(Vec3f v) : x(v.x), y(v.y), z(v.z) {}  // NOLINT: broadcast

    RTFACT_INLINE P& operator[](int a) { return a == 0 ? x : (a == 1 ? y : z); }
    RTFACT_INLINE const P& operator[](int a) const { return a == 0 ? x : (a == 1 ? y : z); }
    RTFACT_INLINE Vec3<W> chunk(int k) const { return {x.chunk(k), y.chunk(k), z.chunk(k)}; }
    RTFACT_INLINE void setChunk(int k, const Vec3<W>& v) {
        x.chunk(k) = v.x;
        y.chunk(k) = v.y;
        z.chunk(k) = v.z;
    }
    RTFACT_INLINE Vec3f lane(int i) const { return {x[i], y[i], z[i]}; }
    RTFACT_INLINE void setLane(int i, Vec3f v) {
        x[i] = v.x;
        y[i] = v.y;
        z[i] = v.z;
    }

    friend RTFACT_INLINE Vec3 operator+(const Vec3& a, const Vec3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
    friend RTFACT_INLINE Vec3 operator-(const Vec3& a, const Vec3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
    friend RTFACT_INLINE Vec3 operator*(const Vec3& a, const Vec3& b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
    friend RTFACT_INLINE Vec3 operator*(const Vec3& a, const P& s) { return {a.x * s, a.y * s, a.z * s}; }
    friend RTFACT_INLINE Vec3 operator*(const P& s, const Vec3& a) { return {a.x * s, a.y * s, a.z * s}; }
    friend RTFACT_INLINE Vec3 operator-(const Vec3& a) { return {-a.x, -a.y, -a.z}; }
    RTFACT_INLINE Vec3& operator+=(const Vec3& b) { return *this = *this + b; }
    RTFACT_INLINE Vec3& operator-=(const Vec3& b) { return *this = *this - b; }
    RTFACT_INLINE Vec3& operator*=(const P& s) { return *this = *this * s; }
};

template <int N>
RTFACT_INLINE Packet<N> dot(const Vec3<N>& a, const Vec3<N>& b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <int N>
RTFACT_INLINE Vec3<N> cross(const Vec3<N>& a, const Vec3<N>& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <int N>
RTFACT_INLINE Packet<N> length(const Vec3<N>& a) {
    return sqrt(dot(a, a));
}
template <int N>
RTFACT_INLINE Vec3<N> normalize(const Vec3<N>& a) {
    return a * (Packet<N>(1.0f) / sqrt(dot(a, a)));
}
template <int N>
RTFACT_INLINE Vec3<N> select(const Mask<N>& m, const Vec3<N>& a, const Vec3<N>& b) {
    return {select(m, a.x, b.x), select(m, a.y, b.y), select(m, a.z, b.z)};
}
template <int N>
RTFACT_INLINE Vec3<N> min(const Vec3<N>& a, const Vec3<N>& b) {
    return {min(a.x, b.x), min(a.y, b.y), min(a.z, b.z)};
}
template <int N>
RTFACT_INLINE Vec3<N> max(const Vec3<N>& a, const Vec3<N>& b) {
    return {max(a.x, b.x), max(a.y, b.y), max(a.z, b.z)};
}

}  // namespace rtfact::simd

namespace rtfact {
using simd::BitMask;
using simd::Mask;
using simd::Packet;
using simd::Vec3;
}  // namespace rtfact
