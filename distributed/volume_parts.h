// What the ranks of a data-parallel volume render agree on (docs/mpi.md): one transfer
// function and window from the whole volume (its range and histogram, reduced from the
// parts), and the visibility order of the slabs for a camera.
#pragma once
#include <mpi.h>

#include <vector>

#include "core/math/vec3f.h"
#include "engine/settings.h"
#include "engine/volume_part.h"

namespace rtfact::distributed {

// Collective: resolves s.volume's transfer function, window and level for the whole
// volume (the default TF chosen from the whole histogram, as one process would) and sets
// them explicitly, so every rank maps values identically.
void agreeOnTransferFunction(MPI_Comm comm, const engine::VolumePart& part, engine::Settings& s);

// Ranks (slab r = rank r) nearest first as seen from `eye`: a ray crosses the slabs on its
// side of the eye in order of their distance along z, and never slabs on both sides.
std::vector<int> slabVisibilityOrder(const engine::VolumePart& part, int ranks, Vec3f eye);

}  // namespace rtfact::distributed
