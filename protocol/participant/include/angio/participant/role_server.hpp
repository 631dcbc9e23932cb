// Serving a participant role to the coupler over zenoh: the beam_solver and solid_solver
// executables (and the replay participant) call serve() and everything about messages,
// verification, sequence numbers, liveliness and timeouts happens here, not in the solvers.
#pragma once

#include <chrono>
#include <optional>
#include <string>

#include "angio/common/cli.hpp"
#include "angio/messages/seal.hpp"
#include "angio/participant/beam_participant.hpp"
#include "angio/participant/solid_participant.hpp"

namespace angio::participant {

struct ServeOptions {
  std::string endpoint;  // the coupler's endpoint to connect to
  std::string run_id;
  std::chrono::milliseconds timeout{600000};  // longest silence from the coupler before giving up
  std::string software;                       // name/version sent in the handshake
  std::optional<msg::RunKey> key;             // the run's secret: requests must carry its tag, replies get it
};

// Options from the common command line (--endpoint, --run-id, --timeout, --key-file or
// <run-dir>/run.key) of a participant; a missing or loose key file throws msg::KeyFileError.
ServeOptions serve_options(const cli::Parser& args, std::string software);
// The run's key of a coupled process: --key-file if given, else <run-dir>/run.key (the launcher
// writes it). Throws msg::KeyFileError (exit 2) naming the file when it is missing or loose.
msg::RunKey run_key(const cli::Parser& args);

// Exit codes of serve(): 0 after a Shutdown request; 4 when the coupler disappeared or stayed
// silent longer than the timeout; 5 when the transport could not be opened.
int serve(BeamParticipant& beam, const ServeOptions& options);
int serve(SolidParticipant& solid, const ServeOptions& options);

}  // namespace angio::participant
