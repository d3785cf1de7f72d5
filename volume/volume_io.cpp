// Loading volumes: the dispatch by path to the format readers (raw, MetaImage, NRRD and
// NIfTI are our own, volume_io_*.cpp; VTK and OpenVDB only behind volume_io_vtk.cpp and
// volume_io_vdb.cpp; DICOM in dicom_modality.cpp).
#include "volume/volume_io.h"

#include <filesystem>

#include "core/io/file_helpers.h"
#include "core/util/error.h"
#include "core/util/input_file.h"
#include "volume/volume_io_detail.h"

namespace fs = std::filesystem;

namespace rtfact::volume {

using io::endsWith;
using io::lower;

bool looksLikeVolume(const std::string& path) {
    std::error_code ec;
    if (fs::is_directory(path, ec)) {
        for (auto& e : fs::directory_iterator(path, ec)) {
            const std::string x = lower(e.path().extension().string());
            if (x == ".dcm" || x == ".ima") return true;
        }
        return false;
    }
    const std::string p = lower(path);
    for (const char* e : {".raw", ".mhd", ".mha", ".nrrd", ".nhdr", ".nii", ".nii.gz", ".vdb"})
        if (endsWith(p, e)) return true;
    if (endsWith(p, ".vti")) return true;
    return false;
}

VolumeGrid loadVolume(const std::string& path, const VolumeLoadOptions& opt) {
    const bool dir = requireFileOrDirectory(path);  // before any reader opens it: a FIFO would block
    const std::string p = lower(path);
    VolumeGrid g;
    if (dir)
        g = loadDicomSeries(path, opt);
    else if (opt.dims || !opt.type.empty())
        g = loadRaw(path, opt);
    else if (endsWith(p, ".mhd") || endsWith(p, ".mha"))
        g = loadMetaImage(path, opt);
    else if (endsWith(p, ".nrrd") || endsWith(p, ".nhdr"))
        g = loadNrrd(path, opt);
    else if (endsWith(p, ".nii") || endsWith(p, ".nii.gz"))
        g = loadNifti(path, opt);
    else if (endsWith(p, ".vti"))
        g = loadVTI(path, opt);
    else if (endsWith(p, ".vdb"))
        g = loadVDB(path, opt);
    else if (endsWith(p, ".raw"))
        g = loadRaw(path, rawOptionsFromName(path, opt));
    else
        throw Error(path, "unknown volume format (raw needs --dims and --type)");
    if (opt.spacing) g.spacing = *opt.spacing;
    return g;
}

BrickedVolume loadBrickedVolume(const std::string& path, const VolumeLoadOptions& opt) {
    const bool dir = requireFileOrDirectory(path);
    if (!dir && endsWith(lower(path), ".vdb") && !opt.dims) {
        BrickedVolume v = loadVDBBricked(path, opt);
        if (opt.spacing) v.spacing = *opt.spacing;
        return v;
    }
    VolumeGrid g = loadVolume(path, opt);
    try {
        return brickVolume(g, true);
    } catch (const Error& e) {
        throw Error(path, e.what());
    }
}

}  // namespace rtfact::volume
