// rtfact-bench python [options]: runs bench/bench_python.py (the Python module against
// the CLI, and the zero-copy check) on the Python and module this build made.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench/bench_commands.h"

namespace rtfact::bench {

int benchPython(int argc, char** argv) {
#ifdef RTFACT_BENCH_PYTHON
    std::string path = RTFACT_BENCH_PYTHONPATH;
    if (const char* old = std::getenv("PYTHONPATH"); old && *old) path += std::string(":") + old;
    setenv("PYTHONPATH", path.c_str(), 1);
    setenv("RTFACT_CLI", RTFACT_BENCH_CLI, 0);
    std::vector<char*> args{const_cast<char*>(RTFACT_BENCH_PYTHON), const_cast<char*>(RTFACT_BENCH_PYTHON_SCRIPT)};
    for (int i = 1; i < argc; ++i) args.push_back(argv[i]);
    args.push_back(nullptr);
    std::fflush(stdout);
    execv(args[0], args.data());
    std::perror("rtfact-bench: error: python: cannot run " RTFACT_BENCH_PYTHON);
    return 1;
#else
    (void)argc;
    (void)argv;
    std::fprintf(stderr, "rtfact-bench: error: python: this build has no Python module (RTFACT_PYTHON=OFF)\n");
    return 1;
#endif
}

}  // namespace rtfact::bench
