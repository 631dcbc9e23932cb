#include "angio/messages/step_state.hpp"

#include <cmath>
#include <string>

namespace angio::msg {

namespace {
std::string name(const fb::Envelope& env) { return payload_name(env.payload_type()); }
}  // namespace

void StepState::check(const fb::Envelope& env) {
  const auto type = env.payload_type();
  if (type == fb::Payload::Hello) {
    greeted_ = true;
    return;
  }
  if (type == fb::Payload::Shutdown) return;
  if (!greeted_) throw ProtocolError(name(env) + " before Hello");
  auto in_this_step = [&](std::uint32_t step) {
    if (!open_) throw ProtocolError(name(env) + " for step " + std::to_string(step) + " outside a step (no StepBegin)");
    if (step != step_)
      throw ProtocolError(name(env) + " for step " + std::to_string(step) + " while step " + std::to_string(step_) +
                          " is open");
  };
  switch (type) {
    case fb::Payload::StepBegin: {
      const auto& s = *env.payload_as_StepBegin();
      if (!std::isfinite(s.time()) || !std::isfinite(s.dt()) || s.dt() < 0.0)
        throw ProtocolError("StepBegin for step " + std::to_string(s.step()) + " with time " +
                            std::to_string(s.time()) + " and increment " + std::to_string(s.dt()) +
                            " (expected finite values, increment >= 0)");
      if (open_)
        throw ProtocolError("StepBegin for step " + std::to_string(s.step()) + " while step " + std::to_string(step_) +
                            " is open (no StepEnd)");
      open_ = true;
      step_ = s.step();
      return;
    }
    case fb::Payload::BeamSolveRequest:
      in_this_step(env.payload_as_BeamSolveRequest()->step());
      return;
    case fb::Payload::BeamLinearRequest:
      in_this_step(env.payload_as_BeamLinearRequest()->step());
      return;
    case fb::Payload::SolidLinearRequest:
      in_this_step(env.payload_as_SolidLinearRequest()->step());
      return;
    case fb::Payload::SolidSolveRequest: {
      const auto& r = *env.payload_as_SolidSolveRequest();
      in_this_step(r.step());
      if (!std::isfinite(r.tolerance()) || r.tolerance() < 0.0)
        throw ProtocolError("SolidSolveRequest with tolerance " + std::to_string(r.tolerance()) +
                            " (expected a finite value >= 0)");
      return;
    }
    case fb::Payload::StepEnd:
      in_this_step(env.payload_as_StepEnd()->step());
      open_ = false;
      return;
    default:
      return;  // anything else is the dispatcher's to refuse
  }
}

}  // namespace angio::msg
