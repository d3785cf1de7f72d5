// Loading scalar volumes: raw, MetaImage (.mhd/.mha), NRRD (.nrrd/.nhdr, raw or gzip,
// detached and per-slice data files), NIfTI-1 (.nii/.nii.gz), VTK image data (.vti),
// DICOM series (a directory) and OpenVDB (.vdb). Every size a header claims is checked
// against the file before anything is allocated; problems throw rtfact::Error.
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "volume/brick_volume.h"
#include "volume/volume_grid.h"

namespace rtfact::volume {

struct VolumeLoadOptions {
    // Raw files (and overrides for any format where it makes sense).
    std::optional<std::array<int, 3>> dims;
    std::string type;  // u8|u16|i16|f32 (raw only)
    std::string endian = "little";
    std::optional<Vec3f> spacing;  // overrides the file's spacing
    uint64_t headerSkip = 0;
    std::string grid;  // OpenVDB grid name; default the first float grid
    bool progress = true;
    // Data-parallel ranks (docs/mpi.md): given the file's dims, the slices [z0, z1) to
    // read; the grid then holds only those (origin unchanged). Raw, MetaImage, NRRD and
    // NIfTI read just their bytes (loadVolumeSlices covers the other formats).
    std::function<std::array<int, 2>(const std::array<int, 3>& dims)> slices;
};

// True for paths this module claims (by extension, or a directory of DICOM files).
bool looksLikeVolume(const std::string& path);
VolumeGrid loadVolume(const std::string& path, const VolumeLoadOptions& opt = {});

// The render-time layout: OpenVDB grids are bricked straight from their sparse tree
// (never densified); everything else is loaded dense, bricked and the dense copy freed.
BrickedVolume loadBrickedVolume(const std::string& path, const VolumeLoadOptions& opt = {});
BrickedVolume loadVDBBricked(const std::string& path, const VolumeLoadOptions& opt);

// Parses "X,Y,Z" dims and "sx,sy,sz" spacing; throw rtfact::Error naming `what`.
std::array<int, 3> parseDims(const std::string& text);
Vec3f parseSpacing(const std::string& text);

// Largest voxel count a grid may have (indices are 32-bit in the SIMD gathers).
inline constexpr uint64_t kMaxVoxels = (uint64_t(1) << 31) - 1;
// Validates dims (positive, product within kMaxVoxels); returns the voxel count.
uint64_t checkedVoxelCount(const std::string& file, const int64_t dims[3]);

// Writers used by the generators and tests.
void writeRaw(const std::string& path, const VolumeGrid& g);
void writeMetaImage(const std::string& mhdPath, const VolumeGrid& g);

// Internals shared by the loader files.
VolumeGrid loadDicomSeries(const std::string& dir, const VolumeLoadOptions& opt);
VolumeGrid loadVTI(const std::string& path, const VolumeLoadOptions& opt);
VolumeGrid loadVDB(const std::string& path, const VolumeLoadOptions& opt);

}  // namespace rtfact::volume
