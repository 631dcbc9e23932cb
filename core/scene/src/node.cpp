#include "angio/scene/node.hpp"

#include "angio/scene/keys.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <filesystem>
#include <set>
#include <sstream>

namespace angio::scene {

Node::Node(YAML::Node node, std::string file, std::string path)
    : node_(std::move(node)), file_(std::move(file)), path_(std::move(path)) {}

std::string Node::child_path(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

std::string Node::got() const {
  if (!node_.IsDefined() || node_.IsNull()) return "nothing";
  if (node_.IsScalar()) return "'" + node_.Scalar() + "'";
  if (node_.IsSequence()) return "a list";
  return "a map";
}

void Node::fail(const std::string& expected) const {
  std::string where = path_.empty() ? "(top level)" : path_;
  std::string msg = file_ + ": " + where + ": expected " + expected;
  if (node_.IsDefined()) msg += ", got " + got();
  throw SceneError(msg);
}

bool Node::has(const std::string& key) const { return node_.IsMap() && node_[key].IsDefined() && !node_[key].IsNull(); }

Node Node::child(const std::string& key, const std::string& what) const {
  if (!node_.IsMap()) fail("a map containing '" + key + "'");
  if (!has(key)) throw SceneError(file_ + ": " + child_path(key) + ": missing, expected " + what);
  return Node(node_[key], file_, child_path(key));
}

std::optional<Node> Node::optional(const std::string& key) const {
  if (!has(key)) return std::nullopt;
  return Node(node_[key], file_, child_path(key));
}

std::size_t Node::size() const {
  if (!node_.IsSequence()) fail("a list");
  return node_.size();
}

Node Node::at(std::size_t i) const {
  if (!node_.IsSequence()) fail("a list");
  if (i >= node_.size()) fail("at least " + std::to_string(i + 1) + " entries");
  return Node(node_[i], file_, path_ + "[" + std::to_string(i) + "]");
}

std::vector<std::string> Node::keys() const {
  if (!node_.IsMap()) fail("a map");
  std::vector<std::string> out;
  for (const auto& kv : node_) out.push_back(kv.first.as<std::string>());
  return out;
}

double Node::as_number() const {
  if (!node_.IsScalar()) fail("a number");
  // yaml-cpp accepts "nan"/".inf"; a scene value must be finite.
  double v;
  try {
    v = node_.as<double>();
  } catch (const YAML::Exception&) {
    fail("a number");
  }
  if (!std::isfinite(v)) fail("a finite number");
  return v;
}

long Node::as_integer() const {
  if (!node_.IsScalar()) fail("an integer");
  try {
    return node_.as<long>();
  } catch (const YAML::Exception&) {
    fail("an integer");
  }
}

std::string Node::as_string() const {
  if (!node_.IsScalar()) fail("a string");
  return node_.Scalar();
}

std::vector<double> Node::as_numbers() const {
  if (!node_.IsSequence()) fail("a list of numbers");
  std::vector<double> out;
  for (std::size_t i = 0; i < node_.size(); ++i) out.push_back(at(i).as_number());
  return out;
}

std::array<double, 3> Node::as_vec3() const {
  if (!node_.IsSequence() || node_.size() != 3) fail("a list of 3 numbers [x, y, z]");
  return {at(0).as_number(), at(1).as_number(), at(2).as_number()};
}

double Node::number(const std::string& key) const { return child(key, "a number").as_number(); }

long Node::integer(const std::string& key, long min, long max) const {
  constexpr long imin = std::numeric_limits<int>::min(), imax = std::numeric_limits<int>::max();
  std::string what = "an integer";
  if (min != imin && max != imax)
    what += " in " + std::to_string(min) + ".." + std::to_string(max);
  else if (min != imin)
    what += " >= " + std::to_string(min) + " (at most " + std::to_string(imax) + ")";
  else if (max != imax)
    what += " <= " + std::to_string(max);
  Node c = child(key, what);
  const long v = c.as_integer();
  if (v < min || v > max) c.fail(what);
  return v;
}

bool Node::boolean(const std::string& key) const {
  Node c = child(key, "true or false");
  if (!c.node_.IsScalar()) c.fail("true or false");
  try {
    return c.node_.as<bool>();
  } catch (const YAML::Exception&) {
    c.fail("true or false");
  }
}

std::string Node::string(const std::string& key) const { return child(key, "a string").as_string(); }

static std::string one_of(std::initializer_list<const char*> allowed) {
  std::string s = "one of";
  for (const char* a : allowed) s += std::string(" '") + a + "'";
  return s;
}

std::string Node::choice(const std::string& key, std::initializer_list<const char*> allowed) const {
  Node c = child(key, one_of(allowed));
  std::string v = c.as_string();
  for (const char* a : allowed)
    if (v == a) return v;
  c.fail(one_of(allowed));
}

const keys::Decl& Node::declaration(const std::string& key) const {
  const keys::Decl* d = keys::find(child_path(key));
  if (!d)
    throw std::logic_error("scene key '" + child_path(key) + "' is read but not declared in core/scene/keys.yaml");
  return *d;
}

namespace {
// The declaration of a key read as `type`; a reader asking for another type is a programming error.
const keys::Decl& typed(const Node& n, const std::string& key, const char* type) {
  const keys::Decl& d = n.declaration(key);
  if (!keys::has_type(d, type))
    throw std::logic_error("scene key '" + (n.path().empty() ? key : n.path() + "." + key) + "' is declared as " +
                           d.type + ", read as " + type);
  return d;
}

bool in_range(const keys::Decl& d, double v) {
  return (d.lo_open ? v > d.lo : v >= d.lo) && (d.hi_open ? v < d.hi : v <= d.hi);
}
}  // namespace

[[noreturn]] static void missing(const Node& n, const std::string& key, const keys::Decl& d) {
  n.child(key, std::string(d.expected) + ": " + d.doc);
  throw std::logic_error("unreachable");
}

namespace {
// The scalar `key` of `n` converted by yaml-cpp to T, or its declared default (converted from the
// table's number) when absent; a value that does not convert fails with the declared expectation.
template <class T>
std::pair<T, std::optional<Node>> declared_scalar(const Node& n, const std::string& key, const char* type) {
  const keys::Decl& d = typed(n, key, type);
  if (!n.has(key)) {
    if (!d.has_default) missing(n, key, d);
    return {static_cast<T>(d.default_number), std::nullopt};
  }
  const Node c = n.child(key);
  if (!c.is_scalar()) c.fail(d.expected);
  try {
    return {c.yaml().as<T>(), c};
  } catch (const YAML::Exception&) {
    c.fail(d.expected);
  }
}
}  // namespace

template <>
double Node::get<double>(const std::string& key) const {
  const auto [v, given] = declared_scalar<double>(*this, key, "number");
  const keys::Decl& d = declaration(key);
  if (given && (!std::isfinite(v) || !in_range(d, v))) given->fail(d.expected);
  return v;
}

template <>
long Node::get<long>(const std::string& key) const {
  const auto [v, given] = declared_scalar<long>(*this, key, "integer");
  // every integer key fits an int, so that callers may cast (4294967296 would wrap around to 0)
  constexpr double imin = std::numeric_limits<int>::min(), imax = std::numeric_limits<int>::max();
  const keys::Decl& d = declaration(key);
  const double x = static_cast<double>(v);
  if (given && (!in_range(d, x) || x < imin || x > imax)) given->fail(d.expected);
  return v;
}

template <>
int Node::get<int>(const std::string& key) const {
  return static_cast<int>(get<long>(key));
}

template <>
bool Node::get<bool>(const std::string& key) const {
  return declared_scalar<bool>(*this, key, "boolean").first;
}

template <>
std::string Node::get<std::string>(const std::string& key) const {
  const keys::Decl& d = typed(*this, key, "string");
  if (!has(key)) {
    if (d.has_default) return d.default_string;
    missing(*this, key, d);
  }
  const Node c = child(key);
  if (!c.node_.IsScalar()) c.fail(d.expected);
  const std::string v = c.node_.Scalar();
  if (!keys::allows(d, v)) c.fail(d.expected);
  return v;
}

template <>
std::array<double, 3> Node::get<std::array<double, 3>>(const std::string& key) const {
  const keys::Decl& d = typed(*this, key, "point");
  if (!has(key)) missing(*this, key, d);
  return child(key).as_vec3();
}

template <>
std::vector<double> Node::get<std::vector<double>>(const std::string& key) const {
  const keys::Decl& d = typed(*this, key, "numbers");
  if (!has(key)) missing(*this, key, d);
  return child(key).as_numbers();
}

std::array<double, 3> Node::vec3(const std::string& key) const {
  return child(key, "a list of 3 numbers [x, y, z]").as_vec3();
}

std::vector<double> Node::numbers(const std::string& key) const { return child(key, "a list of numbers").as_numbers(); }

std::vector<long> Node::integers(const std::string& key) const {
  Node c = child(key, "a list of integers");
  std::vector<long> out;
  for (std::size_t i = 0; i < c.size(); ++i) out.push_back(c.at(i).as_integer());
  return out;
}

void Node::check_keys() const {
  const std::vector<std::string> declared = keys::children(path_);
  if (std::find(declared.begin(), declared.end(), "*") != declared.end()) {
    if (!node_.IsMap()) fail("a map");
    return;
  }
  check_keys(declared);
}

void Node::check_keys(std::initializer_list<const char*> allowed) const {
  check_keys(std::vector<std::string>(allowed.begin(), allowed.end()));
}

namespace {
// Levenshtein distance (insertions, deletions, substitutions), for "did you mean".
std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

// Every map of the document: a key given twice is an error naming both lines (the launcher's
// SceneLoader applies the same rule). A node reached again through an alias is checked once (its
// anchor's mark identifies it), so an alias bomb costs linear time; merge keys (`<<`) may repeat.
void check_unique_keys(const YAML::Node& n, const std::string& file, const std::string& path,
                       std::set<std::pair<int, int>>& seen) {
  if (!(n.IsMap() || n.IsSequence()) || !seen.emplace(n.Mark().line, n.Mark().column).second) return;
  if (n.IsMap()) {
    std::map<std::string, int> first;
    for (const auto& kv : n) {
      const std::string k = kv.first.IsScalar() ? kv.first.Scalar() : std::string("?");
      const std::string sub = path.empty() ? k : path + "." + k;
      const int line = kv.first.Mark().line + 1;
      if (k != "<<") {
        if (const auto it = first.find(k); it != first.end())
          throw SceneError(file + ": " + sub + ": expected each key once in a map, got it twice (lines " +
                           std::to_string(it->second) + " and " + std::to_string(line) + ")");
        first.emplace(k, line);
      }
      check_unique_keys(kv.second, file, sub, seen);
    }
  } else {
    for (std::size_t i = 0; i < n.size(); ++i)
      check_unique_keys(n[i], file, path + "[" + std::to_string(i) + "]", seen);
  }
}
}  // namespace

void Node::check_keys(const std::vector<std::string>& allowed) const {
  if (!node_.IsMap()) fail("a map");
  std::set<std::string> ok(allowed.begin(), allowed.end());
  for (const auto& kv : node_) {
    std::string k = kv.first.as<std::string>();
    if (!ok.count(k)) {
      std::string list, nearest;
      std::size_t best = std::max<std::size_t>(2, k.size() / 3) + 1;
      for (const auto& a : allowed) {
        list += (list.empty() ? "" : ", ") + a;
        if (const std::size_t d = edit_distance(k, a); d < best) best = d, nearest = a;
      }
      throw SceneError(file_ + ": " + child_path(k) + ": unknown key, expected one of: " + list +
                       (nearest.empty() ? "" : "; did you mean `" + nearest + "`?"));
    }
  }
}

Node load_scene(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) throw SceneError(path + ": cannot open scene file (no such file)");
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw SceneError(path + ": YAML syntax error at line " + std::to_string(e.mark.line + 1) + ", column " +
                     std::to_string(e.mark.column + 1) + ": " + e.msg);
  }
  Node n(root, path, "");
  if (!root.IsMap()) n.fail("a YAML map at the top level");
  std::set<std::pair<int, int>> seen;
  check_unique_keys(root, path, "", seen);
  return n;
}

std::string resolve_path(const Node& node, const std::string& relative) {
  std::filesystem::path p(relative);
  if (p.is_absolute()) return p.string();
  return (std::filesystem::path(node.file()).parent_path() / p).lexically_normal().string();
}

}  // namespace angio::scene
