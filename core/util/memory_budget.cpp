#include "core/util/memory_budget.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "core/util/error.h"

namespace rtfact {

namespace {

uint64_t readCgroupLimit() {
    for (const char* path : {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"}) {
        std::ifstream f(path);
        std::string v;
        if (f >> v && v != "max") {
            try {
                return std::stoull(v);
            } catch (...) {
            }
        }
    }
    return UINT64_MAX;
}

// RTFACT_MEMORY_LIMIT=2G (or 512M, 64K, bytes): a cap chosen by the user, e.g. to keep
// room for other jobs; the tests use it to exercise the checks on small files.
uint64_t readUserLimit() {
    const char* env = std::getenv("RTFACT_MEMORY_LIMIT");
    if (!env || !*env) return UINT64_MAX;
    char* end = nullptr;
    const double v = std::strtod(env, &end);
    double scale = 1;
    switch (*end) {
        case 'k':
        case 'K':
            scale = 1024.0;
            ++end;
            break;
        case 'm':
        case 'M':
            scale = 1024.0 * 1024.0;
            ++end;
            break;
        case 'g':
        case 'G':
            scale = 1024.0 * 1024.0 * 1024.0;
            ++end;
            break;
        case 't':
        case 'T':
            scale = 1024.0 * 1024.0 * 1024.0 * 1024.0;
            ++end;
            break;
        default:
            break;
    }
    if (*end == 'i' || *end == 'B') ++end;  // accept 2GiB / 2GB
    if (*end == 'B') ++end;
    if (end == env || *end != '\0' || !(v > 0) || v * scale > 1.8e19)
        throw Error("RTFACT_MEMORY_LIMIT", std::string("not a size: '") + env + "' (e.g. 512M, 8G)");
    return uint64_t(v * scale);
}

}  // namespace

uint64_t availableMemoryBytes() {
    uint64_t avail = UINT64_MAX;
    std::ifstream f("/proc/meminfo");
    std::string line;
    while (std::getline(f, line)) {
        if (line.rfind("MemAvailable:", 0) == 0) {
            std::istringstream is(line.substr(13));
            uint64_t kb = 0;
            if (is >> kb) avail = kb * 1024ull;
            break;
        }
    }
    const uint64_t limit = std::min(readCgroupLimit(), readUserLimit());
    return avail < limit ? avail : limit;
}

std::string formatBytes(uint64_t bytes) {
    char buf[64];
    const double b = double(bytes);
    if (b >= 1024.0 * 1024.0 * 1024.0)
        std::snprintf(buf, sizeof buf, "%.1f GiB", b / (1024.0 * 1024.0 * 1024.0));
    else if (b >= 1024.0 * 1024.0)
        std::snprintf(buf, sizeof buf, "%.1f MiB", b / (1024.0 * 1024.0));
    else
        std::snprintf(buf, sizeof buf, "%.0f KiB", b / 1024.0);
    return buf;
}

void checkMemory(const std::string& file, uint64_t bytes, const std::string& what, const std::string& hint) {
    const uint64_t avail = availableMemoryBytes();
    // Leave a tenth of what is free for everything else.
    if (avail != UINT64_MAX && bytes > avail - avail / 10) {
        std::string msg =
            "needs " + formatBytes(bytes) + " for " + what + " but only " + formatBytes(avail) + " are available";
        if (!hint.empty()) msg += " (" + hint + ")";
        throw Error(file, msg);
    }
}

}  // namespace rtfact
