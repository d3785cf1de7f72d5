// Subcommands of rtfact-bench; each receives the arguments after its name.
#pragma once

namespace rtfact::bench {

int benchMesh(int argc, char** argv);
int benchPoints(int argc, char** argv);
int benchVolume(int argc, char** argv);
int benchPython(int argc, char** argv);
// The browser viewer over a socket (bench_view.cpp).
int benchView(int argc, char** argv);
int benchLoad(int argc, char** argv);
// Under mpirun: compositing and data-parallel scaling (bench_mpi.cpp; RTFACT_MPI builds).
int benchMpi(int argc, char** argv);

}  // namespace rtfact::bench
