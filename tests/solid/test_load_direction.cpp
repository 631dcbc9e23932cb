// loads_keep_direction (load_direction.hpp): where the solid's first iterate may be extrapolated.
// Cases from the scenes' load curves: a ramp, a hold, a peak, the start and end of a ramp, a contact
// pair switched on, a tool retracting; round-off of a flat curve is no change.
#include <gtest/gtest.h>

#include "angio/solid/load_direction.hpp"

using angio::solid::loads_keep_direction;

TEST(LoadDirection, RampAndHoldContinueTurnsDoNot) {
  EXPECT_TRUE(loads_keep_direction({0.1}, {0.2}, {0.35}));  // ramp up (another slope: still up)
  EXPECT_TRUE(loads_keep_direction({0.5}, {0.4}, {0.3}));   // ramp down (a retracting tool)
  EXPECT_TRUE(loads_keep_direction({1.0}, {1.0}, {1.0}));   // hold
  EXPECT_FALSE(loads_keep_direction({0.9}, {1.0}, {0.9}));  // peak: up, then down
  EXPECT_FALSE(loads_keep_direction({0.9}, {1.0}, {1.0}));  // a ramp ends in a hold
  EXPECT_FALSE(loads_keep_direction({0.0}, {0.0}, {0.1}));  // a ramp starts from a hold
  EXPECT_FALSE(loads_keep_direction({0.0}, {0.0}, {1.0}));  // a contact pair switched on (0 -> 1)
}

TEST(LoadDirection, EveryLevelMustContinue) {
  EXPECT_TRUE(loads_keep_direction({0.1, 1.0, 0.0}, {0.2, 1.0, 0.0}, {0.3, 1.0, 0.0}));
  EXPECT_FALSE(loads_keep_direction({0.1, 1.0, 0.0}, {0.2, 1.0, 0.0}, {0.3, 1.0, 1.0}));  // the last turns
  EXPECT_TRUE(loads_keep_direction({}, {}, {}));                                          // no loads: no turn
  EXPECT_FALSE(loads_keep_direction({0.1}, {0.2, 1.0}, {0.3, 1.0}));                      // not the same loads
}

TEST(LoadDirection, RoundOffOfAFlatCurveIsNoChange) {
  const double p = 1.01;                                           // MPa, a hold
  EXPECT_TRUE(loads_keep_direction({p}, {p * (1 + 1e-15)}, {p}));  // below 1e-12 of the level: none
  EXPECT_FALSE(loads_keep_direction({p}, {p * (1 + 1e-9)}, {p}));  // a real (small) change: a turn
}
