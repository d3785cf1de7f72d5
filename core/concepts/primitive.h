// Primitive: anything with bounds can live in an acceleration structure.
#pragma once
#include <concepts>

#include "core/math/aabb.h"

namespace rtfact {

template <class P>
concept Primitive = requires(const P& p) {
    { p.bounds() } -> std::convertible_to<AABB>;
};

}  // namespace rtfact
