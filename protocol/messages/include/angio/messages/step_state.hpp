// The order of requests a participant accepts (docs/design.md §4.4): Hello first; then per load step a
// StepBegin (finite time and increment), solve requests for that step (a solid's with a finite
// tolerance >= 0), and a StepEnd for that step;
// Shutdown at any time. A request out of this order is refused with a ProtocolError (the role server
// answers it with an Error) and leaves the state as it was, so a stray or forged request cannot
// commit, roll back or solve anything.
#pragma once

#include <cstdint>

#include "angio/messages/envelope.hpp"

namespace angio::msg {

class StepState {
 public:
  // Throws ProtocolError if `env` may not come now; otherwise advances the state.
  void check(const fb::Envelope& env);
  bool in_step() const { return open_; }

 private:
  bool greeted_ = false;
  bool open_ = false;
  std::uint32_t step_ = 0;
};

}  // namespace angio::msg
