// The first iterate of a load step (solid.newton.prediction): the committed state extrapolated along
// the last step (u_n + Δt/Δt_prev (u_n − u_n−1)) or the committed state itself. Consistency check:
// the free balloon (configs/solid_free_balloon.yaml, elastic, pressure-controlled, one equilibrium
// per pressure) inflated in 20 steps reaches the same diameters from either start, to the order of
// the Newton tolerance; the extrapolated start, a step's change closer to the end of a steadily
// inflating balloon, needs fewer Newton iterations over the run.
#include <gtest/gtest.h>
#include <mpi.h>
#include <petscsys.h>

#include <cmath>

#include "angio/participant/standalone.hpp"
#include "angio/solid/participant.hpp"
#include "angio/solid/scene.hpp"
#include "free_balloon_scene.hpp"
#include "mpi_test.hpp"

using namespace angio::solid;

namespace {

SolidScene balloon(bool extrapolate) {
  SolidScene sc = free_balloon_inflation(20);
  sc.options.newton.continuation = 0;
  sc.options.newton.extrapolate = extrapolate;
  return sc;
}

}  // namespace

TEST(Prediction, ExtrapolatedStartSameEquilibriumFewerIterations) {
  SolidRunner constant(PETSC_COMM_WORLD, balloon(false), "");
  ASSERT_EQ(angio::participant::run_standalone(constant, balloon(false).time), 0);
  SolidRunner extrapolated(PETSC_COMM_WORLD, balloon(true), "");
  ASSERT_EQ(angio::participant::run_standalone(extrapolated, balloon(true).time), 0);
  const auto& hc = constant.history();
  const auto& he = extrapolated.history();
  ASSERT_EQ(hc.size(), he.size());
  for (size_t i = 0; i < hc.size(); ++i) {
    ASSERT_NEAR(hc[i].time, he[i].time, 1e-12);
    EXPECT_NEAR(hc[i].d_mid, he[i].d_mid, 1e-5) << "t = " << hc[i].time;  // Newton atol 1e-8 N
  }
  const long nc = constant.totals().newton_iterations, ne = extrapolated.totals().newton_iterations;
  if (angio_test::world_rank() == 0)
    std::printf("Newton iterations over 20 steps: constant start %ld, extrapolated %ld; D_mid at 13 atm %.6f mm\n", nc,
                ne, he.back().d_mid);
  EXPECT_GT(he.back().d_mid, 2.5);  // inflated to the lock-up
  EXPECT_LT(ne, nc);
}
