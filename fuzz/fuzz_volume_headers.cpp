// libFuzzer harness: our own volume readers (MetaImage, NRRD, NIfTI, raw). The first
// byte picks the format; the rest is the file. VTK/OpenVDB-backed readers are stubbed.
#include <cstddef>
#include <cstdint>

#include "core/util/error.h"
#include "fuzz/fuzz_file_input.h"
#include "volume/volume_io.h"

namespace rtfact::volume {
VolumeGrid loadDicomSeries(const std::string& dir, const VolumeLoadOptions&) { throw Error(dir, "stub"); }
VolumeGrid loadVTI(const std::string& path, const VolumeLoadOptions&) { throw Error(path, "stub"); }
VolumeGrid loadVDB(const std::string& path, const VolumeLoadOptions&) { throw Error(path, "stub"); }
BrickedVolume loadVDBBricked(const std::string& path, const VolumeLoadOptions&) { throw Error(path, "stub"); }
}  // namespace rtfact::volume

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 1) return 0;
    static const char* exts[] = {".mhd", ".nhdr", ".nrrd", ".nii", "_8x8x8_uint8.raw", ".mha"};
    const std::string path = rtfact::fuzz::writeTemp(data + 1, size - 1, exts[data[0] % 6]);
    try {
        const auto g = rtfact::volume::loadVolume(path, {});
        (void)g;
    } catch (const rtfact::Error&) {
    }
    return 0;
}
