// The MPI implementation of Communicator (communicator.h): MPI_COMM_WORLD. Compiled only when
// CMake finds MPI; the only file that includes <mpi.h>.
#include <mpi.h>

#include <algorithm>
#include <climits>

#include "core/error.h"
#include "distributed/communicator.h"

namespace pl {
namespace {

class MpiCommunicator final : public Communicator {
 public:
  MpiCommunicator() {
    int initialised = 0;
    MPI_Initialized(&initialised);
    if (!initialised) {
      // Only the main thread calls MPI (the worker threads compute between collectives).
      int provided = 0;
      MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
      owner_ = true;
    }
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
  }
  ~MpiCommunicator() override {
    if (owner_) MPI_Finalize();
  }
  int rank() const override { return rank_; }
  int size() const override { return size_; }

  void allgatherv(void* buffer, const std::vector<uint64_t>& displacement, const std::vector<uint64_t>& count) override {
    // MPI counts are int: one call moves at most INT_MAX bytes per rank, so larger layouts go
    // in rounds, each rank sending the next slice of its part.
    std::vector<int> counts(size_), displs(size_);
    std::vector<uint64_t> sent(size_, 0);
    for (;;) {
      bool any = false;
      for (int r = 0; r < size_; ++r) {
        const uint64_t left = count[r] - sent[r];
        const uint64_t chunk = std::min<uint64_t>(left, uint64_t(INT_MAX) / 2);
        counts[r] = int(chunk);
        any = any || chunk > 0;
      }
      if (!any) break;
      // Displacements are int too: slices are addressed from the lowest one of this round.
      uint64_t base = ~uint64_t(0);
      for (int r = 0; r < size_; ++r)
        if (counts[r] > 0) base = std::min(base, displacement[r] + sent[r]);
      bool fits = true;
      for (int r = 0; r < size_; ++r) {
        const uint64_t d = counts[r] > 0 ? displacement[r] + sent[r] - base : 0;
        fits = fits && d <= uint64_t(INT_MAX);
        displs[r] = int(d);
      }
      if (!fits) fail("MPI exchange of more than 2 GB in one layout: use more ranks or a coarser preset");
      MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, static_cast<char*>(buffer) + base, counts.data(), displs.data(),
                     MPI_BYTE, MPI_COMM_WORLD);
      for (int r = 0; r < size_; ++r) {
        sent[r] += uint64_t(counts[r]);
        if (r != rank_) bytesReceived_ += uint64_t(counts[r]);
      }
      ++exchanges_;
    }
  }

  std::vector<uint64_t> allgather(uint64_t value) override {
    std::vector<uint64_t> all(size_);
    MPI_Allgather(&value, 1, MPI_UINT64_T, all.data(), 1, MPI_UINT64_T, MPI_COMM_WORLD);
    return all;
  }
  void barrier() override { MPI_Barrier(MPI_COMM_WORLD); }
  [[noreturn]] void abort(int status) override {
    MPI_Abort(MPI_COMM_WORLD, status);
    std::exit(status);  // MPI_Abort does not return; this keeps [[noreturn]] honest
  }
  std::string name() const override { return "MPI"; }

 private:
  int rank_ = 0, size_ = 1;
  bool owner_ = false;
};

}  // namespace

std::unique_ptr<Communicator> makeMpiCommunicator() { return std::make_unique<MpiCommunicator>(); }

}  // namespace pl
