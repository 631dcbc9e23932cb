// Recording files (protocol/recording): what is written is read back byte for byte, and a damaged
// file is refused with a message naming it, before anything large is allocated (robustness).
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "angio/recording/recording.hpp"

using namespace angio;

namespace {
std::string temp_path(const char* name) { return ::testing::TempDir() + name; }

std::vector<char> slurp(const std::string& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), {}};
}

void spit(const std::string& p, const std::vector<char>& b) {
  std::ofstream f(p, std::ios::binary | std::ios::trunc);
  f.write(b.data(), std::streamsize(b.size()));
}

std::string error_of(const std::string& p) {
  try {
    recording::read(p);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

// A recording of two exchanges, in a file of the running test's own (ctest runs the tests of this
// file in parallel processes); returns its path.
std::string two_exchanges() {
  const std::string p =
      temp_path((std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + ".angiorec").c_str());
  recording::Recorder r(p, "run-A");
  r.add(fb::Role::Beam, "solve", msg::Buffer{1, 2, 3}, msg::Buffer{4, 5});
  r.add(fb::Role::Solid, "step_end", msg::Buffer{}, msg::Buffer{6});
  return p;
}
}  // namespace

TEST(Recording, RoundTrip) {
  const auto rec = recording::read(two_exchanges());
  EXPECT_EQ(rec.run_id, "run-A");
  ASSERT_EQ(rec.exchanges.size(), 2u);
  EXPECT_EQ(rec.exchanges[0].role, fb::Role::Beam);
  EXPECT_EQ(rec.exchanges[0].verb, "solve");
  EXPECT_EQ(rec.exchanges[0].request, (msg::Buffer{1, 2, 3}));
  EXPECT_EQ(rec.exchanges[0].reply, (msg::Buffer{4, 5}));
  EXPECT_EQ(rec.exchanges[1].role, fb::Role::Solid);
  EXPECT_TRUE(rec.exchanges[1].request.empty());
}

TEST(Recording, TruncatedFileIsRefused) {
  const std::string p = two_exchanges();
  auto b = slurp(p);
  b.resize(b.size() - 1);
  spit(p, b);
  const std::string m = error_of(p);
  EXPECT_NE(m.find(p), std::string::npos) << m;
  EXPECT_NE(m.find("truncated"), std::string::npos) << m;
}

// A length field of 0xFFFFFFFF (a flipped length) is refused before allocating 4 GiB.
TEST(Recording, HugeLengthIsRefusedBeforeAllocating) {
  const std::string p = two_exchanges();
  auto b = slurp(p);
  // header: magic (8) + format (4) + run id length (4) + "run-A" (5); exchange 0: role (1),
  // verb length (2) + "solve" (5), then the request length at offset 29, its data at 33
  const std::size_t at = 8 + 4 + 4 + 5 + 1 + 2 + 5;
  for (int i = 0; i < 4; ++i) b[at + i] = char(0xFF);
  spit(p, b);
  const std::string m = error_of(p);
  EXPECT_NE(m.find("4294967295 bytes for the data at offset 33 exceeds"), std::string::npos) << m;
}

TEST(Recording, UnknownRoleIsRefused) {
  const std::string p = two_exchanges();
  auto b = slurp(p);
  b[8 + 4 + 4 + 5] = char(7);  // role byte of exchange 0
  spit(p, b);
  const std::string m = error_of(p);
  EXPECT_NE(m.find("exchange 0 has role 7"), std::string::npos) << m;
}
