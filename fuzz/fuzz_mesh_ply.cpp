// libFuzzer harness: our own PLY mesh reader (header and body).
#include <cstddef>
#include <cstdint>

#include "core/util/error.h"
#include "fuzz/fuzz_file_input.h"
#include "surfaces/mesh.h"
#include "surfaces/ply_header.h"

namespace rtfact {
Mesh readPly(const std::string& file, const PlyHeader& h);  // surfaces/ply_reader.cpp
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string path = rtfact::fuzz::writeTemp(data, size, ".ply");
    try {
        const auto header = rtfact::readPlyHeader(path);
        const auto mesh = rtfact::readPly(path, header);
        (void)mesh;
    } catch (const rtfact::Error&) {
    }
    return 0;
}
