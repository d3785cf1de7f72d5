// Internals shared by the volume readers (not part of the public interface; the fuzz
// harness calls the readers directly).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "core/io/scalar_type.h"
#include "volume/volume_grid.h"
#include "volume/volume_io.h"

namespace rtfact::volume {

// Our own readers, one file each (volume_io_<format>.cpp).
VolumeGrid loadRaw(const std::string& path, const VolumeLoadOptions& o);
VolumeGrid loadMetaImage(const std::string& path, const VolumeLoadOptions& o);
VolumeGrid loadNrrd(const std::string& path, const VolumeLoadOptions& o);
VolumeGrid loadNifti(const std::string& path, const VolumeLoadOptions& o);
// name_XxYxZ_type.raw (the Open SciVis naming) carries dims and type: `opt` with them.
VolumeLoadOptions rawOptionsFromName(const std::string& path, const VolumeLoadOptions& opt);

namespace detail {

// One piece of the voxel payload: `bytes` decoded bytes from `path`.
struct Piece {
    std::string path;
    uint64_t offset = 0;  // in the file (before decompression)
    uint64_t skip = 0;    // decoded bytes to drop first
    bool compressed = false;
    uint64_t bytes = 0;
    bool skipFromEnd = false;  // NRRD "byte skip: -1": data are the last bytes of the file
};

// Checks the pieces against their files and the memory budget, reads them and converts
// the source type into the grid's compact storage.
// With o.slices, only those slices' bytes are read (keepSlices).
void decodePayload(VolumeGrid& g, io::ScalarType src, bool bigEndian, std::vector<Piece>& pieces,
                   const std::string& header, const VolumeLoadOptions& o);
// Trims the pieces to the bytes of slices [z0, z1) of g (volume_io_region.cpp) and sets
// g.dims[2] to their count.
void keepSlices(VolumeGrid& g, int sourceBytes, std::vector<Piece>& pieces, const std::string& header,
                std::array<int, 2> z);
// A voxel type as MetaImage, NRRD or our options spell it ("MET_USHORT", "unsigned short", "u16").
io::ScalarType parseVoxelType(const std::string& file, std::string t);

std::string trim(const std::string& s);
std::vector<std::string> splitWords(const std::string& s);
// A finite number, or Error(file, "bad <what> '<s>'").
double parseNumber(const std::string& file, const std::string& s, const std::string& what);
void setDims(VolumeGrid& g, const std::string& file, const std::vector<int64_t>& d);
void setSpacing(VolumeGrid& g, const std::string& file, const std::vector<double>& s);
// The first `limit` bytes of a file (fewer when it is shorter).
std::string readTextHead(const std::string& path, size_t limit);
// A modality value as DICOM spells it: "MET_MOD_CT" (MetaImage), "ct", "MR" -> "CT", "MR".
std::string modalityTerm(std::string v);
// "CT" or "MR" when free text names the modality as a word ("CT scan of a bonsai tree").
std::string modalityWord(const std::string& text);
// Free text from a fixed-size, NUL-padded header field.
std::string headerText(const uint8_t* p, size_t n);

}  // namespace detail
}  // namespace rtfact::volume
