#include "angio/scene/output_settings.hpp"

namespace angio::scene {

OutputSettings output_settings(const Node& root) {
  OutputSettings o;
  if (auto out = root.optional("output")) {
    out->check_keys({"every", "state"});
    o.every = int(out->integer_or("every", o.every, 1));
    o.state = out->boolean_or("state", o.state);
  }
  return o;
}

}  // namespace angio::scene
