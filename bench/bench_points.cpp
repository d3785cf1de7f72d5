// rtfact-bench points: placeholder until its issue lands.
#include <cstdio>

#include "bench/bench_commands.h"

namespace rtfact::bench {

int benchPoints(int, char**) {
    std::fprintf(stderr, "rtfact-bench: points benchmark not built yet\n");
    return 2;
}

}  // namespace rtfact::bench
