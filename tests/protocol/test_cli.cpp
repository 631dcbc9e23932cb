// Command-line handling shared by the executables: values, defaults, --help, clear usage errors.
#include <gtest/gtest.h>

#include "angio/common/cli.hpp"

using angio::cli::Parser;
using angio::cli::UsageError;

namespace {
bool parse(Parser& p, std::vector<std::string> args) {
  std::vector<char*> argv;
  static std::string prog = "prog";
  argv.push_back(prog.data());
  for (auto& a : args) argv.push_back(a.data());
  return p.parse(static_cast<int>(argv.size()), argv.data());
}
}  // namespace

TEST(Cli, ValuesDefaultsAndErrors) {
  Parser p("prog", "test");
  p.add_common();
  EXPECT_TRUE(parse(p, {"--scene", "a.yaml", "--timeout=5"}));
  EXPECT_EQ(p.get("scene"), "a.yaml");
  EXPECT_DOUBLE_EQ(p.number("timeout"), 5.0);
  EXPECT_EQ(p.get("run-id"), "run");  // default
  Parser q("prog", "test");
  q.add_common();
  EXPECT_THROW(parse(q, {"--nope"}), UsageError);
  Parser r("prog", "test");
  r.add_common();
  EXPECT_THROW(parse(r, {"--scene"}), UsageError);
  Parser s("prog", "test");
  s.add_common();
  parse(s, {"--timeout", "soon"});
  EXPECT_THROW(s.number("timeout"), UsageError);
}

TEST(Cli, HelpReturnsFalse) {
  Parser p("prog", "test");
  p.add_common();
  testing::internal::CaptureStdout();
  EXPECT_FALSE(parse(p, {"--help"}));
  EXPECT_NE(testing::internal::GetCapturedStdout().find("--scene FILE"), std::string::npos);
}
