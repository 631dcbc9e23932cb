// Beam state files (state_file.hpp): the stent of configs/beam_stent_radial_expansion.yaml expanded
// plastically to its peak in 40 steps, its state written, and the unloading continued from the file
// in 40 more, ends where the uninterrupted 80-step run ends (consistency: positions, rotations and
// plastic strains restored exactly); the same continuation without the plastic strains does not
// (the check sees them). A state lands only on the stent it came from.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "angio/beam/participant.hpp"

using namespace angio::beam;

namespace {
// one directory per test: ctest runs the tests of this file as concurrent processes
std::filesystem::path kDir;
void use_directory(const std::string& test) {
  kDir = std::filesystem::temp_directory_path() / ("beam_state_file_test_" + test);
  std::filesystem::remove_all(kDir);
}

std::string scene_text() {
  std::ifstream f(std::string(ANGIO_SOURCE_DIR) + "/configs/beam_stent_radial_expansion.yaml");
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}
// The scene with its time line replaced and `initial` (an initial_state entry) added to the stent.
BeamScene scene(const std::string& time, const std::string& initial = "") {
  std::string t = std::regex_replace(scene_text(), std::regex("time: \\{[^}]*\\}"), time);
  if (!initial.empty())
    t = std::regex_replace(t, std::regex("\nstent:\n"), "\nstent:\n  initial_state: " + initial + "\n");
  std::filesystem::create_directories(kDir);
  const auto path = kDir / "scene.yaml";
  std::ofstream(path) << t;
  return load_beam_scene(path.string());
}
std::vector<Vec3> run(BeamScene sc, const std::string& dir) {
  const auto time = sc.time;
  BeamSolverParticipant p(std::move(sc), dir);
  const std::vector<angio::participant::Vec3> no_contact(p.sample_points().size(), {0, 0, 0});
  for (int s = 1; s <= time.steps; ++s) {  // the radial line load of the scene, no contact
    p.begin_step(s, time.start + (time.end - time.start) * s / time.steps);
    const auto st = p.solve(no_contact);
    EXPECT_TRUE(st.converged) << st.message;
    p.end_step(true);
  }
  p.finish();
  return p.model().positions();
}
double max_difference(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double d = 0.0;
  for (size_t i = 0; i < a.size(); ++i) d = std::max(d, (a[i] - b[i]).norm());
  return d;
}
}  // namespace

TEST(BeamStateFile, ContinuedRunEndsWhereTheUninterruptedRunEnds) {
  use_directory("continued");
  const auto whole = run(scene("time: {end: 2.0, steps: 80}"), "");
  run(scene("time: {end: 1.0, steps: 40}"), (kDir / "first").string());
  const std::string state = (kDir / "first" / "beam" / "state.h5").string();
  const BeamState s = read_beam_state(state);
  EXPECT_NEAR(s.time, 1.0, 1e-15);
  double kappa = 0.0;
  for (const auto& p : s.plastic) kappa = std::max(kappa, p.kappa_bar);
  EXPECT_GT(kappa, 0.0);  // expanded plastically

  const auto continued = run(scene("time: {start: 1.0, end: 2.0, steps: 40}", "{file: " + state + "}"), "");
  const double diff = max_difference(whole, continued);
  std::printf("continued - uninterrupted: %.3e mm\n", diff);
  EXPECT_LT(diff, 1e-10);

  BeamScene elastic = scene("time: {start: 1.0, end: 2.0, steps: 40}", "{file: " + state + "}");
  for (auto& p : elastic.initial_state->plastic) p = PlasticState{};
  EXPECT_GT(max_difference(whole, run(std::move(elastic), "")), 0.01);  // the recoil is another one
}

TEST(BeamStateFile, MismatchesAreSceneErrorsNamingTheKey) {
  use_directory("mismatches");
  run(scene("time: {end: 0.1, steps: 2}"), (kDir / "first").string());
  const std::string state = (kDir / "first" / "beam" / "state.h5").string();
  auto message = [&](const std::string& text, const std::string& time) {
    try {
      std::string t = std::regex_replace(scene_text(), std::regex("time: \\{[^}]*\\}"), time);
      t = std::regex_replace(t, std::regex("\nstent:\n"), "\nstent:\n  initial_state: {file: " + state + "}\n");
      t = std::regex_replace(t, std::regex("crowns: 8"), text);
      const auto path = kDir / "bad.yaml";
      std::ofstream(path) << t;
      load_beam_scene(path.string());
    } catch (const angio::scene::SceneError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::string other = message("crowns: 6", "time: {start: 0.1, end: 1.0, steps: 1}");
  EXPECT_NE(other.find("stent.initial_state.file"), std::string::npos) << other;
  EXPECT_NE(other.find("a different stent"), std::string::npos) << other;
  EXPECT_NE(message("crowns: 8", "time: {start: 0.2, end: 1.0, steps: 1}").find("time.start"), std::string::npos);
}
