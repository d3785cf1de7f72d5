// libFuzzer harness: the PCD path end to end (header checks, then our ascii / binary / LZF
// body decoder). It first ran PCL's PCDReader after our checks and found three inputs that
// crashed PCL; PCD bodies are now decoded by us.
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
