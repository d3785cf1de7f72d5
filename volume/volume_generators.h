// Synthetic volumes: the 3D Shepp-Logan phantom and a homogeneous slab whose
// transmittance is known in closed form.
#pragma once
#include "volume/volume_grid.h"

namespace rtfact::volume {

// n^3 voxels over [-1, 1]^3; densities 0..1 stored as u8 (x255) or u16 (x4095).
VolumeGrid makeSheppLogan(int n, Storage storage = Storage::U16);

// nx*ny*nz voxels, value `inside` for z in [z0, z1] (voxel indices), 0 elsewhere, u8.
VolumeGrid makeSlab(int nx, int ny, int nz, int z0, int z1, uint8_t inside = 255);

}  // namespace rtfact::volume
