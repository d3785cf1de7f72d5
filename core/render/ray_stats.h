// Per-thread count of rays traced; the tile scheduler sums it over a frame.
#pragma once
#include <cstdint>

namespace rtfact {

inline thread_local uint64_t tlsRaysTraced = 0;

}  // namespace rtfact
