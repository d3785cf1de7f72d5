// One rank's part of a volume for data-parallel rendering (docs/mpi.md): slab `part` of
// `parts` along z, read from the file with the ghost slices trilinear sampling and
// central-difference gradients reach into, rendered on the whole volume's sample lattice
// and clipped to the slab, so that the slabs' images composited front to back equal the
// whole volume's image. No MPI here: the MPI driver combines the parts' figures.
#pragma once
#include <array>
#include <optional>
#include <string>
#include <utility>

#include "engine/scene.h"
#include "engine/settings.h"
#include "volume/value_histogram.h"
#include "volume/volume_grid.h"

namespace rtfact::engine {

// Ghost slices on each side of a slab: trilinear sampling needs 1, the central
// differences of shaded DVR 1 more.
inline constexpr int kGhostSlices = 2;

struct VolumePart {
    int part = 0, parts = 1;
    std::array<int, 3> dims{};  // the whole volume's
    Vec3f origin, spacing;      // the whole volume's
    int own0 = 0, own1 = 0;     // the slab: planes [own0, own1] of the whole volume (cells between)
    int z0 = 0;                 // first slice loaded (own0 minus the ghosts)
    int ghosts = kGhostSlices;  // ghost slices read on each side (ghostSlices)
    bool readWhole = false;     // the format has no slab access (read whole, cropped)
    uint64_t loadedBytes = 0;   // voxel bytes held after loading
    volume::VolumeGrid grid;    // the loaded slices, until partScene() bricks them
    volume::VolumeMetadata meta;
    float scale = 1, offset = 0;
    volume::Storage storage = volume::Storage::U8;

    // Slices the slab's voxels count for (each voxel of the volume in exactly one part).
    std::pair<int, int> ownedSlices() const { return {own0, part == parts - 1 ? own1 + 1 : own1}; }
    // Finite data range of the owned voxels (+inf, -inf when none).
    std::pair<float, float> ownedRange() const;
    // The owned voxels binned as histogramOf(whole volume) bins them when [lo, hi] is the
    // whole range: the parts' bins add up to the whole volume's histogram.
    volume::ValueHistogram ownedHistogram(float lo, float hi) const;
};

// The ghost slices for settings s: kGhostSlices, and for a pre-integrated march one more
// than a step's voxels (a rank's first sample looks back a step into its neighbour).
int ghostSlices(const VolumeSettings& s);

// Slab planes [own0, own1] of part `part` of `parts` for `slices` slices (balanced cells).
std::pair<int, int> slabPlanes(int slices, int part, int parts);

// Reads part `part` of `parts` of a volume file with `ghosts` ghost slices; throws Error
// (file unreadable, or cut short before the end of this part's slices) or UsageError (fewer
// cells than parts).
VolumePart loadVolumePart(const std::string& file, const OpenOptions& opt, int part, int parts,
                          int ghosts = kGhostSlices);

// The whole volume's box after the clip settings (world), as the single-process render
// and its default camera bound it.
AABB wholeClippedBox(const VolumePart& p, const VolumeSettings& s);

// Bricks the loaded slices into a scene (the dense slices are freed).
Scene partScene(VolumePart& p);

// The settings this part renders with: `s` (the whole volume's, with its transfer function
// and window resolved) clipped to the slab, on the whole clipped box's lattice. None when
// the clip leaves nothing of the slab.
std::optional<Settings> partSettings(const VolumePart& p, const Settings& s);

}  // namespace rtfact::engine
