// Open MPI's ranks for `lacuna slice` (see src/cli/mpi_ranks.h). Collectives come only from the
// main thread (the workers are TBB's, inside one rank), so MPI_THREAD_FUNNELED is enough.
#include <mpi.h>

#include <cstdlib>
#include <limits>
#include <numeric>

#include "cli/mpi_ranks.h"
#include "errors.h"

namespace lacuna {
namespace {

class MpiRanks : public SliceRanks {
 public:
  MpiRanks() {
    int provided = 0;
    if (MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS)
      throw IoError("mpirun started this process, but MPI could not be initialised");
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
  }
  ~MpiRanks() override { MPI_Finalize(); }

  int rank() const override { return rank_; }
  int size() const override { return size_; }

  double min(double value) override {
    double out = value;
    MPI_Allreduce(&value, &out, 1, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
    return out;
  }

  int64_t max(int64_t value) override {
    int64_t out = value;
    MPI_Allreduce(&value, &out, 1, MPI_INT64_T, MPI_MAX, MPI_COMM_WORLD);
    return out;
  }

  std::vector<std::string> gather(const std::string& bytes) override {
    // MPI counts are ints: a rank's layers past 2 GB (figures and contours, not images) are refused
    // everywhere, before anything is sent.
    const int64_t too_large = max(bytes.size() > size_t(std::numeric_limits<int>::max()) ? 1 : 0);
    if (too_large)
      throw ResourceLimit("a process's layers (figures and contours) exceed 2 GB; use more processes or a larger "
                          "--tolerance-mm");
    const int mine = int(bytes.size());
    std::vector<int> counts(size_t(size_), 0), offsets(size_t(size_), 0);
    MPI_Gather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
    std::vector<std::string> out;
    std::string all;
    if (rank_ == 0) {
      int64_t total = 0;
      for (int r = 0; r < size_; ++r) {
        offsets[size_t(r)] = int(total);
        total += counts[size_t(r)];
        if (total > std::numeric_limits<int>::max())
          throw ResourceLimit("the processes' layers together exceed 2 GB; use a larger --tolerance-mm");
      }
      all.resize(size_t(total));
    }
    MPI_Gatherv(bytes.data(), mine, MPI_BYTE, all.data(), counts.data(), offsets.data(), MPI_BYTE, 0, MPI_COMM_WORLD);
    if (rank_ == 0)
      for (int r = 0; r < size_; ++r) out.push_back(all.substr(size_t(offsets[size_t(r)]), size_t(counts[size_t(r)])));
    return out;
  }

 private:
  int rank_ = 0, size_ = 1;
};

}  // namespace

bool launched_by_mpirun() {
  return std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr || std::getenv("PMI_SIZE") != nullptr ||
         std::getenv("PMIX_RANK") != nullptr;
}

std::unique_ptr<SliceRanks> mpi_ranks() {
  if (!launched_by_mpirun()) return nullptr;
  return std::make_unique<MpiRanks>();
}

bool built_with_mpi() { return true; }

}  // namespace lacuna
