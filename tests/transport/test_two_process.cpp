// Request/reply between this test and a separate helper process (transport_test_server).
#include <gtest/gtest.h>

#include <chrono>
#include <string>

#include "angio/transport.hpp"
#include "test_util.hpp"

namespace at = angio::transport;
namespace tt = angio::transport::test;
using namespace std::chrono_literals;

namespace {

enum class HelperRole { Listens, Connects };

void run_exchange(HelperRole role, const std::string& endpoint) {
  const std::string prefix = tt::unique_prefix("proc");
  const std::string key = prefix + "/coupler/step";
  const std::string side = role == HelperRole::Listens ? "--listen" : "--connect";
  // This process takes the opposite side of the link.
  at::SessionConfig mine;
  (role == HelperRole::Listens ? mine.connect : mine.listen).push_back(endpoint);
  auto session = at::Session::open(mine);

  tt::ChildProcess helper({ANGIO_TRANSPORT_TEST_SERVER, side, endpoint, "--key", key, "--token",
                           prefix + "/coupler/alive", "--max-seconds", "90"});

  // The first request also waits for the helper to start, connect and declare its queryable.
  EXPECT_EQ(at::to_string(session.request(key, at::as_bytes("hello"), 60s)), "echo:hello");
  for (int i = 0; i < 10; ++i) {
    const std::string msg = "step " + std::to_string(i);
    EXPECT_EQ(at::to_string(session.request(key, at::as_bytes(msg), 20s)), "echo:" + msg);
  }
  const at::Bytes big(240'000, 0x5a);
  const at::Bytes reply = session.request(key, big, 20s);
  ASSERT_EQ(reply.size(), big.size() + 5);
  EXPECT_EQ(at::to_string(session.request(key, at::as_bytes("shutdown"), 20s)), "bye");
  EXPECT_EQ(helper.wait_exit(30s), 0);
}

}  // namespace

TEST(TransportTwoProcess, HelperListensOnUnixSocket) {
  tt::TempDir dir;
  run_exchange(HelperRole::Listens, dir.unix_endpoint());
}

TEST(TransportTwoProcess, HelperConnectsOverUnixSocket) {
  tt::TempDir dir;
  run_exchange(HelperRole::Connects, dir.unix_endpoint());
}

TEST(TransportTwoProcess, HelperListensOnTcpLoopback) { run_exchange(HelperRole::Listens, tt::free_tcp_endpoint()); }
