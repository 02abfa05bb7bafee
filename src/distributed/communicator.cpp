// The single-process communicator and the launcher test (see communicator.h).
#include "distributed/communicator.h"

#include <algorithm>
#include <cstdlib>

#include <fmt/format.h>

#include "core/error.h"

namespace pl {

#if PLENOPTIC_HAVE_MPI
std::unique_ptr<Communicator> makeMpiCommunicator();  // mpi_communicator.cpp
#endif

uint64_t Communicator::sum(uint64_t value) {
  uint64_t total = 0;
  for (uint64_t v : allgather(value)) total += v;
  return total;
}

std::string Communicator::ranksDiffering(uint64_t value, uint64_t& rank0Value) {
  const std::vector<uint64_t> values = allgather(value);
  rank0Value = values[0];
  std::string differ;
  for (size_t r = 1; r < values.size(); ++r)
    if (values[r] != values[0]) differ += fmt::format("{}{}", differ.empty() ? "" : ", ", r);
  return differ;
}

void SingleProcess::abort(int status) { std::exit(status); }

namespace {
/// The world size the launcher announced, 0 when not launched by one.
int launcherWorldSize() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_SIZE", "PMI_SIZE", "MPI_LOCALNRANKS"}) {
    if (const char* value = std::getenv(name)) return std::max(1, std::atoi(value));
  }
  return 0;
}
}  // namespace

bool mpiAvailable() { return PLENOPTIC_HAVE_MPI != 0; }

std::unique_ptr<Communicator> makeCommunicator() {
  const int world = launcherWorldSize();
#if PLENOPTIC_HAVE_MPI
  if (world > 0) return makeMpiCommunicator();
#else
  if (world > 1)
    fail("launched by mpirun with {} ranks, but this plenoptic was built without MPI (install libopenmpi-dev and "
         "rebuild; see scripts/bootstrap.sh)", world);
#endif
  return std::make_unique<SingleProcess>();
}

}  // namespace pl
