// Validated access to a YAML scene file.
//
// Every accessor knows the file and the key path it reads, so a bad input turns into one clear
// message "scene.yaml: stent.material.E: expected a positive number, got '-3'" instead of a crash
// deep inside a solver. Units in scenes are mm, N, MPa, s.
#pragma once

#include <yaml-cpp/yaml.h>

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

  // Scalars read from a child key.
  double number(const std::string& key) const;
  double number_or(const std::string& key, double fallback) const;
  double positive(const std::string& key) const;                      // > 0
  double positive_or(const std::string& key, double fallback) const;  // > 0 when given
  double non_negative(const std::string& key) const;                  // >= 0
  double non_negative_or(const std::string& key, double fallback) const;
  double in_range(const std::string& key, double lo, double hi) const;  // lo <= v <= hi
  // Integers are range-checked before any caller casts them: by default to the range of int, so a
  // count such as `steps: 4294967296` is refused here instead of wrapping around to 0 in an int.
  long integer(const std::string& key, long min = std::numeric_limits<int>::min(),
               long max = std::numeric_limits<int>::max()) const;
  long integer_or(const std::string& key, long fallback, long min = std::numeric_limits<int>::min(),
                  long max = std::numeric_limits<int>::max()) const;
  bool boolean(const std::string& key) const;
  bool boolean_or(const std::string& key, bool fallback) const;
  std::string string(const std::string& key) const;
  std::string string_or(const std::string& key, const std::string& fallback) const;
  std::string choice(const std::string& key, std::initializer_list<const char*> allowed) const;
  std::string choice_or(const std::string& key, std::initializer_list<const char*> allowed,
                        const std::string& fallback) const;
  std::array<double, 3> vec3(const std::string& key) const;
  std::vector<double> numbers(const std::string& key) const;
  std::vector<long> integers(const std::string& key) const;

  // This node itself as a scalar.
  double as_number() const;
  long as_integer() const;
  std::string as_string() const;
  std::array<double, 3> as_vec3() const;
  std::vector<double> as_numbers() const;

  // Rejects keys not in `allowed` (catches typos such as "pressur:"), naming the offending key and
  // the nearest allowed one ("did you mean `pressure`?").
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

// Loads and parses a scene file; throws SceneError naming the file on I/O or syntax errors, and on a
// key given twice in one map (yaml-cpp would silently read the first, the launcher the last).
Node load_scene(const std::string& path);

// Resolves a path given in a scene relative to the scene file's directory (absolute paths pass).
std::string resolve_path(const Node& node, const std::string& relative);

}  // namespace angio::scene
