// The first iterate of a load step (solid.newton.prediction): the committed state extrapolated along
// the last step (u_n + Δt/Δt_prev (u_n − u_n−1)) or the committed state itself. Consistency check:
// the free balloon (configs/solid_free_balloon.yaml, elastic, pressure-controlled, one equilibrium
// per pressure) inflated in 20 steps reaches the same diameters from either start, to the order of
// the Newton tolerance; the extrapolated start, a step's change closer to the end of a steadily
// inflating balloon, needs fewer Newton iterations over the run. Past the pressure's peak the
// model does not extrapolate for one step (loads_keep_direction): the prediction along the inflation
// would inflate a balloon that the next pressure deflates.
#include <gtest/gtest.h>
#include <mpi.h>
#include <petscsys.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "angio/participant/standalone.hpp"
#include "angio/solid/insertion_tool.hpp"
#include "angio/solid/mesh.hpp"
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

// Steps the model to t = dt, 2 dt, ..., n dt, solving and committing each step: per step whether
// predict() extrapolated (empty after a failed solve, which is reported).
std::vector<int> steps_extrapolated(SolidModel& m, double dt, int n) {
  std::vector<int> out;
  for (int k = 1; k <= n; ++k) {
    m.set_time(dt * k);
    out.push_back(m.predict());
    const SolveReport r = m.solve();
    EXPECT_TRUE(r.converged) << "t = " << dt * k << ": " << r.message;
    if (!r.converged) return {};
    m.commit();
  }
  return out;
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

// Consistency with the definition: the balloon's pressure curve (0 -> 13 atm at t = 1 -> 0 at t = 2)
// in the steps of 0.05 of the test above, past the peak. predict() extrapolates from the second
// committed step on while the pressure keeps rising, and again once it keeps falling, but not at the
// first step after the peak; every step converges from either start.
TEST(Prediction, NotAcrossThePressurePeak) {
  SolidRunner runner(PETSC_COMM_WORLD, balloon(true), "");
  std::vector<int> expected(23, 1);  // to t = 1.15
  expected[0] = 0;                   // t = 0.05: no step before it
  expected[20] = 0;                  // t = 1.05: the first step after the peak
  EXPECT_EQ(steps_extrapolated(runner.model(), 0.05, 23), expected);
}

// Consistency with the definition: a tube (inner radius 0.8 mm) under a rising blood pressure, opened
// by an insertion tool whose radius grows from 0.5 to 0.9 mm (t = 0 to 0.5) and shrinks to 0 (t = 1),
// steps of 0.25. No step extrapolates while the tool is out (ContactModel::extrapolates), nor the
// first one after it has gone (its radius stops falling: a turn); the two after that do.
TEST(Prediction, NotWhileAnInsertionToolIsOut) {
  TubeSpec s;
  s.part = "artery";
  s.surface_prefix = "artery_";
  s.length = 3.0;
  s.inner_radius = 0.8;
  s.layers = {{"media", 0.3, 1}};
  s.n_circ = 16;
  s.n_axial = 6;
  ModelOptions o;
  o.newton.extrapolate = true;
  SolidModel model(PETSC_COMM_WORLD, make_tube(s), {{"media", {0.1566, 0.45}, {}}}, o);
  model.add_pressure({"artery_inner", [](double t) { return 0.01 * t; }});  // MPa
  model.add_springs({"artery_end0", 1e3});
  model.add_springs({"artery_end1", 1e3});
  InsertionTool::Options io;
  io.axis = {Vec3d(0, 0, -1), Vec3d(0, 0, 4)};
  io.radius = [](double t) { return t < 0.5 ? 0.5 + 0.8 * t : std::max(0.0, 0.9 * (1.0 - t) / 0.5); };  // mm
  InsertionTool tool(model, io);
  model.set_contact(&tool);
  model.start_at(0.0);
  //  t:                                     0.25 0.5 0.75 1 (tool gone) 1.25 (turn) 1.5 1.75
  EXPECT_EQ(steps_extrapolated(model, 0.25, 7), (std::vector<int>{0, 0, 0, 0, 0, 1, 1}));
}
