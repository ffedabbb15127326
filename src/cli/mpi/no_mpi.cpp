// The stand-in for builds without MPI (see src/cli/mpi_ranks.h).

#include "cli/mpi_ranks.h"
#include "errors.h"

namespace lacuna {

std::unique_ptr<JobRanks> mpi_ranks() {
  if (launched_by_mpirun())
    throw InvalidInput("started by mpirun, but this lacuna was built without MPI (install libopenmpi-dev and "
                       "rebuild, or run it alone)");
  return nullptr;
}

bool built_with_mpi() { return false; }

}  // namespace lacuna
