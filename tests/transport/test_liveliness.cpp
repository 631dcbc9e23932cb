// Liveliness tokens: a peer that disappears (dropped token, or killed process) is noticed.
#include <gtest/gtest.h>

#include <chrono>

#include "angio/transport.hpp"
#include "test_util.hpp"

namespace at = angio::transport;
namespace tt = angio::transport::test;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

TEST(TransportLiveliness, DroppedTokenIsSeenGone) {
  tt::TempDir dir;
  const std::string key = tt::unique_prefix("live") + "/beam/alive";
  auto [watcher_session, peer] = tt::linked_sessions(dir.unix_endpoint());
  auto watcher = watcher_session.watch_liveliness(key);
  {
    auto token = peer.declare_liveliness_token(key);
    ASSERT_TRUE(watcher.wait_until_alive(30s));
    EXPECT_EQ(watcher.alive_keys().count(key), 1u);
    EXPECT_TRUE(watcher_session.liveliness_alive(key, 5s));
  }
  EXPECT_TRUE(watcher.wait_until_gone(10s));
  EXPECT_FALSE(watcher_session.liveliness_alive(key, 1s));
}

TEST(TransportLiveliness, KilledProcessIsDetected) {
  tt::TempDir dir;
  const std::string prefix = tt::unique_prefix("kill");
  const std::string token_key = prefix + "/coupler/alive";
  auto session = at::Session::open({.listen = {dir.unix_endpoint()}, .connect = {}});
  auto watcher = session.watch_liveliness(prefix + "/*/alive");

  tt::ChildProcess helper({ANGIO_TRANSPORT_TEST_SERVER, "--connect", dir.unix_endpoint(), "--key",
                           prefix + "/coupler/step", "--token", token_key, "--max-seconds", "90"});
  ASSERT_TRUE(watcher.wait_until_alive(60s)) << "helper token never appeared";
  EXPECT_EQ(watcher.alive_keys().count(token_key), 1u);

  helper.kill_now();
  const auto t0 = Clock::now();
  EXPECT_EQ(helper.wait_exit(10s), -9);
  ASSERT_TRUE(watcher.wait_until_gone(10s)) << "killed peer still considered alive";
  const auto detected_ms = std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - t0).count();
  RecordProperty("detection_ms", static_cast<int>(detected_ms));
  EXPECT_LT(detected_ms, 5000);
}
