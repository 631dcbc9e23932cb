// Round-trip latency of request/reply between two processes, for payloads shaped like the
// coupling data (n 3-vectors of doubles). Driven by bench/bench_transport_latency.py.
//
//   transport_latency_bench server --listen EP --key K
//       echoes every request; an empty request is the shutdown signal.
//   transport_latency_bench client --connect EP --key K [--vectors 1000,10000]
//                                  [--rounds 200] [--warmup 20] [--label NAME]
//       prints one JSON line per payload size, then shuts the server down.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "angio/transport.hpp"

namespace at = angio::transport;
using namespace std::chrono_literals;

namespace {

std::map<std::string, std::string> parse_flags(int argc, char** argv, int first) {
  std::map<std::string, std::string> flags;
  for (int i = first; i + 1 < argc; i += 2) {
    if (std::strncmp(argv[i], "--", 2) != 0) throw std::runtime_error(std::string("unexpected argument ") + argv[i]);
    flags[argv[i] + 2] = argv[i + 1];
  }
  return flags;
}

std::string flag(const std::map<std::string, std::string>& f, const std::string& name, const std::string& dflt = "") {
  auto it = f.find(name);
  if (it != f.end()) return it->second;
  if (dflt.empty()) throw std::runtime_error("missing --" + name);
  return dflt;
}

int run_server(const std::map<std::string, std::string>& f) {
  auto session = at::Session::open({.listen = {flag(f, "listen")}, .connect = {}});
  auto queryable = session.declare_queryable(flag(f, "key"));
  bool stop = false;
  std::cout << "ready" << std::endl;
  queryable.serve(
      [&stop](const at::IncomingQuery& q) {
        if (q.payload().empty()) stop = true;
        return at::Bytes(q.payload().begin(), q.payload().end());
      },
      [&stop] { return stop; });
  return 0;
}

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  const auto idx = static_cast<std::size_t>(p * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(idx, v.size() - 1)];
}

int run_client(const std::map<std::string, std::string>& f) {
  const std::string key = flag(f, "key");
  const int rounds = std::stoi(flag(f, "rounds", "200"));
  const int warmup = std::stoi(flag(f, "warmup", "20"));
  const std::string label = flag(f, "label", "unnamed");
  std::vector<std::size_t> sizes;
  std::stringstream ss(flag(f, "vectors", "1000,10000"));
  for (std::string item; std::getline(ss, item, ',');) sizes.push_back(std::stoul(item));

  auto session = at::Session::open({.listen = {}, .connect = {flag(f, "connect")}});
  for (std::size_t n : sizes) {
    std::vector<double> vec(3 * n);
    for (std::size_t i = 0; i < vec.size(); ++i) vec[i] = 0.001 * static_cast<double>(i);
    const at::ByteView payload(reinterpret_cast<const std::uint8_t*>(vec.data()), vec.size() * sizeof(double));
    // The first request also waits for the server to be connected and declared.
    session.request(key, payload, 30s);
    for (int i = 0; i < warmup; ++i) session.request(key, payload, 10s);
    std::vector<double> us;
    us.reserve(static_cast<std::size_t>(rounds));
    for (int i = 0; i < rounds; ++i) {
      const auto t0 = std::chrono::steady_clock::now();
      const at::Bytes reply = session.request(key, payload, 10s);
      const auto t1 = std::chrono::steady_clock::now();
      if (reply.size() != payload.size()) throw std::runtime_error("echo size mismatch");
      us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
    }
    std::printf(
        "{\"transport\": \"%s\", \"vectors\": %zu, \"bytes\": %zu, \"round_trips\": %d, "
        "\"median_us\": %.1f, \"p90_us\": %.1f, \"min_us\": %.1f}\n",
        label.c_str(), n, payload.size(), rounds, percentile(us, 0.5), percentile(us, 0.9),
        *std::min_element(us.begin(), us.end()));
    std::fflush(stdout);
  }
  session.request(key, {}, 10s);  // shutdown
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc < 2) throw std::runtime_error("usage: transport_latency_bench server|client --flag value ...");
    const std::string role = argv[1];
    const auto flags = parse_flags(argc, argv, 2);
    if (role == "server") return run_server(flags);
    if (role == "client") return run_client(flags);
    throw std::runtime_error("unknown role " + role);
  } catch (const std::exception& e) {
    std::cerr << "transport_latency_bench: " << e.what() << "\n";
    return 1;
  }
}
