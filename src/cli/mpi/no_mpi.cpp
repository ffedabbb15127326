// The stand-in for builds without MPI (see src/cli/mpi_ranks.h).
#include <cstdlib>

#include "cli/mpi_ranks.h"
#include "errors.h"

namespace lacuna {

bool launched_by_mpirun() {
  return std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr || std::getenv("PMI_SIZE") != nullptr ||
         std::getenv("PMIX_RANK") != nullptr;
}

std::unique_ptr<SliceRanks> mpi_ranks() {
  if (launched_by_mpirun())
    throw InvalidInput("started by mpirun, but this lacuna was built without MPI (install libopenmpi-dev and "
                       "rebuild, or run it alone)");
  return nullptr;
}

bool built_with_mpi() { return false; }

}  // namespace lacuna
