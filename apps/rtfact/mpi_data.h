// Data-parallel rendering under mpirun (--distribute data, docs/mpi.md): each rank reads
// only its slab of the volume (plus ghost slices), renders it on the whole volume's sample
// lattice into premultiplied RGBA, and the ranks composite sort-last in visibility order
// (rtfact::distributed); rank 0 writes the image.
#pragma once
#include <functional>
#include <string>

#include "apps/rtfact/common_options.h"
#include "apps/rtfact/mpi_common.h"
#include "apps/rtfact/render_command.h"
#include "engine/settings.h"

namespace rtfact::app {

// "image" or "data": --distribute if given, else image when the data fit every rank's
// share of this node's available memory (data when they do not, for commands that can).
std::string chooseDistribution(const CommonOptions& c, const DataSource* data, int ranks);

int runMpiData(const mpi::Mpi& mpi, CommonOptions& c, const std::function<engine::Settings()>& settings,
               const DataSource& data);

}  // namespace rtfact::app
