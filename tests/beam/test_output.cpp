// beam/summary.json through nlohmann::json: the text parses back, non-finite numbers are null
// (never NaN tokens), integers stay integers, strings are escaped, and the keys and nesting the
// consumers (scripts/report.py, bench_scenes.py, the scene tests) read are in place.
#include <unistd.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include <nlohmann/json.hpp>

#include "angio/beam/output.hpp"

using namespace angio::beam;

namespace {

BeamModel small_cantilever() {
  BeamModel m;
  const int sec = m.add_section(circular_section(1.0e4, 0.3, 0.2));
  for (int i = 0; i <= 2; ++i) m.add_node(Vec3(i, 0, 0));
  for (int i = 0; i < 2; ++i) m.add_element(i, i + 1, sec, Vec3::UnitY());
  m.fix(0, {true, true, true, true, true, true});
  m.finalize();
  return m;
}

StepRecord record(int step, double time, double diameter) {
  StepRecord r{step, time, diameter, 3, 1e-9, 0.25, 0.01};
  return r;
}

}  // namespace

TEST(BeamSummary, NonFiniteIsNullAndStringsRoundTrip) {
  const BeamModel m = small_cantilever();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<StepRecord> steps{record(1, 0.5, 2.0), record(2, 1.0, 2.5)};
  steps[0].residual = nan;
  steps[1].max_bending_moment = std::numeric_limits<double>::infinity();
  StepRecord initial = record(0, 0.0, 1.5);
  const std::string status = "odd \"status\" with a back\\slash and a\nnewline";
  const auto path =
      std::filesystem::temp_directory_path() / ("beam_summary_json_test_" + std::to_string(::getpid()) + ".json");
  const std::string text = write_summary(path.string(), m, steps, false, status, 2.0, 4, initial);

  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  EXPECT_EQ(s.str(), text);
  EXPECT_EQ(text.find("nan"), std::string::npos);
  EXPECT_EQ(text.find("inf"), std::string::npos);
  const auto j = nlohmann::json::parse(text);  // throws on invalid JSON

  EXPECT_EQ(j.at("status").get<std::string>(), status);
  EXPECT_EQ(j.at("units").at("moment"), "N mm");
  ASSERT_TRUE(j.at("num_nodes").is_number_integer());
  EXPECT_EQ(j.at("num_nodes").get<int>(), 3);
  EXPECT_EQ(j.at("num_elements").get<int>(), 2);
  EXPECT_EQ(j.at("generated_stent"), false);
  const auto& d = j.at("diameter");
  EXPECT_DOUBLE_EQ(d.at("initial").get<double>(), 1.5);
  EXPECT_DOUBLE_EQ(d.at("max").get<double>(), 2.5);
  EXPECT_DOUBLE_EQ(d.at("time_of_max").get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(d.at("final").get<double>(), 2.5);
  EXPECT_DOUBLE_EQ(d.at("recoil").get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(d.at("recoil_percent").get<double>(), 0.0);
  EXPECT_TRUE(d.at("definition").is_string());
  EXPECT_FALSE(j.contains("stent"));  // not a generated stent
  ASSERT_TRUE(j.at("newton_iterations_total").is_number_integer());
  EXPECT_EQ(j.at("newton_iterations_total").get<int>(), 6);
  EXPECT_DOUBLE_EQ(j.at("wall_seconds_total").get<double>(), 0.02);
  EXPECT_DOUBLE_EQ(j.at("newton_seconds_total").get<double>(), 2.0);
  EXPECT_DOUBLE_EQ(j.at("seconds_per_newton_iteration").get<double>(), 0.5);

  const auto& st = j.at("steps");
  ASSERT_EQ(st.size(), 2u);
  EXPECT_TRUE(st[0].at("step").is_number_integer());
  EXPECT_TRUE(st[0].at("iterations").is_number_integer());
  EXPECT_TRUE(st[0].at("residual").is_null());            // NaN
  EXPECT_TRUE(st[1].at("max_bending_moment").is_null());  // inf
  EXPECT_DOUBLE_EQ(st[1].at("residual").get<double>(), 1e-9);
  EXPECT_FALSE(st[0].contains("distal_diameter"));
  // the keys in the order they were always written
  const auto ordered = nlohmann::ordered_json::parse(text);
  std::vector<std::string> keys;
  for (const auto& [k, v] : ordered.at("steps")[0].items()) keys.push_back(k);
  EXPECT_EQ(keys, (std::vector<std::string>{"step", "time", "diameter", "iterations", "residual", "max_bending_moment",
                                            "wall_seconds"}));

  const auto& x = j.at("final_positions");
  ASSERT_EQ(x.size(), 3u);
  for (int n = 0; n < 3; ++n) {
    ASSERT_EQ(x[n].size(), 3u);
    for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(x[n][k].get<double>(), m.position(n)(k));
  }
  std::filesystem::remove(path);
}

// A generated stent: the "stent" block and the per-step stent measures; NaN measures are null.
TEST(BeamSummary, GeneratedStentBlock) {
  const BeamModel m = small_cantilever();
  std::vector<StepRecord> steps{record(1, 0.5, 2.0), record(2, 1.0, 3.0), record(3, 1.5, 2.8)};
  for (auto& s : steps) {
    s.distal_diameter = s.diameter + 0.2;
    s.central_diameter = s.diameter;
    s.length = 10.0 - s.step * 0.1;
    s.axis_sagitta = 0.0;  // axis_radius stays NaN: straight
  }
  StepRecord initial = record(0, 0.0, 1.5);
  initial.length = 10.0;
  initial.axis_sagitta = 0.0;
  const auto path =
      std::filesystem::temp_directory_path() / ("beam_summary_stent_json_test_" + std::to_string(::getpid()) + ".json");
  const auto j = nlohmann::json::parse(write_summary(path.string(), m, steps, true, "completed", 1.0, 0, initial));
  std::filesystem::remove(path);
  const auto& s = j.at("stent");
  EXPECT_DOUBLE_EQ(s.at("length_initial").get<double>(), 10.0);
  EXPECT_NEAR(s.at("length_at_max_diameter").get<double>(), 9.8, 1e-12);
  EXPECT_NEAR(s.at("length_final").get<double>(), 9.7, 1e-12);
  EXPECT_NEAR(s.at("foreshortening_final_percent").get<double>(), 3.0, 1e-12);
  EXPECT_DOUBLE_EQ(s.at("distal_diameter_at_max").get<double>(), 3.2);
  EXPECT_DOUBLE_EQ(s.at("central_diameter_at_max").get<double>(), 3.0);
  EXPECT_NEAR(s.at("dogboning_max_percent").get<double>(), 100.0 * 0.2 / 2.2, 1e-12);
  EXPECT_DOUBLE_EQ(s.at("time_of_dogboning_max").get<double>(), 0.5);
  EXPECT_TRUE(s.at("axis_radius_initial").is_null());
  EXPECT_TRUE(s.at("axis_radius_at_max_diameter").is_null());
  EXPECT_TRUE(s.at("axis_radius_final").is_null());
  EXPECT_DOUBLE_EQ(s.at("axis_sagitta_final").get<double>(), 0.0);
  EXPECT_TRUE(s.at("definitions").is_string());
  EXPECT_NEAR(j.at("diameter").at("recoil").get<double>(), 0.2, 1e-12);
  EXPECT_DOUBLE_EQ(j.at("seconds_per_newton_iteration").get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(j.at("steps")[1].at("distal_diameter").get<double>(), 3.2);
  EXPECT_NEAR(j.at("steps")[1].at("length").get<double>(), 9.8, 1e-12);
  EXPECT_DOUBLE_EQ(j.at("steps")[1].at("axis_sagitta").get<double>(), 0.0);
}
