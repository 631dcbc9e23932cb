// Load stepping with step cutting: reaches the end time exactly, halves on rejection, grows back,
// and gives up below the minimum increment with the reason (consistency properties).
#include <gtest/gtest.h>

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
    st.accept();
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
  st.accept();  // t = 0.25
  st.reject("test");
  EXPECT_DOUBLE_EQ(st.increment(), 0.125);
  EXPECT_DOUBLE_EQ(st.time(), 0.375);
  st.reject("test");
  EXPECT_DOUBLE_EQ(st.time(), 0.3125);
  st.accept();
  // Grows back (0.125) but does not cross the grid point 0.5 ...
  EXPECT_DOUBLE_EQ(st.time(), 0.4375);
  st.accept();
  EXPECT_DOUBLE_EQ(st.time(), 0.5);
  st.accept();
  // ... keeps doubling from the grid point until it is nominal again.
  EXPECT_DOUBLE_EQ(st.increment(), 0.125);
  std::vector<double> times;
  while (!st.finished()) {
    times.push_back(st.time());
    st.accept();
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
