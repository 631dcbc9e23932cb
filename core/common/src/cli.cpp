#include "angio/common/cli.hpp"

#include <cstdio>
#include <sstream>

#include "angio/common/log.hpp"
#include "angio/scene/node.hpp"

namespace angio::cli {

Parser::Parser(std::string program, std::string summary) : program_(std::move(program)), summary_(std::move(summary)) {}

Parser& Parser::add(Option o) {
  options_.push_back(std::move(o));
  return *this;
}

Parser& Parser::add_common() {
  add({"scene", "FILE", "scene file (YAML; units mm, N, MPa, s)", ""});
  add({"run-dir", "DIR", "run directory for output (created if missing)", "run"});
  add({"endpoint", "ENDPOINT", "zenoh endpoint of the coupler, e.g. unixsock-stream//path/c.sock or tcp/127.0.0.1:7447",
       ""});
  add({"run-id", "ID", "run id shared by all processes of one run (key prefix, envelope check)", "run"});
  add({"key-file", "FILE",
       "the run's secret key (64 hex digits, mode 0600) that authenticates every message; default <run-dir>/run.key, "
       "which the launcher writes",
       ""});
  // One solid solve can take many minutes where the balloon unfolds against the wall (generic artery
  // with the paper's end springs: up to 54 s per solve on 2 cores, a continued solve over 600 s): the
  // silence that means a frozen peer is longer than that. A vanished peer is noticed at once anyway
  // (liveliness token).
  add({"timeout", "SECONDS", "give up when the peer is silent or gone this long", "1800"});
  add({"log-level", "LEVEL", "debug, info, warn or error", "info"});
  add({"check", "", "read and check the scene (and build the model), then exit: 0 valid, 2 the error", ""});
  return *this;
}

std::string Parser::usage() const {
  std::ostringstream os;
  os << "Usage: " << program_ << " [options]\n" << summary_ << "\n\nOptions:\n";
  for (const auto& o : options_) {
    std::string lhs = "  --" + o.name + (o.value_name.empty() ? "" : " " + o.value_name);
    os << lhs << std::string(lhs.size() < 28 ? 28 - lhs.size() : 1, ' ') << o.help;
    if (!o.default_value.empty()) os << " (default: " << o.default_value << ")";
    os << "\n";
  }
  os << "  --help                    print this help and exit\n";
  return os.str();
}

bool Parser::parse(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::fputs(usage().c_str(), stdout);
      return false;
    }
    if (a.rfind("--", 0) != 0) throw UsageError("unexpected argument '" + a + "' (see --help)");
    std::string name = a.substr(2), value;
    bool inline_value = false;
    if (auto eq = name.find('='); eq != std::string::npos) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
      inline_value = true;
    }
    const Option* opt = nullptr;
    for (const auto& o : options_)
      if (o.name == name) opt = &o;
    if (!opt) throw UsageError("unknown option '--" + name + "' (see --help)");
    if (opt->value_name.empty()) {
      value = "1";
    } else if (!inline_value) {
      if (i + 1 >= argc) throw UsageError("option --" + name + " needs a value " + opt->value_name);
      value = argv[++i];
    }
    values_[name] = value;
  }
  return true;
}

bool Parser::has(const std::string& name) const { return values_.count(name) > 0; }

std::optional<std::string> Parser::maybe(const std::string& name) const {
  if (auto it = values_.find(name); it != values_.end()) return it->second;
  for (const auto& o : options_)
    if (o.name == name && !o.default_value.empty()) return o.default_value;
  return std::nullopt;
}

std::string Parser::get(const std::string& name) const {
  auto v = maybe(name);
  if (!v) throw UsageError("missing required option --" + name + " (see --help)");
  return *v;
}

double Parser::number(const std::string& name) const {
  std::string v = get(name);
  try {
    std::size_t pos = 0;
    double d = std::stod(v, &pos);
    if (pos != v.size()) throw std::invalid_argument(v);
    return d;
  } catch (const std::exception&) {
    throw UsageError("option --" + name + ": expected a number, got '" + v + "'");
  }
}

void setup_logging(const Parser& p, const std::string& role) {
  log::set_role(role);
  try {
    log::set_level(log::parse_level(p.get("log-level")));
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--log-level: ") + e.what());
  }
}

void require(const Parser& p, std::initializer_list<const char*> names) {
  for (const char* n : names)
    if (!p.has(n) || p.get(n).empty())
      throw UsageError(std::string("missing required option --") + n + " (see --help)");
}

int run_main(Parser& p, int argc, char** argv, const std::function<int()>& body) {
  try {
    if (!p.parse(argc, argv)) return 0;
    return body();
  } catch (const UsageError& e) {
    LOG_ERROR(e.what());
    return 2;
  } catch (const scene::SceneError& e) {
    LOG_ERROR(e.what());
    return 2;
  } catch (const std::invalid_argument& e) {
    LOG_ERROR(e.what());
    return 2;
  } catch (const std::exception& e) {
    LOG_ERROR(e.what());
    return 1;
  }
}

}  // namespace angio::cli
