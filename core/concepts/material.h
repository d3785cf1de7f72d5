// Material: evaluates and samples a BSDF per lane. Shading frames and directions are
// world space; wo points away from the surface towards the viewer.
#pragma once
#include "core/simd/vec3.h"

namespace rtfact {

template <int N>
struct SurfacePoint {
    Vec3<N> p;       // position
    Vec3<N> n;       // shading normal, facing the incoming ray
    Vec3<N> ng;      // geometric normal, facing the incoming ray
    Packet<N> u, v;  // surface parameterisation
    Vec3<N> color;   // per-element colour (vertex/point colour), white when none
    Packet<N, int32_t> material;
    // Lanes whose ray arrives on the front (outer) side of the surface, as the scene
    // defines it (triangle winding, disc normal); dielectrics enter there and leave
    // elsewhere. Scenes that cannot tell report every hit as entering.
    Mask<N> front = Mask<N>(true);

    // Lane i as a single shading point (materials that run lane by lane).
    SurfacePoint<1> lane(int i) const {
        SurfacePoint<1> s;
        s.p = p.lane(i);
        s.n = n.lane(i);
        s.ng = ng.lane(i);
        s.u = u[i];
        s.v = v[i];
        s.color = color.lane(i);
        s.material = material[i];
        s.front = Mask<1>(front[i]);
        return s;
    }
};

template <int N>
struct BsdfSample {
    Vec3<N> wi;
    Vec3<N> weight;    // f * cos / pdf
    Mask<N> specular;  // delta lobes: no light sampling
    Mask<N> transmit;  // wi continues on the far side of the surface
    Mask<N> valid;
};

// eval returns f * cos(theta_i) for the pair (wo, wi); sample draws wi from two
// uniform numbers.
template <class M>
concept Material = requires(const M& m, const SurfacePoint<1>& s1, const SurfacePoint<simd::kNativeWidth>& sn,
                            const Vec3<1>& w1, const Vec3<simd::kNativeWidth>& wn, const Packet<1>& u1,
                            const Packet<simd::kNativeWidth>& un) {
    { m.template eval<1>(s1, w1, w1) } -> std::same_as<Vec3<1>>;
    { m.template eval<simd::kNativeWidth>(sn, wn, wn) } -> std::same_as<Vec3<simd::kNativeWidth>>;
    { m.template sample<1>(s1, w1, u1, u1) } -> std::same_as<BsdfSample<1>>;
    { m.template sample<simd::kNativeWidth>(sn, wn, un, un) } -> std::same_as<BsdfSample<simd::kNativeWidth>>;
};

}  // namespace rtfact
