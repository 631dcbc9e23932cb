// Building the messages of the protocol, each wrapped in an Envelope (run id, sequence, version).
#pragma once

#include <string>

#include "angio/messages/envelope.hpp"
#include "angio/participant/types.hpp"

namespace angio::msg {

struct Header {
  std::string run_id;
  std::uint64_t sequence = 0;
  fb::Role sender = fb::Role::Coupler;
};

Buffer hello(const Header& h, const std::string& software);
Buffer hello_reply(const Header& h, const std::string& software,
                   const participant::SamplePoints* points /* beam only */);
Buffer step_begin(const Header& h, std::uint32_t step, double time, double dt);
// planes: robin mode (nullptr: plain Dirichlet–Neumann request)
Buffer beam_solve_request(const Header& h, std::uint32_t step, std::uint32_t iteration,
                          const std::vector<participant::Vec3>& line_loads,
                          const participant::ContactPlanes* planes = nullptr);
Buffer beam_solve_reply(const Header& h, const participant::SolveStats& stats, double wall_time,
                        const participant::SamplePoints& points);
Buffer solid_solve_request(const Header& h, std::uint32_t step, std::uint32_t iteration,
                           const participant::SamplePoints& points, double tolerance);
Buffer solid_solve_reply(const Header& h, const participant::SolveStats& stats, double wall_time,
                         const participant::ContactReply& contact);
// Linearized responses at the last solve (the interface Newton–Krylov): per plane a shift along its
// normal (mm) and a turn of the normal to the beam, the sample points' displacement back; the points'
// displacement to the solid, per plane its shift and turn back.
Buffer beam_linear_request(const Header& h, std::uint32_t step, std::uint32_t iteration,
                           const std::vector<double>& plane_shift, const std::vector<participant::Vec3>& normal_turn);
Buffer beam_linear_reply(const Header& h, const participant::SolveStats& stats, double wall_time,
                         const std::vector<participant::Vec3>& dx);
Buffer solid_linear_request(const Header& h, std::uint32_t step, std::uint32_t iteration,
                            const std::vector<participant::Vec3>& dx);
Buffer solid_linear_reply(const Header& h, const participant::SolveStats& stats, double wall_time,
                          const std::vector<double>& plane_shift, const std::vector<participant::Vec3>& normal_turn);
Buffer step_end(const Header& h, std::uint32_t step, bool accept);
Buffer ack(const Header& h);
Buffer shutdown(const Header& h, const std::string& reason);
Buffer error(const Header& h, const std::string& message, std::uint32_t step = 0, std::uint32_t iteration = 0,
             const std::vector<double>& residual_history = {});

}  // namespace angio::msg
