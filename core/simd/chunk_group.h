// chunkGroup<M>(p, k): native chunks k .. k + M / W - 1 of a packet, mask or vector of
// packets as one M-lane value, in place (a reference; vectors by value). Kernels that
// work on several chunks of a packet at once (a volume march group, an LoD traversal
// group) use it to run one M-wide code path over those lanes.
#pragma once
#include "core/simd/vec3.h"

namespace rtfact::simd {

template <int M, int N, class T>
concept ChunkGroupOf = M <= N&& M % Packet<N, T>::W == 0 && chunkWidth(M) == Packet<N, T>::W;
static_assert(ChunkGroupOf<2 * kNativeWidth, 4 * kNativeWidth, float>);
static_assert(!ChunkGroupOf<kNativeWidth, 1, float>);

template <int M, int N, class T>
requires ChunkGroupOf<M, N, T> RTFACT_INLINE Packet<M, T>
&chunkGroup(Packet<N, T>& p, int k) { return *reinterpret_cast<Packet<M, T>*>(&p.c[k]); }
template <int M, int N, class T>
requires ChunkGroupOf<M, N, T> RTFACT_INLINE const Packet<M, T>& chunkGroup(const Packet<N, T>& p, int k) {
    return *reinterpret_cast<const Packet<M, T>*>(&p.c[k]);
}
template <int M, int N>
requires ChunkGroupOf<M, N, float> RTFACT_INLINE const Mask<M>& chunkGroup(const Mask<N>& m, int k) {
    return *reinterpret_cast<const Mask<M>*>(&m.c[k]);
}
template <int M, int N>
requires ChunkGroupOf<M, N, float> RTFACT_INLINE Vec3<M> chunkGroup(const Vec3<N>& v, int k) {
    return {chunkGroup<M>(v.x, k), chunkGroup<M>(v.y, k), chunkGroup<M>(v.z, k)};
}

}  // namespace rtfact::simd

namespace rtfact {
using simd::chunkGroup;
}  // namespace rtfact
