// Continuation of a failed solve (solid.newton.continuation): a load step too large for Newton is
// reached through sub-increments of the same step, and the equilibrium it returns is that of the
// step's own equations. Consistency check against the same balloon (configs/solid_free_balloon.yaml,
// elastic, pressure-controlled, a monotone diameter–pressure curve, so one equilibrium per pressure)
// loaded in small steps: the diameters at the common times agree to the Newton tolerance's order.
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

SolidScene balloon(int steps, int continuation) {
  SolidScene sc = free_balloon_inflation(steps);  // no cuts: the continuation must carry a failed step
  sc.options.newton.max_iterations = 12;
  sc.options.newton.continuation = continuation;
  return sc;
}

double d_at(const std::vector<StepSummary>& h, double t) {
  for (const auto& s : h)
    if (std::abs(s.time - t) < 1e-9) return s.d_mid;
  ADD_FAILURE() << "no committed step at t = " << t;
  return 0.0;
}

}  // namespace

TEST(Continuation, LargeStepReachesTheSmallStepEquilibrium) {
  // Two steps of 0.66 MPa each over the unfolding plateau: Newton alone fails the first one.
  {
    SolidRunner plain(PETSC_COMM_WORLD, balloon(2, 0), "");
    EXPECT_NE(angio::participant::run_standalone(plain, balloon(2, 0).time), 0)
        << "the large step converges without continuation: the test no longer tests it";
  }
  SolidRunner cont(PETSC_COMM_WORLD, balloon(2, 16), "");
  ASSERT_EQ(angio::participant::run_standalone(cont, balloon(2, 16).time), 0);
  SolidRunner fine(PETSC_COMM_WORLD, balloon(20, 0), "");
  ASSERT_EQ(angio::participant::run_standalone(fine, balloon(20, 0).time), 0);
  for (double t : {0.5, 1.0}) {
    const double dc = d_at(cont.history(), t), df = d_at(fine.history(), t);
    if (angio_test::world_rank() == 0) std::printf("t = %.1f: D_mid continued %.6f, small steps %.6f mm\n", t, dc, df);
    EXPECT_GT(dc, 1.2);         // inflated, not stuck at the start
    EXPECT_NEAR(dc, df, 1e-5);  // the same equilibrium (Newton atol 1e-8 N)
  }
}
