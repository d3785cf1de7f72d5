// Fuzz input as a file: loaders take paths, so each input is written to a per-process
// temporary file with the extension chosen by the harness.
#pragma once
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

namespace rtfact::fuzz {

inline std::string writeTemp(const uint8_t* data, size_t size, const std::string& ext) {
    const std::string path = "/tmp/rtfact-fuzz-" + std::to_string(getpid()) + ext;
    if (FILE* f = std::fopen(path.c_str(), "wb")) {
        if (size) std::fwrite(data, 1, size, f);
        std::fclose(f);
    }
    return path;
}

}  // namespace rtfact::fuzz
