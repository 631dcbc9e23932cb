// Helpers of the MPI test executables (solid model tests, solid contact tests); mpi_test_main.cpp holds their
// main(): PETSc/MPI start-up, test output and angio logging on rank 0 only, and a failure on any rank fails all.
#pragma once

namespace angio_test {
int world_rank();  // rank in PETSC_COMM_WORLD
int world_size();
}  // namespace angio_test
