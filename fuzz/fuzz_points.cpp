// libFuzzer harness: our own point-cloud readers (PLY binary/ASCII, XYZ, PTS). The first
// byte picks the format; the rest is the file. PCD has its own harness (fuzz_pcd).
#include <cstddef>
#include <cstdint>

#include "core/util/error.h"
#include "fuzz/fuzz_file_input.h"
#include "points/point_cloud_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 1) return 0;
    const int kind = data[0] % 3;
    const std::string path = rtfact::fuzz::writeTemp(data + 1, size - 1,
                                                     kind == 0   ? ".ply"
                                                     : kind == 1 ? ".xyz"
                                                                 : ".pts");
    try {
        const auto cloud = kind == 0 ? rtfact::points::loadPly(path) : rtfact::points::loadXyz(path);
        (void)cloud;
    } catch (const rtfact::Error&) {
    }
    return 0;
}
