#pragma once
// The ranks of a distributed job and what they exchange (issue #16: the MPI-distributed bake).
// One small interface, two implementations: a single process (rank 0 of 1, every call a no-op
// or a copy), and MPI (mpi_communicator.cpp, compiled only when CMake finds MPI). Nothing
// outside this module includes <mpi.h>.
//
// Contract shared by both:
//   * every rank calls the collective operations (allgatherv, allgather, barrier) in the same
//     order with the same layout arguments;
//   * byte counts and displacements are in bytes, the same on every rank;
//   * results are deterministic: allgather returns the values in rank order, so a reduction
//     folded over it in that order gives the same bits on every rank and in every run.
//   * a failure inside MPI ends the whole job (MPI's default error handler); abort() ends it
//     on purpose (a rank that threw), with `status` as mpirun's exit status.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace pl {

class Communicator {
 public:
  virtual ~Communicator() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  /// In place: rank r's bytes [displacement[r], displacement[r] + count[r]) of `buffer` are
  /// copied to the same place on every other rank (size() entries each).
  virtual void allgatherv(void* buffer, const std::vector<uint64_t>& displacement, const std::vector<uint64_t>& count) = 0;
  /// Every rank's `value`, in rank order, on every rank.
  virtual std::vector<uint64_t> allgather(uint64_t value) = 0;
  virtual void barrier() = 0;
  /// Ends every rank of the job with `status` (does not return).
  [[noreturn]] virtual void abort(int status) = 0;
  /// "MPI" or "single process": what the stats report.
  virtual std::string name() const = 0;

  /// Bytes this rank has received through allgatherv so far (the exchange volume).
  uint64_t bytesReceived() const { return bytesReceived_; }
  /// Calls to allgatherv so far (each is one collective: its latency is paid once per call).
  uint64_t exchanges() const { return exchanges_; }

  /// Σ over ranks of `value` (integers: the same on every rank whatever the order).
  uint64_t sum(uint64_t value);
  /// The ranks whose `value` differs from rank 0's, as "1, 3" (empty when all agree), and
  /// rank 0's value in `rank0Value`: how a job checks that every rank does the same work.
  std::string ranksDiffering(uint64_t value, uint64_t& rank0Value);

 protected:
  uint64_t bytesReceived_ = 0;
  uint64_t exchanges_ = 0;
};

/// Rank 0 of 1.
class SingleProcess final : public Communicator {
 public:
  int rank() const override { return 0; }
  int size() const override { return 1; }
  void allgatherv(void*, const std::vector<uint64_t>&, const std::vector<uint64_t>&) override {}
  std::vector<uint64_t> allgather(uint64_t value) override { return {value}; }
  void barrier() override {}
  [[noreturn]] void abort(int status) override;
  std::string name() const override { return "single process"; }
};

/// Whether this build has the MPI implementation.
bool mpiAvailable();

/// The MPI communicator (MPI_COMM_WORLD; MPI is initialised here and finalised with the
/// object) when the program was launched by mpirun/mpiexec (Open MPI's or a PMI launcher's
/// environment variables are set: a plain run never initialises MPI) and the build has MPI,
/// otherwise
/// SingleProcess. Throws pl::Error when launched by mpirun with more than one rank but built
/// without MPI (each rank would otherwise bake the whole scene and write the same file).
std::unique_ptr<Communicator> makeCommunicator();

}  // namespace pl
