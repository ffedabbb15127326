// `lacuna slice` over MPI ranks (`mpirun -np K lacuna slice ...`): an optional component, built when
// CMake finds Open MPI (src/cli/mpi/mpi_ranks.cpp), otherwise a stand-in that refuses to run under
// mpirun (src/cli/mpi/no_mpi.cpp), so that K copies never write the same files side by side.
#pragma once

#include <cstdlib>
#include <memory>

#include "pipeline/slice_output.h"

namespace lacuna {

// Whether mpirun started this process (its environment says so).
inline bool launched_by_mpirun() {
  return std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr || std::getenv("PMI_SIZE") != nullptr ||
         std::getenv("PMIX_RANK") != nullptr;
}

// The job's ranks, MPI initialised until they are destroyed; null when mpirun did not start this
// process. Throws InvalidInput when it did but this build has no MPI.
std::unique_ptr<JobRanks> mpi_ranks();

// Whether this build can run over MPI ranks.
bool built_with_mpi();

}  // namespace lacuna
