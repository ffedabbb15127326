// Open MPI's ranks for `lacuna slice` (see src/cli/mpi_ranks.h). Collectives come only from the
// main thread (the workers are TBB's, inside one rank), so MPI_THREAD_FUNNELED is enough.
#include <mpi.h>

#include <limits>

#include "cli/mpi_ranks.h"
#include "errors.h"

namespace lacuna {
namespace {

class MpiRanks : public JobRanks {
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
    // MPI counts are ints: every process learns every size first, so all refuse together when the
    // layers (figures and contours, not images) exceed 2 GB, before anything is sent.
    const int64_t mine = int64_t(bytes.size());
    std::vector<int64_t> sizes(size_t(size_), 0);
    MPI_Allgather(&mine, 1, MPI_INT64_T, sizes.data(), 1, MPI_INT64_T, MPI_COMM_WORLD);
    int64_t total = 0;
    for (int64_t n : sizes) total += n;
    if (total > std::numeric_limits<int>::max())
      throw ResourceLimit("the processes' layers (figures and contours) exceed 2 GB together; use a larger "
                          "--tolerance-mm or thicker layers");
    std::vector<int> counts(size_t(size_), 0), offsets(size_t(size_), 0);
    for (int r = 0; r < size_; ++r) {
      counts[size_t(r)] = int(sizes[size_t(r)]);
      if (r > 0) offsets[size_t(r)] = offsets[size_t(r - 1)] + counts[size_t(r - 1)];
    }
    std::string all(rank_ == 0 ? size_t(total) : 0, '\0');
    MPI_Gatherv(bytes.data(), int(mine), MPI_BYTE, all.data(), counts.data(), offsets.data(), MPI_BYTE, 0, MPI_COMM_WORLD);
    std::vector<std::string> out;
    if (rank_ == 0)
      for (int r = 0; r < size_; ++r) out.push_back(all.substr(size_t(offsets[size_t(r)]), size_t(counts[size_t(r)])));
    return out;
  }

 private:
  int rank_ = 0, size_ = 1;
};

}  // namespace

std::unique_ptr<JobRanks> mpi_ranks() {
  if (!launched_by_mpirun()) return nullptr;
  return std::make_unique<MpiRanks>();
}

bool built_with_mpi() { return true; }

}  // namespace lacuna
