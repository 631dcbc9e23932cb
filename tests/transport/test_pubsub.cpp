// Status lines published by one session reach a subscriber in another.
#include <gtest/gtest.h>

#include <chrono>

#include "angio/transport.hpp"
#include "test_util.hpp"

namespace at = angio::transport;
namespace tt = angio::transport::test;
using namespace std::chrono_literals;

TEST(TransportPubSub, StatusLineReachesWildcardSubscriber) {
  tt::TempDir dir;
  const std::string prefix = tt::unique_prefix("status");
  auto [a, b] = tt::linked_sessions(dir.unix_endpoint());
  auto sub = a.declare_subscriber(prefix + "/*/status");
  auto pub = b.declare_publisher(prefix + "/beam/status");

  // Publications sent before the subscription has propagated are lost (pub/sub has no
  // history), so publish until one arrives, within a bounded time.
  std::optional<at::Sample> got;
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (!got && std::chrono::steady_clock::now() < deadline) {
    pub.put("step 3 converged");
    got = sub.recv(200ms);
  }
  ASSERT_TRUE(got.has_value());
  EXPECT_EQ(got->key, prefix + "/beam/status");
  EXPECT_EQ(got->text(), "step 3 converged");
}
