// coupling_summary.json through nlohmann::json: the keys scripts/report.py, bench_scenes.py,
// stability.py and the scene tests read, integers as integers, non-finite numbers as null, and the
// error message of a failed run as an escaped JSON string that reads back unchanged.
#include <unistd.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include <nlohmann/json.hpp>

#include "angio/coupler/summary.hpp"

using namespace angio::coupler;

TEST(CouplingSummary, FailedRunErrorRoundTrips) {
  RunReport r;
  r.steps = 4;
  r.total_iterations = 14;
  r.max_iterations = 6;
  r.rejected_attempts = 2;
  r.prediction_retries = 3;
  r.wall_time = 8.0;
  r.beam_time = 1.5;
  r.solid_time = 5.0;
  const std::string error = "step 5 failed: \"solid\" did not converge\n  at C:\\run\\x\ttab";
  const auto path =
      std::filesystem::temp_directory_path() / ("coupling_summary_json_test_" + std::to_string(::getpid()) + ".json");
  ASSERT_TRUE(write_coupling_summary(path.string(), "failed", error, r, 0.5));
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  const std::string text = s.str();
  std::filesystem::remove(path);
  EXPECT_EQ(text, coupling_summary_json("failed", error, r, 0.5));
  const auto j = nlohmann::ordered_json::parse(text);  // throws on invalid JSON

  EXPECT_EQ(j.at("status"), "failed");
  EXPECT_EQ(j.at("error").get<std::string>(), error);
  for (const char* k :
       {"steps", "rejected_attempts", "prediction_retries", "coupling_iterations_total", "coupling_iterations_max"})
    EXPECT_TRUE(j.at(k).is_number_integer()) << k;
  EXPECT_EQ(j.at("steps").get<int>(), 4);
  EXPECT_EQ(j.at("rejected_attempts").get<int>(), 2);
  EXPECT_EQ(j.at("prediction_retries").get<int>(), 3);
  EXPECT_EQ(j.at("coupling_iterations_total").get<int>(), 14);
  EXPECT_DOUBLE_EQ(j.at("coupling_iterations_mean").get<double>(), 3.5);
  EXPECT_EQ(j.at("coupling_iterations_max").get<int>(), 6);
  EXPECT_DOUBLE_EQ(j.at("wall_time").get<double>(), 8.0);
  EXPECT_DOUBLE_EQ(j.at("beam_time").get<double>(), 1.5);
  EXPECT_DOUBLE_EQ(j.at("solid_time").get<double>(), 5.0);
  EXPECT_DOUBLE_EQ(j.at("messaging_time").get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(j.at("messaging_share").get<double>(), 0.0625);
  std::vector<std::string> keys;
  for (const auto& [k, v] : j.items()) keys.push_back(k);
  EXPECT_EQ(keys, (std::vector<std::string>{"status", "error", "steps", "rejected_attempts", "prediction_retries",
                                            "coupling_iterations_total", "coupling_iterations_mean",
                                            "coupling_iterations_max", "wall_time", "beam_time", "solid_time",
                                            "messaging_time", "messaging_share", "jacobian_products", "product_time"}));
}

TEST(CouplingSummary, OkRunAndNonFiniteTimes) {
  RunReport r;  // no steps: mean 0, share 0 (wall time 0)
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::string text = coupling_summary_json("ok", "", r, nan);
  EXPECT_EQ(text.find("nan"), std::string::npos);
  const auto j = nlohmann::json::parse(text);
  EXPECT_EQ(j.at("status"), "ok");
  EXPECT_EQ(j.at("error"), "");
  EXPECT_EQ(j.at("steps").get<int>(), 0);
  EXPECT_DOUBLE_EQ(j.at("coupling_iterations_mean").get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(j.at("messaging_share").get<double>(), 0.0);
  EXPECT_TRUE(j.at("messaging_time").is_null());
  r.wall_time = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(nlohmann::json::parse(coupling_summary_json("ok", "", r, 1.0)).at("wall_time").is_null());
  // a file that cannot be written is reported, not thrown
  EXPECT_FALSE(write_coupling_summary("/nonexistent-dir/x/coupling_summary.json", "ok", "", r, 0.0));
}
