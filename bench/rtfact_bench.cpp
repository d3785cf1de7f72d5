// rtfact-bench mesh|points|volume|load FILE [options]: RTfact against its peer in one process.
#include <cstdio>
#include <cstring>
#include <exception>

#include "bench/bench_commands.h"
#include "core/util/error.h"

int main(int argc, char** argv) {
    using namespace rtfact::bench;
    if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h")) {
        std::printf(
            "usage: rtfact-bench mesh|points|volume|view|load FILE [options] | python [options]   (rtfact-bench CMD "
            "--help)\n");
        return argc < 2 ? 2 : 0;
    }
    try {
        if (!std::strcmp(argv[1], "mesh")) return benchMesh(argc - 1, argv + 1);
        if (!std::strcmp(argv[1], "points")) return benchPoints(argc - 1, argv + 1);
        if (!std::strcmp(argv[1], "volume")) return benchVolume(argc - 1, argv + 1);
        if (!std::strcmp(argv[1], "python")) return benchPython(argc - 1, argv + 1);
        if (!std::strcmp(argv[1], "view")) return benchView(argc - 1, argv + 1);
        if (!std::strcmp(argv[1], "load")) return benchLoad(argc - 1, argv + 1);
#ifdef RTFACT_BENCH_MPI
        if (!std::strcmp(argv[1], "mpi")) return benchMpi(argc - 1, argv + 1);
#endif
    } catch (const rtfact::Error& e) {
        std::fprintf(stderr, "rtfact-bench: error: %s\n", e.message().c_str());
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "rtfact-bench: error: %s\n", e.what());
        return 1;
    }
    std::fprintf(stderr, "rtfact-bench: error: unknown benchmark '%s' (mesh, points, volume, view, load, python)\n",
                 argv[1]);
    return 2;
}
