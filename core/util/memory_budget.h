// Memory the machine can give us, checked before large allocations so that an absurd
// request ends in a clear error naming the option that would help, not in the OOM killer.
#pragma once
#include <cstdint>
#include <string>

namespace rtfact {

// Bytes available to this process: MemAvailable, capped by a cgroup limit and by the
// environment variable RTFACT_MEMORY_LIMIT (e.g. 8G) if set.
uint64_t availableMemoryBytes();

// Throws rtfact::Error(file, ...) when `bytes` exceeds what is available (with a margin),
// e.g. "needs 37.2 GiB for the dense grid but 21.0 GiB are available (try --lod)".
void checkMemory(const std::string& file, uint64_t bytes, const std::string& what, const std::string& hint = "");

// "1.5 GiB", "320 MiB", ...
std::string formatBytes(uint64_t bytes);

}  // namespace rtfact
