// VolumeGrid: a dense scalar grid stored compactly (u8/u16 as read, everything else as
// f32) with a linear map from stored value to data value (NIfTI scl_slope/inter, signed
// types shifted into unsigned storage). World position of voxel (i,j,k) is
// origin + (i,j,k) * spacing (node centred, like VTK image data).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "core/math/aabb.h"
#include "core/util/huge_pages.h"

namespace rtfact::volume {

enum class Storage { U8, U16, F32 };

// What the file says about the acquisition, used to choose defaults (transfer function).
struct VolumeMetadata {
    std::string modality;        // DICOM terms, upper case: "CT", "MR", "PT", ...; empty when unknown
    std::string modalitySource;  // where it was read, e.g. "DICOM modality", "MetaImage Modality"
};

inline const char* storageName(Storage s) { return s == Storage::U8 ? "u8" : (s == Storage::U16 ? "u16" : "f32"); }
inline int storageBytes(Storage s) { return s == Storage::U8 ? 1 : (s == Storage::U16 ? 2 : 4); }

struct VolumeGrid {
    int dims[3] = {0, 0, 0};
    Vec3f spacing{1, 1, 1};
    Vec3f origin{0, 0, 0};
    Storage storage = Storage::U8;
    std::string sourceType;             // type in the file (u8, i16, f64, ...)
    float scale = 1.0f, offset = 0.0f;  // data value = stored * scale + offset
    VolumeMetadata meta;
    // Stored voxels, x fastest, plus kPad bytes so wide gathers may over-read.
    std::vector<uint8_t> bytes;
    static constexpr size_t kPad = 16;

    size_t voxelCount() const { return size_t(dims[0]) * size_t(dims[1]) * size_t(dims[2]); }
    size_t index(int i, int j, int k) const {
        return (size_t(k) * size_t(dims[1]) + size_t(j)) * size_t(dims[0]) + size_t(i);
    }
    template <class T>
    const T* data() const {
        return reinterpret_cast<const T*>(bytes.data());
    }
    template <class T>
    T* data() {
        return reinterpret_cast<T*>(bytes.data());
    }
    // Stored value (before scale/offset) of voxel n.
    float stored(size_t n) const {
        switch (storage) {
            case Storage::U8:
                return float(bytes[n]);
            case Storage::U16:
                return float(data<uint16_t>()[n]);
            default:
                return data<float>()[n];
        }
    }
    float value(size_t n) const { return stored(n) * scale + offset; }
    float value(int i, int j, int k) const { return value(index(i, j, k)); }
    // Allocates storage for dims (already validated) and fills it with zeros.
    void allocate(Storage s) {
        storage = s;
        // huge pages: 4 KiB first-touch faults of a large scan cost more than reading it on VMs
        resizeFreshHugePages(bytes, voxelCount() * size_t(storageBytes(s)) + kPad);
    }
    AABB bounds() const {
        const Vec3f ext((dims[0] - 1) * spacing.x, (dims[1] - 1) * spacing.y, (dims[2] - 1) * spacing.z);
        return {origin, origin + ext};
    }
    size_t memoryBytes() const { return bytes.capacity(); }
};

// Value range and a coarse histogram of the data values.
struct VolumeSummary {
    float lo = 0, hi = 0;
    double mean = 0;
    size_t nonFinite = 0;
    std::vector<uint64_t> histogram;  // bins over [lo, hi]
};
VolumeSummary summarize(const VolumeGrid& g, int bins = 16);

}  // namespace rtfact::volume
