// Command-line options shared by the three executables, so every process answers to the same
// flags: --scene FILE, --run-dir DIR, --endpoint E, --run-id ID, --key-file F, --timeout S,
// --log-level L, --check.
#pragma once

#include <functional>
#include <initializer_list>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace angio::cli {

class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Option {
  std::string name;        // without leading dashes, e.g. "scene"
  std::string value_name;  // e.g. "FILE"; empty for a flag without value
  std::string help;
  std::string default_value;
};

class Parser {
 public:
  Parser(std::string program, std::string summary);
  Parser& add(Option o);
  Parser& add_common();  // scene, run-dir, endpoint, run-id, key-file, timeout, log-level, check

  // Returns false when --help was given (usage already printed). Throws UsageError otherwise.
  bool parse(int argc, char** argv);

  bool has(const std::string& name) const;
  std::string get(const std::string& name) const;  // value or default; throws if neither
  std::optional<std::string> maybe(const std::string& name) const;
  double number(const std::string& name) const;
  std::string usage() const;

 private:
  std::string program_, summary_;
  std::vector<Option> options_;
  std::map<std::string, std::string> values_;
};

// Applies --log-level and names the role in every log line.
void setup_logging(const Parser& p, const std::string& role);

// Throws UsageError "missing required option --NAME (see --help)" for the first option of
// `names` that was not given (or given empty).
void require(const Parser& p, std::initializer_list<const char*> names);

// The shape every executable's main() shares: parses the command line (--help → exit 0), runs
// `body` and maps failures to exit codes, each logged once: usage errors, scene errors and
// invalid arguments → 2 (bad input), any other exception → 1. Returns body's exit code otherwise.
int run_main(Parser& p, int argc, char** argv, const std::function<int()>& body);

}  // namespace angio::cli
