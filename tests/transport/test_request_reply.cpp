// Request/reply between two sessions of one process, over a unix socket and over tcp.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "angio/transport.hpp"
#include "test_util.hpp"

namespace at = angio::transport;
namespace tt = angio::transport::test;
using namespace std::chrono_literals;

namespace {

// Serves `queryable` on a background thread until destroyed.
class BackgroundServer {
 public:
  BackgroundServer(at::Queryable& q, at::Queryable::Handler handler)
      : thread_([this, &q, handler = std::move(handler)] {
          q.serve(
              handler, [this] { return stop_.load(); }, 20ms);
        }) {}
  ~BackgroundServer() {
    stop_ = true;
    thread_.join();
  }

 private:
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

at::Bytes pattern(std::size_t n) {
  at::Bytes b(n);
  for (std::size_t i = 0; i < n; ++i) b[i] = static_cast<std::uint8_t>((i * 131 + 7) % 251);
  return b;
}

at::Bytes reversed(at::ByteView v) { return at::Bytes(v.rbegin(), v.rend()); }

void exchange_small_and_large(const std::string& endpoint) {
  const std::string key = tt::unique_prefix("rr") + "/coupler/step";
  auto [server, client] = tt::linked_sessions(endpoint);
  auto queryable = server.declare_queryable(key);
  BackgroundServer bg(queryable, [](const at::IncomingQuery& q) { return reversed(q.payload()); });

  const at::Bytes small{1, 2, 3, 4, 5};
  EXPECT_EQ(client.request(key, small, 20s), reversed(small));

  const at::Bytes large = pattern(240'000);  // 10,000 3-vectors of doubles
  for (int i = 0; i < 3; ++i) {
    const at::Bytes reply = client.request(key, large, 20s);
    ASSERT_EQ(reply.size(), large.size());
    EXPECT_EQ(reply, reversed(large));
  }

  const at::Bytes empty;
  EXPECT_TRUE(client.request(key, empty, 20s).empty());

  // "Wait forever" must not overflow any deadline arithmetic.
  EXPECT_EQ(client.request(key, small, std::chrono::milliseconds::max()), reversed(small));
}

}  // namespace

TEST(TransportRequestReply, UnixSocketSmallAndLargePayloads) {
  tt::TempDir dir;
  exchange_small_and_large(dir.unix_endpoint());
}

TEST(TransportRequestReply, TcpLoopbackSmallAndLargePayloads) { exchange_small_and_large(tt::free_tcp_endpoint()); }

TEST(TransportRequestReply, HandlerExceptionBecomesRemoteError) {
  tt::TempDir dir;
  const std::string key = tt::unique_prefix("err") + "/coupler/step";
  auto [server, client] = tt::linked_sessions(dir.unix_endpoint());
  auto queryable = server.declare_queryable(key);
  BackgroundServer bg(queryable,
                      [](const at::IncomingQuery&) -> at::Bytes { throw std::runtime_error("bad step index"); });
  try {
    client.request(key, at::as_bytes("x"), 20s);
    FAIL() << "expected RemoteError";
  } catch (const at::RemoteError& e) {
    EXPECT_NE(std::string(e.what()).find("bad step index"), std::string::npos) << e.what();
  }
}

TEST(TransportRequestReply, ManualRecvAndReplyExposeKey) {
  tt::TempDir dir;
  const std::string key = tt::unique_prefix("manual") + "/beam/forces";
  auto [server, client] = tt::linked_sessions(dir.unix_endpoint());
  auto queryable = server.declare_queryable(key);
  std::thread t([&] {
    const auto deadline = std::chrono::steady_clock::now() + 30s;
    while (std::chrono::steady_clock::now() < deadline) {
      auto q = queryable.recv(100ms);
      if (!q) continue;
      EXPECT_EQ(q->key(), key);
      EXPECT_EQ(at::to_string(q->payload()), "ping");
      q->reply(at::as_bytes("pong"));
      EXPECT_TRUE(q->answered());
      return;
    }
  });
  EXPECT_EQ(at::to_string(client.request(key, at::as_bytes("ping"), 20s)), "pong");
  t.join();
}

// A filtered request takes the reply its callback accepts even when another replier on the key
// answers first (the coupler's defence against a foreign peer); without an acceptable reply it
// times out, and an error reply from the foreign peer does not pre-empt the real one.
TEST(TransportRequestReply, AcceptSkipsRefusedRepliesFromOtherRepliers) {
  tt::TempDir dir;
  const std::string key = tt::unique_prefix("acc") + "/solid/solve";
  auto [server, client] = tt::linked_sessions(dir.unix_endpoint());
  auto foreign_session = at::Session::open({.listen = {}, .connect = {dir.unix_endpoint()}});
  auto real = server.declare_queryable(key);
  auto foreign = foreign_session.declare_queryable(key);
  BackgroundServer fast(foreign, [](const at::IncomingQuery&) -> at::Bytes { throw std::runtime_error("garbage"); });
  BackgroundServer slow(real, [](const at::IncomingQuery&) {
    std::this_thread::sleep_for(200ms);  // the foreign error reply arrives first
    return at::Bytes{'g', 'o', 'o', 'd'};
  });
  const auto good = [](at::ByteView b) { return at::to_string(b) == "good"; };
  EXPECT_EQ(at::to_string(client.request(key, at::as_bytes("q"), 20s, good)), "good");
  const auto nothing = [](at::ByteView) { return false; };
  EXPECT_THROW(client.request(key, at::as_bytes("q"), 1s, nothing), at::TransportError);
}

TEST(TransportSession, ListenOnBusyEndpointFails) {
  tt::TempDir dir;
  auto first = at::Session::open({.listen = {dir.unix_endpoint()}, .connect = {}});
  EXPECT_THROW(at::Session::open({.listen = {dir.unix_endpoint()}, .connect = {}}), at::TransportError);
}

TEST(TransportSession, InvalidEndpointFails) {
  EXPECT_THROW(at::Session::open({.listen = {"nonsense"}, .connect = {}}), at::TransportError);
}

TEST(TransportSession, DefaultEndpointIsUnixSocketInRunDir) {
  EXPECT_EQ(at::default_endpoint_for("/tmp/run1"), "unixsock-stream//tmp/run1/angio.sock");
  EXPECT_THROW(at::default_endpoint_for("/tmp/" + std::string(120, 'x')), at::TransportError);
}
