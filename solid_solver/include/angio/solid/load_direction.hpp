// Whether a load step continues the path of the one before it: the test behind the solid's
// extrapolated first iterate (solid.newton.prediction).
#pragma once
#include <vector>

namespace angio::solid {

// The scalar levels a scene's loads follow (each pressure, a tool's radius, 1/0 for a contact pair
// switched on at its `from`), at the commit before the last one (`before`), at the last commit
// (`committed`) and at the new step's time (`now`), in the same order. True when every level moves
// from `committed` to `now` in the direction it moved from `before` to `committed` (up, down or not
// at all; changes below 1e-12 of the level's magnitude count as none). Linear extrapolation of the
// displacement, u_n + Δt/Δt_prev (u_n − u_n−1), is a consistent first iterate only on such a path;
// where a load turns (a pressure past its peak, a tool that stops or retracts, a ramp that starts or
// ends, a contact switched on) it moves the state away from the new equilibrium, further than the
// committed state is. Different lengths: false.
bool loads_keep_direction(const std::vector<double>& before, const std::vector<double>& committed,
                          const std::vector<double>& now);

}  // namespace angio::solid
