// libFuzzer harness: the LAS reader end to end (header, VLRs/EVLRs, Extra Bytes
// descriptors, CRS text, record decoding, the summary of `rtfact info`). LAZ input stops
// at the LAZ decoder, which has its own harness.
#include <cstddef>
#include <cstdint>

#include "core/util/error.h"
#include "fuzz/fuzz_file_input.h"
#include "points/las_io.h"
#include "points/point_cloud_io.h"
#include "points/point_cloud_io_detail.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string path = rtfact::fuzz::writeTemp(data, size, ".las");
    try {
        (void)rtfact::points::probeLas(path);
    } catch (const rtfact::Error&) {
    }
    try {
        (void)rtfact::points::las::summarize(path);
    } catch (const rtfact::Error&) {
    }
    try {
        rtfact::points::LoadFilter f;
        f.returns = rtfact::points::LoadFilter::Returns::Last;
        const auto cloud = rtfact::points::loadLas(path, f, 1);
        (void)cloud;
    } catch (const rtfact::Error&) {
    }
    return 0;
}
