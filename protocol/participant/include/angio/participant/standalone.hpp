// Load stepping for a single participant (beam-only or solid-only scenes): no coupler, no
// coupling iterations, the same step cutting as the coupler.
#pragma once

#include "angio/participant/beam_participant.hpp"
#include "angio/participant/solid_participant.hpp"
#include "angio/scene/load_curve.hpp"

namespace angio::participant {

// Both return the process exit code: 0 on success, 3 when a step could not be completed
// (the error, with step, time and residual history, is logged; committed output stays intact).
int run_standalone(BeamParticipant& beam, const scene::TimeSettings& time);
int run_standalone(SolidParticipant& solid, const scene::TimeSettings& time);

}  // namespace angio::participant
