// Builder: turns element bounds into a structure; it never sees the elements themselves.
#pragma once
#include <concepts>
#include <span>

#include "core/math/aabb.h"

namespace rtfact {

template <class B, class Structure>
concept Builder = requires(const B& b, std::span<const AABB> bounds, Structure& out) {
    b.build(bounds, out);
};

}  // namespace rtfact
