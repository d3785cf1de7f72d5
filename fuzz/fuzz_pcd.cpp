// libFuzzer harness: the PCD path end to end. Our header parse and body-size checks run
// first, then PCL's PCDReader reads the body: the harness proves that every input PCL
// would crash or allocate blindly on is rejected before it gets there.
#include <cstddef>
#include <cstdint>

#include "core/util/error.h"
#include "fuzz/fuzz_file_input.h"
#include "points/point_cloud_io.h"
#include "points/point_cloud_io_detail.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string path = rtfact::fuzz::writeTemp(data, size, ".pcd");
    try {
        (void)rtfact::points::probePcd(path);
    } catch (const rtfact::Error&) {
    }
    try {
        const auto cloud = rtfact::points::loadPcd(path);
        (void)cloud;
    } catch (const rtfact::Error&) {
    }
    return 0;
}
