#include "angio/scene/output_settings.hpp"

namespace angio::scene {

OutputSettings output_settings(const Node& root) {
  OutputSettings o;
  if (auto out = root.optional("output")) {
    out->check_keys();
    o.every = out->get<int>("every");
    o.state = out->get<bool>("state");
  }
  return o;
}

}  // namespace angio::scene
