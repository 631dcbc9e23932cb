// Lookup in the declared scene keys (core/scene/keys.yaml, compiled into keys_generated.hpp).
#pragma once

#include <string>
#include <vector>

#include "angio/scene/keys_generated.hpp"

namespace angio::scene::keys {

// The declaration of a concrete key path such as "artery.layers.media.fibers[0].k1" (list indices
// match `[]`, any name matches `*`; an exact name wins over `*`), or nullptr when undeclared.
const Decl* find(const std::string& path);
// The keys a map at `path` may hold ("*" among them when any name is allowed).
std::vector<std::string> children(const std::string& path);
// Whether the declaration admits the type `t` (one of its '|'-separated types).
bool has_type(const Decl& d, const std::string& t);
// Whether the declaration lists the string `v` among its values (true when it lists none).
bool allows(const Decl& d, const std::string& v);

}  // namespace angio::scene::keys
