// The processes of one job over MPI (`mpirun -np K lacuna slice|run --stream`): the collectives the
// pipeline needs (src/cli/mpi/mpi_ranks.cpp implements them with Open MPI), and one step of a job
// run on every process so that an error anywhere ends the job everywhere.
#pragma once

#include <cstdint>
#include <exception>
#include <string>
#include <vector>

#include "errors.h"

namespace lacuna {

// The processes of one job (MPI ranks, see src/cli/mpi_ranks.h): each evaluates a block of the slabs
// (`lacuna slice` cuts the layers whose planes lie in them, a streamed run meshes them); the first
// gathers what they found and writes.
class JobRanks {
 public:
  virtual ~JobRanks() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  // Over every process (each must call them in the same order).
  virtual double min(double value) = 0;
  virtual int64_t max(int64_t value) = 0;
  // The first process gets every process's bytes in rank order, the others nothing.
  virtual std::vector<std::string> gather(const std::string& bytes) = 0;
};

// Runs one step of a job on every process, then lets every process know whether any failed: the
// one that failed rethrows its error, the others stop with an error of the same kind naming it,
// so the job ends everywhere with nothing written. Alone, just runs the step.
template <typename Step>
void in_every_rank(JobRanks* ranks, Step&& step) {
  if (!ranks) {
    step();
    return;
  }
  std::exception_ptr error;
  int64_t kind = 0;  // 1 internal, 2 input, 3 files, 4 budget, 5 checks, 6 cancelled
  try {
    step();
  } catch (const InvalidInput&) {
    kind = 2, error = std::current_exception();
  } catch (const IoError&) {
    kind = 3, error = std::current_exception();
  } catch (const ResourceLimit&) {
    kind = 4, error = std::current_exception();
  } catch (const CheckFailed&) {
    kind = 5, error = std::current_exception();
  } catch (const Cancelled&) {
    kind = 6, error = std::current_exception();
  } catch (...) {
    kind = 1, error = std::current_exception();
  }
  // The worst kind, and among the processes with it the first.
  const int64_t count = ranks->size();
  const int64_t worst = ranks->max(kind == 0 ? 0 : kind * count + (count - 1 - ranks->rank()));
  if (worst == 0) return;
  if (error) std::rethrow_exception(error);
  const std::string message = "process " + std::to_string(count - 1 - worst % count) + " of " + std::to_string(count) +
                              " failed (its message says why); this one stopped with it and nothing was written";
  switch (worst / count) {
    case 2: throw InvalidInput(message);
    case 3: throw IoError(message);
    case 4: throw ResourceLimit(message);
    case 5: throw CheckFailed(message);
    case 6: throw Cancelled(message);
    default: throw InternalError(message);
  }
}

}  // namespace lacuna
