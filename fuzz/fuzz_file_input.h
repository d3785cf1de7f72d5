// Fuzz input as a file: loaders take paths, so each input is written to a per-process
// temporary file with the extension chosen by the harness (removed when the process exits).
#pragma once
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <set>
#include <string>

namespace rtfact::fuzz {

struct TempFiles {
    std::set<std::string> paths;
    ~TempFiles() {
        for (const std::string& p : paths) std::remove(p.c_str());
    }
};

inline std::string writeTemp(const uint8_t* data, size_t size, const std::string& ext) {
    static TempFiles written;
    const std::string path = "/tmp/rtfact-fuzz-" + std::to_string(getpid()) + ext;
    written.paths.insert(path);
    if (FILE* f = std::fopen(path.c_str(), "wb")) {
        if (size) std::fwrite(data, 1, size, f);
        std::fclose(f);
    }
    return path;
}

}  // namespace rtfact::fuzz
