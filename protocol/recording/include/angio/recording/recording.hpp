// Recording of the exchanges of a run (docs/design.md §4.6): every request the
// coupler sends and the reply it gets, in order, as the raw flatbuffers bytes.
//
// File layout (little endian): "ANGIOREC" u32 format_version, u32 len + run id; then per exchange
//   u8 role, u16 len + verb, u32 len + request bytes, u32 len + reply bytes.
// Raw bytes make a replay bit-exact and keep the format independent of the schema's evolution
// (the envelope inside carries the protocol version).
#pragma once

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "angio/messages/envelope.hpp"

namespace angio::recording {

struct Exchange {
  fb::Role role;
  std::string verb;
  msg::Buffer request;
  msg::Buffer reply;
};

class Recorder {
 public:
  Recorder(const std::string& path, const std::string& run_id);  // throws on I/O error
  void add(fb::Role role, const std::string& verb, const msg::Buffer& request, const msg::Buffer& reply);
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::ofstream out_;
};

struct Recording {
  std::string run_id;
  std::vector<Exchange> exchanges;
};

// Throws std::runtime_error naming the file on a missing, foreign or truncated recording.
Recording read(const std::string& path);

}  // namespace angio::recording
