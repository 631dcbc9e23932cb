// Collecting per-rank values on rank 0 (summaries).
#pragma once
#include <mpi.h>

#include <vector>

namespace angio::solid {

// The concatenation of every rank's `mine` on rank 0 (rank order); empty on the other ranks. Collective.
inline std::vector<double> gather_on_root(MPI_Comm comm, const std::vector<double>& mine) {
  int size = 1, rank = 0;
  MPI_Comm_size(comm, &size);
  MPI_Comm_rank(comm, &rank);
  const int count = int(mine.size());
  std::vector<int> counts(size), displs(size, 0);
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm);
  std::vector<double> all;
  if (rank == 0) {
    for (int r = 1; r < size; ++r) displs[r] = displs[r - 1] + counts[r - 1];
    all.resize(displs.back() + counts.back());
  }
  MPI_Gatherv(mine.data(), count, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, 0, comm);
  return all;
}

}  // namespace angio::solid
