// Run-time packet size -> compile-time instantiation. The sizes compiled are 1, the
// small SIMD widths and the coherent-packet sizes 16, 64 and 256.
#pragma once
#include <string>

#include "core/simd/packet.h"

namespace rtfact {

inline constexpr int kPacketSizes[] = {1, 4, 8, 16, 64, 256};

inline std::string supportedPacketSizes() {
    std::string s;
    for (int n : kPacketSizes) {
        const int w = simd::chunkWidth(n);
        if (!simd::widthSupported(w) || n % w != 0) continue;
        if (!s.empty()) s += ", ";
        s += std::to_string(n);
    }
    return s;
}

// Calls f.template operator()<N>() for the packet size n; false if n is not compiled.
template <class F>
bool dispatchPacketSize(int n, F&& f) {
    bool done = false;
    auto one = [&]<int N>() {
        if constexpr (simd::ValidPacketSize<N>) {
            if (n == N) {
                f.template operator()<N>();
                done = true;
            }
        }
    };
    one.template operator()<1>();
    one.template operator()<4>();
    one.template operator()<8>();
    one.template operator()<16>();
    one.template operator()<64>();
    one.template operator()<256>();
    return done;
}

}  // namespace rtfact
