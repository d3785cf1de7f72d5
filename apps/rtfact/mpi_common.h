// What the MPI drivers share (docs/mpi.md): a step's outcome on one rank, the MPI
// session, and how the ranks agree on the first failure (one error line naming the rank).
#pragma once
#include <mpi.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "apps/rtfact/common_options.h"
#include "apps/rtfact/outcome.h"

namespace rtfact::app::mpi {

using app::attempt;
using app::Outcome;

class Mpi {
   public:
    Mpi() {
        int provided = 0;
        // Workers' render threads ask for tiles, one at a time (SERIALIZED).
        MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided);
        MPI_Comm_rank(MPI_COMM_WORLD, &rank);
        MPI_Comm_size(MPI_COMM_WORLD, &size);
        serialized = provided >= MPI_THREAD_SERIALIZED;
    }
    ~Mpi() { MPI_Finalize(); }
    Mpi(const Mpi&) = delete;
    Mpi& operator=(const Mpi&) = delete;

    // Collective: every rank learns whether any failed; rank 0 prints the first failing
    // rank's message as the one error line. Returns that rank's exit status (0: none).
    int agree(const Outcome& mine) const {
        int failing = mine.status ? rank : size;
        MPI_Allreduce(MPI_IN_PLACE, &failing, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
        if (failing == size) return 0;
        int head[2] = {mine.status, int(mine.message.size())};
        MPI_Bcast(head, 2, MPI_INT, failing, MPI_COMM_WORLD);
        std::string message = rank == failing ? mine.message : std::string(size_t(head[1]), '\0');
        MPI_Bcast(message.data(), head[1], MPI_CHAR, failing, MPI_COMM_WORLD);
        if (rank == 0) std::fprintf(stderr, "rtfact: error: rank %d: %s\n", failing, message.c_str());
        return head[0];
    }
    // For a failure the ranks cannot agree on (out of step): one line, then every rank ends.
    [[noreturn]] void abort(const Outcome& o) const {
        std::fprintf(stderr, "rtfact: error: rank %d: %s\n", rank, o.message.c_str());
        std::fflush(stderr);
        MPI_Abort(MPI_COMM_WORLD, o.status ? o.status : 1);
        std::abort();
    }

    int rank = 0, size = 1;
    bool serialized = false;
};

}  // namespace rtfact::app::mpi
