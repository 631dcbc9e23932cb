// Requests that cannot be answered must end with TimeoutError close to their timeout.
#include <gtest/gtest.h>

#include <chrono>
#include <optional>
#include <thread>

#include "angio/transport.hpp"
#include "test_util.hpp"

namespace at = angio::transport;
namespace tt = angio::transport::test;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

namespace {

// Generous upper slack for a loaded 2-core machine; the point is "finite", not "precise".
constexpr auto kSlack = 5s;

// Runs a request expected to time out; returns the elapsed time.
Clock::duration expect_timeout(const at::Session& s, const std::string& key, std::chrono::milliseconds timeout) {
  const auto t0 = Clock::now();
  try {
    s.request(key, at::as_bytes("hello"), timeout);
    ADD_FAILURE() << "request to " << key << " unexpectedly succeeded";
  } catch (const at::TimeoutError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(key), std::string::npos) << what;
    EXPECT_NE(what.find(std::to_string(timeout.count()) + " ms"), std::string::npos) << what;
  }
  const auto elapsed = Clock::now() - t0;
  EXPECT_GE(elapsed, timeout - 50ms);
  EXPECT_LT(elapsed, timeout + kSlack);
  return elapsed;
}

}  // namespace

TEST(TransportTimeout, NoQueryableOnKey) {
  tt::TempDir dir;
  auto s = at::Session::open({.listen = {dir.unix_endpoint()}, .connect = {}});
  expect_timeout(s, tt::unique_prefix("noq") + "/coupler/step", 700ms);
}

TEST(TransportTimeout, PeerNeverStarted) {
  tt::TempDir dir;
  // Nobody listens on this socket: the session keeps retrying the connection in background.
  auto s = at::Session::open({.listen = {}, .connect = {dir.unix_endpoint("absent.sock")}});
  expect_timeout(s, tt::unique_prefix("absent") + "/coupler/step", 700ms);
}

TEST(TransportTimeout, QueryableThatNeverAnswers) {
  tt::TempDir dir;
  const std::string key = tt::unique_prefix("silent") + "/coupler/step";
  auto [server, client] = tt::linked_sessions(dir.unix_endpoint());
  auto queryable = server.declare_queryable(key);
  // The first query is answered so that the route is known to exist; the second is held
  // unanswered, so its timeout is of the "did not answer" kind.
  std::optional<at::IncomingQuery> held;
  std::thread holder([&] {
    const auto deadline = Clock::now() + 60s;
    bool warmed_up = false;
    while (!held && Clock::now() < deadline) {
      auto q = queryable.recv(50ms);
      if (!q) continue;
      if (warmed_up) {
        held = std::move(q);
      } else {
        q->reply(at::as_bytes("ok"));
        warmed_up = true;
      }
    }
  });
  EXPECT_EQ(at::to_string(client.request(key, at::as_bytes("warmup"), 30s)), "ok");
  const auto t0 = Clock::now();
  try {
    client.request(key, at::as_bytes("hello"), 1500ms);
    ADD_FAILURE() << "unexpected reply";
  } catch (const at::TimeoutError& e) {
    EXPECT_NE(std::string(e.what()).find("did not answer"), std::string::npos) << e.what();
  }
  const auto elapsed = Clock::now() - t0;
  EXPECT_GE(elapsed, 1450ms);
  EXPECT_LT(elapsed, 1500ms + kSlack);
  holder.join();
  ASSERT_TRUE(held.has_value());
}

TEST(TransportTimeout, RequestOnceReportsNoReplyImmediately) {
  tt::TempDir dir;
  auto s = at::Session::open({.listen = {dir.unix_endpoint()}, .connect = {}});
  const auto t0 = Clock::now();
  EXPECT_THROW(s.request_once(tt::unique_prefix("once") + "/x", at::as_bytes("a"), 10s), at::NoReplyError);
  EXPECT_LT(Clock::now() - t0, 5s);
}
