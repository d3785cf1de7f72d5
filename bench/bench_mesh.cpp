// rtfact-bench mesh: placeholder until its issue lands.
#include <cstdio>

#include "bench/bench_commands.h"

namespace rtfact::bench {

int benchMesh(int, char**) {
    std::fprintf(stderr, "rtfact-bench: mesh benchmark not built yet\n");
    return 2;
}

}  // namespace rtfact::bench
