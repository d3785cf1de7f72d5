// DICOM series and VTK XML image data through VTK's readers. VTK headers stay in this
// file. Inputs are checked first (a directory of .dcm files; a .vti whose XML header
// declares ImageData with a sane extent) because the readers allocate what files claim.
#include <vtkDICOMImageReader.h>
#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkXMLImageDataReader.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <utility>
#include <vector>

#include "core/util/error.h"
#include "core/util/input_file.h"
#include "core/util/vtk_quiet.h"
#include "volume/dicom_modality.h"
#include "volume/volume_io.h"

namespace fs = std::filesystem;

namespace rtfact::volume {

namespace {

VolumeGrid fromImageData(const std::string& path, vtkImageData* img) {
    if (!img) throw Error(path, "reader produced no image");
    int ext[6];
    img->GetExtent(ext);
    const int64_t d[3] = {int64_t(ext[1]) - ext[0] + 1, int64_t(ext[3]) - ext[2] + 1, int64_t(ext[5]) - ext[4] + 1};
    checkedVoxelCount(path, d);
    vtkDataArray* arr = img->GetPointData() ? img->GetPointData()->GetScalars() : nullptr;
    if (!arr) throw Error(path, "image has no scalar point data");
    if (arr->GetNumberOfComponents() != 1)
        throw Error(path, "image scalars have " + std::to_string(arr->GetNumberOfComponents()) +
                              " components; only scalar volumes are supported");
    VolumeGrid g;
    for (int a = 0; a < 3; ++a) g.dims[a] = int(d[a]);
    if (uint64_t(arr->GetNumberOfTuples()) != g.voxelCount())
        throw Error(path, "scalar array size does not match the extent");
    double sp[3], org[3];
    img->GetSpacing(sp);
    img->GetOrigin(org);
    for (int a = 0; a < 3; ++a) {
        g.spacing[a] = sp[a] > 0 && std::isfinite(sp[a]) ? float(std::fabs(sp[a])) : 1.0f;
        g.origin[a] = std::isfinite(org[a]) ? float(org[a] + ext[2 * a] * sp[a]) : 0.0f;
    }
    const int t = arr->GetDataType();
    const size_t n = g.voxelCount();
    if (t == VTK_UNSIGNED_CHAR) {
        g.sourceType = "u8";
        g.allocate(Storage::U8);
        std::memcpy(g.bytes.data(), arr->GetVoidPointer(0), n);
    } else if (t == VTK_UNSIGNED_SHORT || t == VTK_SHORT) {
        g.sourceType = t == VTK_SHORT ? "i16" : "u16";
        g.allocate(Storage::U16);
        const uint16_t* s = static_cast<const uint16_t*>(arr->GetVoidPointer(0));
        uint16_t* o = g.data<uint16_t>();
        const uint16_t flip = t == VTK_SHORT ? 0x8000 : 0;
        for (size_t i = 0; i < n; ++i) o[i] = uint16_t(s[i] ^ flip);
        if (t == VTK_SHORT) g.offset = -32768.0f;
    } else {
        g.sourceType = arr->GetDataTypeAsString();
        g.allocate(Storage::F32);
        float* o = g.data<float>();
        for (size_t i = 0; i < n; ++i) {
            const double v = arr->GetComponent(vtkIdType(i), 0);
            o[i] = std::isfinite(v) ? float(v) : 0.0f;
        }
    }
    return g;
}

}  // namespace

VolumeGrid loadDicomSeries(const std::string& dir, const VolumeLoadOptions&) {
    requireDirectory(dir);
    std::error_code ec;
    std::vector<std::pair<fs::path, uint64_t>> slices;  // DICOM files and their sizes
    for (auto& e : fs::directory_iterator(dir, ec)) {
        // VTK's reader opens every file of the directory: a FIFO among them would block it
        // (dangling links are skipped, as VTK skips them).
        if (!fs::exists(e.path(), ec)) continue;
        if (requireFileOrDirectory(e.path().string()) || e.path().filename() == "DICOMDIR") continue;
        // DICOM part 10 files carry "DICM" at byte 128.
        std::ifstream f(e.path(), std::ios::binary);
        char pre[132] = {};
        f.read(pre, 132);
        if (f.gcount() == 132 && std::memcmp(pre + 128, "DICM", 4) == 0) slices.emplace_back(e.path(), e.file_size(ec));
    }
    const size_t files = slices.size();
    if (files == 0) throw Error(dir, "directory holds no DICOM files (no 'DICM' marker at byte 128)");
    QuietVtkOutput quiet;
    VtkErrors errs;
    vtkNew<vtkDICOMImageReader> r;
    errs.observe(r, false);  // it warns about non-DICOM files in the directory and skips them
    r->SetDirectoryName(dir.c_str());
    r->Update();
    vtkImageData* img = r->GetOutput();
    if (!errs.first.empty()) throw Error(dir, "DICOM series: " + errs.first);
    if (!img || img->GetNumberOfPoints() == 0) {
        const std::string m = quiet.firstMessage();
        throw Error(dir, "VTK could not read the DICOM series" + (m.empty() ? std::string() : " (" + m + ")"));
    }
    // vtkDICOMImageReader fills slices from truncated files with whatever it finds:
    // every DICOM file must at least hold one slice of pixel data.
    int ext[6];
    img->GetExtent(ext);
    const uint64_t sliceBytes =
        uint64_t(ext[1] - ext[0] + 1) * uint64_t(ext[3] - ext[2] + 1) * uint64_t(img->GetScalarSize());
    for (const auto& [path, size] : slices)
        if (size < sliceBytes + 132)
            throw Error(path.string(), "truncated DICOM slice: " + std::to_string(size) + " bytes, one " +
                                           std::to_string(ext[1] - ext[0] + 1) + "x" +
                                           std::to_string(ext[3] - ext[2] + 1) + " slice needs " +
                                           std::to_string(sliceBytes));
    if (ext[5] - ext[4] + 1 != int(files))
        throw Error(dir, "VTK read " + std::to_string(ext[5] - ext[4] + 1) + " slices from " + std::to_string(files) +
                             " DICOM files (corrupt or mismatched slices)");
    VolumeGrid g = fromImageData(dir, img);
    const float slope = r->GetRescaleSlope(), inter = r->GetRescaleOffset();
    if (std::isfinite(slope) && slope != 0.0f && (slope != 1.0f || inter != 0.0f)) {
        g.offset = g.offset * slope + inter;
        g.scale = slope;
    }
    g.sourceType += " (DICOM, " + std::to_string(files) + " files)";
    if (const std::string m = readDicomModality(slices.front().first.string()); !m.empty())
        g.meta = {m, "DICOM modality"};
    return g;
}

VolumeGrid loadVTI(const std::string& path, const VolumeLoadOptions&) {
    requireRegularFile(path);  // a FIFO would block the open
    std::ifstream f(path, std::ios::binary);
    if (!f) throw Error(path, "cannot open file");
    std::string head(4096, '\0');
    f.read(head.data(), 4096);
    head.resize(size_t(f.gcount()));
    if (head.find("<VTKFile") == std::string::npos || head.find("ImageData") == std::string::npos)
        throw Error(path, "not a VTK XML ImageData file");
    // WholeExtent="x0 x1 y0 y1 z0 z1": reject absurd extents before VTK allocates them.
    const size_t p = head.find("WholeExtent=\"");
    if (p == std::string::npos) throw Error(path, "VTI without WholeExtent");
    long long e[6];
    if (std::sscanf(head.c_str() + p + 13, "%lld %lld %lld %lld %lld %lld", &e[0], &e[1], &e[2], &e[3], &e[4], &e[5]) !=
        6)
        throw Error(path, "bad VTI WholeExtent");
    const int64_t d[3] = {e[1] - e[0] + 1, e[3] - e[2] + 1, e[5] - e[4] + 1};
    const uint64_t n = checkedVoxelCount(path, d);
    std::error_code ec;
    const uint64_t fsz = fs::file_size(path, ec);
    // Compressed (zlib) appended data can shrink at most ~1032:1.
    if (double(n) > double(fsz) * 1100.0 + 4096.0)
        throw Error(path, "extent claims " + std::to_string(n) + " voxels, more than the file can hold");
    QuietVtkOutput quiet;
    VtkErrors errs;
    vtkNew<vtkXMLImageDataReader> r;
    errs.observe(r);
    if (!r->CanReadFile(path.c_str())) throw Error(path, "VTK cannot read this VTI file");
    r->SetFileName(path.c_str());
    r->Update();
    if (!errs.first.empty()) throw Error(path, errs.first);
    if (const std::string m = quiet.firstMessage(); !m.empty()) throw Error(path, m);
    if (r->GetErrorCode() != 0) throw Error(path, "VTK failed to read the VTI file");
    return fromImageData(path, r->GetOutput());
}

}  // namespace rtfact::volume
