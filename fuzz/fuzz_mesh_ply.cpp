// libFuzzer harness: our own PLY mesh reader (header and body).
#include <cstddef>
#include <cstdint>

#include "core/io/mapped_file.h"
#include "core/io/ply_header.h"
#include "core/util/error.h"
#include "fuzz/fuzz_file_input.h"
#include "surfaces/ply_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string path = rtfact::fuzz::writeTemp(data, size, ".ply");
    try {
        const rtfact::io::MappedFile f(path);
        const auto header = rtfact::io::readPlyHeader(f);
        const auto mesh = rtfact::surfaces::readPly(f, header);
        (void)mesh;
    } catch (const rtfact::Error&) {
    }
    return 0;
}
