// The path tracer lives in the core (it renders any GeometryScene); meshes give it
// their MTL materials through PathIntegrator::fromMesh.
#pragma once
#include "core/render/path_integrator.h"
#include "surfaces/mesh.h"

namespace rtfact::surfaces {
static_assert(MtlStyleMaterial<MeshMaterial>);
}  // namespace rtfact::surfaces
