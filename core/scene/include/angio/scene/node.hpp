// Validated access to a YAML scene file.
//
// Every accessor knows the file and the key path it reads, so a bad input turns into one clear
// message "scene.yaml: stent.material.E: expected a positive number, got '-3'" instead of a crash
// deep inside a solver. Units in scenes are mm, N, MPa, s.
#pragma once

#include <yaml-cpp/yaml.h>

#include "angio/scene/keys_generated.hpp"

#include <array>
#include <initializer_list>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace angio::scene {

// Thrown for any invalid scene input; what() is "<file>: <key path>: <what was expected>".
class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Node {
 public:
  Node(YAML::Node node, std::string file, std::string path);

  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }  // e.g. "stent.material.E" or "loads[2]"
  const YAML::Node& yaml() const { return node_; }

  bool is_map() const { return node_.IsMap(); }
  bool is_sequence() const { return node_.IsSequence(); }
  bool is_scalar() const { return node_.IsScalar(); }
  bool has(const std::string& key) const;

  // Required child; throws "missing key, expected <what>" when absent.
  Node child(const std::string& key, const std::string& what = "a value") const;
  std::optional<Node> optional(const std::string& key) const;

  // Sequence access.
  std::size_t size() const;  // throws unless this node is a sequence
  Node at(std::size_t i) const;
  std::vector<std::string> keys() const;  // throws unless this node is a map

  // Declared keys (core/scene/keys.yaml, the one place of each key's type, unit, default and
  // range): the value of the child `key`, or its declared default when absent; a value of the wrong
  // type or outside the declared range or values fails naming the key, and so does an absent key
  // without a default. T: double (number), long or int (integer), bool (boolean), std::string
  // (string), std::array<double, 3> (point), std::vector<double> (numbers). Reading a key that is not
  // declared, or as another type, is a programming error (std::logic_error).
  template <class T>
  T get(const std::string& key) const;
  // The declaration of the child `key` (std::logic_error when undeclared).
  const keys::Decl& declaration(const std::string& key) const;

  // Scalars read from a child key without a declaration (the raw building blocks).
  double number(const std::string& key) const;
  long integer(const std::string& key, long min = std::numeric_limits<int>::min(),
               long max = std::numeric_limits<int>::max()) const;
  bool boolean(const std::string& key) const;
  std::string string(const std::string& key) const;
  std::string choice(const std::string& key, std::initializer_list<const char*> allowed) const;
  std::array<double, 3> vec3(const std::string& key) const;
  std::vector<double> numbers(const std::string& key) const;
  std::vector<long> integers(const std::string& key) const;

  // This node itself as a scalar.
  double as_number() const;
  long as_integer() const;
  std::string as_string() const;
  std::array<double, 3> as_vec3() const;
  std::vector<double> as_numbers() const;

  // Rejects keys not declared under this node (catches typos such as "pressur:"), naming the
  // offending key and the nearest declared one ("did you mean `pressure`?").
  void check_keys() const;
  // The same against a given list (e.g. the keys of one variant of a section, a mesh from a file).
  void check_keys(std::initializer_list<const char*> allowed) const;
  void check_keys(const std::vector<std::string>& allowed) const;

  // Throws SceneError "<file>: <path>: expected <expected>[, got '<value>']".
  [[noreturn]] void fail(const std::string& expected) const;

 private:
  std::string child_path(const std::string& key) const;
  std::string got() const;

  YAML::Node node_;
  std::string file_;
  std::string path_;
};

template <>
double Node::get<double>(const std::string& key) const;
template <>
long Node::get<long>(const std::string& key) const;
template <>
int Node::get<int>(const std::string& key) const;
template <>
bool Node::get<bool>(const std::string& key) const;
template <>
std::string Node::get<std::string>(const std::string& key) const;
template <>
std::array<double, 3> Node::get<std::array<double, 3>>(const std::string& key) const;
template <>
std::vector<double> Node::get<std::vector<double>>(const std::string& key) const;

// Loads and parses a scene file; throws SceneError naming the file on I/O or syntax errors, and on a
// key given twice in one map (yaml-cpp would silently read the first, the launcher the last).
Node load_scene(const std::string& path);

// Resolves a path given in a scene relative to the scene file's directory (absolute paths pass).
std::string resolve_path(const Node& node, const std::string& relative);

}  // namespace angio::scene
