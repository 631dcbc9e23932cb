// Load stepping with step cutting: reaches the end time exactly, halves on rejection, grows back,
// and gives up below the minimum increment with the reason (consistency properties).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "angio/common/load_stepper.hpp"

using angio::LoadStepper;
using angio::StepFailure;

TEST(LoadStepper, NominalSteps) {
  angio::scene::TimeSettings s;
  s.end = 2.0;
  s.steps = 100;
  s.min_step = 1e-4;
  LoadStepper st(s);
  int n = 0;
  while (!st.finished()) {
    EXPECT_NEAR(st.increment(), 0.02, 1e-12);
    st.accept(1);
    ++n;
  }
  EXPECT_EQ(n, 100);
  EXPECT_NEAR(st.previous_time(), 2.0, 1e-12);
}

TEST(LoadStepper, CutsAndRecoversOnTheNominalGrid) {
  angio::scene::TimeSettings s;
  s.end = 1.0;
  s.steps = 4;
  s.min_step = 0.01;
  LoadStepper st(s);
  st.accept(1);  // t = 0.25
  st.reject("test");
  EXPECT_DOUBLE_EQ(st.increment(), 0.125);
  EXPECT_DOUBLE_EQ(st.time(), 0.375);
  st.reject("test");
  EXPECT_DOUBLE_EQ(st.time(), 0.3125);
  st.accept(1);
  // Grows back (0.125) but does not cross the grid point 0.5 ...
  EXPECT_DOUBLE_EQ(st.time(), 0.4375);
  st.accept(1);
  EXPECT_DOUBLE_EQ(st.time(), 0.5);
  st.accept(1);
  // ... keeps doubling from the grid point until it is nominal again.
  EXPECT_DOUBLE_EQ(st.increment(), 0.125);
  std::vector<double> times;
  while (!st.finished()) {
    times.push_back(st.time());
    st.accept(1);
  }
  EXPECT_EQ(times, (std::vector<double>{0.625, 0.75, 1.0}));  // the grid and the end exactly
}

TEST(LoadStepper, GivesUpBelowMinimumWithReason) {
  angio::scene::TimeSettings s;
  s.end = 1.0;
  s.steps = 1;
  s.min_step = 0.2;
  LoadStepper st(s);
  st.reject("r1");  // 0.5
  st.reject("r2");  // 0.25
  try {
    st.reject("Newton diverged");
    FAIL();
  } catch (const StepFailure& e) {
    std::string m = e.what();
    EXPECT_NE(m.find("Newton diverged"), std::string::npos) << m;
    EXPECT_NE(m.find("step 1"), std::string::npos) << m;
  }
}

// Adaptive steps (time.adaptive), consistency of the schedule: easy steps double the increment up
// to max_step, landing on the nominal grid and on every stop (a load-curve corner) exactly; a hard
// step returns to the nominal increment; a cut step grows back to the nominal one first.
TEST(LoadStepper, AdaptiveStepsGrowOnEasyStepsAndHitTheStops) {
  angio::scene::TimeSettings s;
  s.end = 2.0;
  s.steps = 100;  // nominal 0.02
  s.min_step = 1e-4;
  s.max_step = 0.08;
  s.easy_iterations = 2;
  s.stops = {0.5, 1.0};
  LoadStepper st(s);
  std::vector<double> times;
  auto take = [&](int iterations) {
    times.push_back(st.time());
    st.accept(iterations);
  };
  take(1);  // 0.02, easy: next 0.04
  EXPECT_NEAR(st.increment(), 0.04, 1e-12);
  take(1);  // 0.06, next 0.08
  take(2);  // 0.14 (2 iterations: still easy), next 0.08 = max_step
  EXPECT_NEAR(st.increment(), 0.08, 1e-12);
  take(1);  // 0.22
  take(5);  // 0.30, hard: nominal again
  EXPECT_NEAR(st.increment(), 0.02, 1e-12);
  take(1);  // 0.32, next 0.04
  take(1);  // 0.36, next 0.08
  take(1);  // 0.44; 0.08 would cross the stop 0.5
  EXPECT_NEAR(st.time(), 0.5, 1e-12);
  while (st.time() < 1.0 - 1e-9) take(1);
  EXPECT_NEAR(st.time(), 1.0, 1e-12);  // the stop 1.0 is hit exactly
  take(1);
  const std::size_t on_grid = times.size();
  st.reject("test");
  st.reject("test");  // 0.04 -> 0.01
  const double cut = st.increment();
  take(1);
  EXPECT_LE(st.increment(), 0.02 + 1e-12);  // after a cut step: back toward nominal first
  EXPECT_GE(st.increment(), cut - 1e-12);
  while (!st.finished()) take(1);
  const std::vector<double> expected_start = {0.02, 0.06, 0.14, 0.22, 0.30, 0.32, 0.36, 0.44, 0.5};
  for (std::size_t i = 0; i < expected_start.size(); ++i) EXPECT_NEAR(times[i], expected_start[i], 1e-12) << i;
  for (std::size_t i = 0; i < on_grid; ++i) {  // every time before the cut on the nominal grid
    const double k = times[i] / 0.02;
    EXPECT_NEAR(k, std::round(k), 1e-6) << times[i];
  }
  EXPECT_NEAR(times[on_grid - 1], 1.0, 1e-12);
  EXPECT_NEAR(times.back(), 2.0, 1e-12);
  EXPECT_LT(times.size(), 60u);  // far fewer steps than the nominal 100
}

// Off (max_step = 0): never a step above the nominal one whatever the iterations; a stop off the
// grid is hit, and the increment grows back from it as after a cut (doubling, landing on the grid).
TEST(LoadStepper, FixedStepsLandOnStops) {
  angio::scene::TimeSettings s;
  s.end = 1.0;
  s.steps = 4;
  s.stops = {0.3};
  LoadStepper st(s);
  std::vector<double> times;
  while (!st.finished()) {
    EXPECT_LE(st.increment(), 0.25 + 1e-12);
    times.push_back(st.time());
    st.accept(1);
  }
  const std::vector<double> expected = {0.25, 0.3, 0.4, 0.5, 0.7, 0.75, 0.85, 1.0};
  ASSERT_EQ(times.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) EXPECT_NEAR(times[i], expected[i], 1e-12) << i;
}
