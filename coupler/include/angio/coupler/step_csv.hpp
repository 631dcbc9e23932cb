// The per-step CSV of a coupled run (docs/design.md §9): one row per accepted load step.
#pragma once

#include <fstream>
#include <string>

#include "angio/coupler/coupling_loop.hpp"

namespace angio::coupler {

class StepCsv {
 public:
  explicit StepCsv(const std::string& path);  // throws std::runtime_error naming the path
  // `pressure`: value of the scene's reporting load curve at the step's time;
  // `messaging`: s of this step's solve round trips not spent in the solvers.
  void write(const StepReport& r, double pressure, double messaging);

 private:
  std::ofstream out_;
};

}  // namespace angio::coupler
