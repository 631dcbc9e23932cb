// Conversions between flatbuffers tables and the plain interface types of participant/.
// Vector lengths are checked: a message whose arrays disagree in length is a ProtocolError.
#pragma once

#include "angio/messages/envelope.hpp"
#include "angio/participant/types.hpp"

namespace angio::msg {

std::vector<participant::Vec3> to_vec3s(const flatbuffers::Vector<const fb::Vec3*>* v);
std::vector<double> to_doubles(const flatbuffers::Vector<double>* v);
participant::SamplePoints to_sample_points(const fb::SamplePoints* p);
participant::SolveStats to_stats(const fb::SolveStats* s);
participant::ContactReply to_contact(const fb::SolidSolveReply& r);

}  // namespace angio::msg
