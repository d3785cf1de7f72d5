// The lights of a scene; the light kind is chosen per light at run time (coarse
// granularity), everything below it is compiled per kind.
#pragma once
#include <variant>
#include <vector>

#include "core/render/directional_light.h"
#include "core/render/point_light.h"

namespace rtfact {

using AnyLight = std::variant<PointLight, DirectionalLight>;
using LightList = std::vector<AnyLight>;

template <int N>
LightSample<N> sampleLight(const AnyLight& l, const Vec3<N>& p, const Packet<N>& u, const Packet<N>& v) {
    return std::visit([&](const auto& light) { return light.template sample<N>(p, u, v); }, l);
}

}  // namespace rtfact
