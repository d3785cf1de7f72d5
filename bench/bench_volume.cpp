// rtfact-bench volume: placeholder until its issue lands.
#include <cstdio>

#include "bench/bench_commands.h"

namespace rtfact::bench {

int benchVolume(int, char**) {
    std::fprintf(stderr, "rtfact-bench: volume benchmark not built yet\n");
    return 2;
}

}  // namespace rtfact::bench
