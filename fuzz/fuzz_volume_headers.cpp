// libFuzzer harness: our own volume readers (MetaImage, NRRD, NIfTI, raw). The first
// byte picks the format; the rest is the file. The readers are called directly (the
// VTK/OpenVDB/DICOM loaders behind loadVolume are not part of the fuzz build).
#include <cstddef>
#include <cstdint>

#include "core/util/error.h"
#include "fuzz/fuzz_file_input.h"
#include "volume/volume_io_detail.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 1) return 0;
    using namespace rtfact::volume;
    static const char* exts[] = {".mhd", ".nhdr", ".nrrd", ".nii", "_8x8x8_uint8.raw", ".mha"};
    const int kind = data[0] % 6;
    const std::string path = rtfact::fuzz::writeTemp(data + 1, size - 1, exts[kind]);
    try {
        const VolumeLoadOptions o;
        const VolumeGrid g = kind == 0 || kind == 5   ? loadMetaImage(path, o)
                             : kind == 1 || kind == 2 ? loadNrrd(path, o)
                             : kind == 3              ? loadNifti(path, o)
                                                      : loadRaw(path, rawOptionsFromName(path, o));
        (void)g;
    } catch (const rtfact::Error&) {
    }
    return 0;
}
