// Peer authentication (msg::RunKey, docs/reliability.md "Security"): HMAC-SHA256 tags over whole envelopes.
// Consistency checks (round trip, every single-byte alteration refused, another key refused) and
// the wire format against an independent HMAC-SHA256 (RFC 2104), Python's hmac module:
//   hmac.new(bytes([7] * 32), b"angio-seal-1" + b"hello", hashlib.sha256).hexdigest()
#include <gtest/gtest.h>
#include <cstdio>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "angio/messages/builders.hpp"
#include "angio/messages/seal.hpp"

using namespace angio;
namespace fs = std::filesystem;

namespace {

msg::RunKey key_of(std::uint8_t fill) {
  std::array<std::uint8_t, msg::RunKey::kKeyBytes> k{};
  k.fill(fill);
  return msg::RunKey(k);
}

// A key file in a per-process temp directory (ctest runs the cases in parallel processes).
fs::path key_file(const std::string& name, const std::string& text, fs::perms mode) {
  const fs::path dir = fs::temp_directory_path() / ("angio_seal_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path p = dir / name;
  std::ofstream(p) << text;
  fs::permissions(p, mode);
  return p;
}

const std::string kHex = "00112233445566778899aabbccddeeff00112233445566778899aabbccddeeff";

}  // namespace

TEST(Seal, RoundTripAndEveryAlterationIsRefused) {
  const auto k = key_of(7);
  const msg::Buffer env = msg::step_end(msg::Header{"run-A", 3, fb::Role::Coupler}, 9, true);
  const auto sealed = k.seal(env);
  ASSERT_EQ(sealed.size(), env.size() + msg::RunKey::kTagBytes);
  const auto back = k.unseal(sealed);
  EXPECT_TRUE(std::equal(back.begin(), back.end(), env.begin(), env.end()));
  for (std::size_t i = 0; i < sealed.size(); ++i) {  // envelope bytes and tag bytes alike
    auto bad = sealed;
    bad[i] ^= 0x01;
    EXPECT_THROW(k.unseal(bad), msg::ProtocolError) << "byte " << i;
    EXPECT_FALSE(k.verified(bad));
  }
}

TEST(Seal, TagIsHmacSha256OverDomainAndEnvelope) {
  const std::string hello = "hello";
  const auto sealed = key_of(7).seal(std::span(reinterpret_cast<const std::uint8_t*>(hello.data()), hello.size()));
  ASSERT_EQ(sealed.size(), 5 + msg::RunKey::kTagBytes);
  std::string hex;
  for (std::size_t i = 5; i < sealed.size(); ++i) {
    char d[3];
    std::snprintf(d, sizeof d, "%02x", sealed[i]);
    hex += d;
  }
  EXPECT_EQ(hex, "5ec4e0b31cfb95ccaaf9fe80f4fedf3e455b85f591487b4bc949b6231db6658d");
}

TEST(Seal, AnotherKeyOrNoTagIsRefused) {
  const msg::Buffer env = msg::shutdown(msg::Header{"run-A", 1, fb::Role::Coupler}, "done");
  EXPECT_THROW(key_of(2).unseal(key_of(1).seal(env)), msg::ProtocolError);
  EXPECT_THROW(key_of(1).unseal(env), msg::ProtocolError);  // an unsealed envelope: its tail is no tag
  EXPECT_THROW(key_of(1).unseal(std::vector<std::uint8_t>(msg::RunKey::kTagBytes, 0)), msg::ProtocolError);
  EXPECT_THROW(key_of(1).unseal({}), msg::ProtocolError);
  EXPECT_TRUE(key_of(1).verified(key_of(1).seal(env)));
}

TEST(Seal, KeyFileIsReadWhenOwnerOnly) {
  const auto p = key_file("ok.key", kHex + "\n", fs::perms::owner_read | fs::perms::owner_write);
  const auto k = msg::RunKey::read(p);
  std::array<std::uint8_t, msg::RunKey::kKeyBytes> raw{};
  for (std::size_t i = 0; i < raw.size(); ++i)
    raw[i] = static_cast<std::uint8_t>(std::stoi(kHex.substr(2 * i, 2), nullptr, 16));
  const msg::Buffer env = msg::shutdown(msg::Header{"r", 1, fb::Role::Coupler}, "x");
  EXPECT_EQ(k.seal(env), msg::RunKey(raw).seal(env));
}

TEST(Seal, BadKeyFilesAreRefusedByName) {
  const auto rw = fs::perms::owner_read | fs::perms::owner_write;
  struct Case {
    std::string name, text;
    fs::perms mode;
    std::string expect;
  };
  for (const Case& c :
       {Case{"loose.key", kHex, rw | fs::perms::group_read | fs::perms::others_read, "mode 0644"},
        Case{"short.key", kHex.substr(2), rw, "64 hex digits"}, Case{"long.key", kHex + "00", rw, "64 hex digits"},
        Case{"nothex.key", "zz" + kHex.substr(2), rw, "64 hex digits"}, Case{"empty.key", "", rw, "64 hex digits"}}) {
    const auto p = key_file(c.name, c.text, c.mode);
    try {
      msg::RunKey::read(p);
      ADD_FAILURE() << c.name << " was accepted";
    } catch (const msg::KeyFileError& e) {
      EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(c.expect), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(msg::RunKey::read("/nonexistent/run.key"), msg::KeyFileError);
  EXPECT_THROW(msg::RunKey::read(fs::temp_directory_path()), msg::KeyFileError);  // a directory
}
