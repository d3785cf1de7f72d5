// The Whitted integrator lives in the core (it renders any GeometryScene); meshes give
// it their MTL materials through PathIntegrator::fromMesh.
#pragma once
#include "core/render/path_integrator.h"
#include "core/render/whitted_integrator.h"
#include "surfaces/mesh.h"
