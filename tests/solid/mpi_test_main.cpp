#include <gtest/gtest.h>
#include <mpi.h>
#include <petscsys.h>

#include "angio/common/log.hpp"
#include "mpi_test.hpp"

namespace angio_test {
int world_rank() {
  int r;
  MPI_Comm_rank(PETSC_COMM_WORLD, &r);
  return r;
}
int world_size() {
  int s;
  MPI_Comm_size(PETSC_COMM_WORLD, &s);
  return s;
}
}  // namespace angio_test

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  int fake_argc = 1;
  PetscInitialize(&fake_argc, &argv, nullptr, nullptr);
  if (angio_test::world_rank() != 0) {
    auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
    angio::log::set_level(angio::log::Level::error);
  }
  const int rc = RUN_ALL_TESTS();
  int any = 0;
  MPI_Allreduce(&rc, &any, 1, MPI_INT, MPI_MAX, PETSC_COMM_WORLD);
  PetscFinalize();
  return any;
}
