// Scene loading: values are read with their key path, and every bad input gives an error that
// names the file, the key path and what was expected.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "angio/scene/load_curve.hpp"
#include "angio/scene/node.hpp"

using namespace angio::scene;

namespace {
const std::string kGood = std::string(ANGIO_TEST_DATA) + "/good.yaml";

Node inline_scene(const std::string& text) { return Node(YAML::Load(text), "inline.yaml", ""); }

// Runs f, expects a SceneError whose message contains every fragment.
template <class F>
void expect_error(F f, std::initializer_list<std::string> fragments) {
  try {
    f();
    FAIL() << "no SceneError thrown";
  } catch (const SceneError& e) {
    for (const auto& s : fragments)
      EXPECT_NE(std::string(e.what()).find(s), std::string::npos) << e.what() << " lacks " << s;
  }
}
}  // namespace

TEST(Scene, ReadsValuesWithPaths) {
  Node root = load_scene(kGood);
  EXPECT_DOUBLE_EQ(root.child("stent").child("material").number("E"), 380000.0);
  EXPECT_EQ(root.child("stent").integer("rings", 1), 4);
  auto c = root.child("stent").vec3("center");
  EXPECT_DOUBLE_EQ(c[2], 1.5);
  EXPECT_EQ(root.child("stent").child("material").path(), "stent.material");
  EXPECT_FALSE(root.child("stent").has("missing"));
}

// Declared keys (core/scene/keys.yaml) carry their default, range, values and meaning: the reader
// gets the default when a key is absent, a message in the declaration's words otherwise; reading an
// undeclared key, or a key as another type, is a programming error.
TEST(Scene, DeclaredKeysGiveDefaultsRangesAndValues) {
  const Node n = inline_scene(
      "coupling: {max_iterations: 7, rel_tol: 1.5, scheme: bogus}\ntime: {steps: 3}\n"
      "artery: {layers: {media: {E: 0.1, fibers: [{k1: 0.001, k2: 0}]}}}\nload_curves: {any_name: [[0, 1]]}");
  const Node c = n.child("coupling");
  EXPECT_EQ(c.get<int>("max_iterations"), 7);
  EXPECT_DOUBLE_EQ(c.get<double>("abs_tol"), keys::defaults::coupling_abs_tol);
  EXPECT_DOUBLE_EQ(keys::defaults::coupling_abs_tol, 1e-6);  // the value keys.yaml declares
  EXPECT_TRUE(c.get<bool>("strict"));
  EXPECT_EQ(c.get<std::string>("acceleration"), "aitken");
  expect_error([&] { c.get<double>("rel_tol"); }, {"coupling.rel_tol", "expected a number in [0, 1)", "'1.5'"});
  expect_error([&] { c.get<std::string>("scheme"); },
               {"coupling.scheme", "expected one of dirichlet-neumann, robin", "'bogus'"});
  expect_error([&] { n.child("time").get<double>("end"); },
               {"time.end", "missing, expected a number (s): pseudo-time of the last step"});
  // `*` matches a layer's name, `[]` every entry of a list
  const Node f = n.child("artery").child("layers").child("media").child("fibers").at(0);
  EXPECT_DOUBLE_EQ(f.get<double>("k1"), 0.001);
  expect_error([&] { f.get<double>("k2"); }, {"artery.layers.media.fibers[0].k2", "expected a positive number"});
  EXPECT_FALSE(f.get<bool>("pair"));
  EXPECT_NO_THROW(n.child("load_curves").check_keys());
  EXPECT_THROW(c.get<double>("not_a_key"), std::logic_error);
  EXPECT_THROW(c.get<double>("max_iterations"), std::logic_error);  // declared an integer
}

TEST(Scene, DeclaredKeysRefuseUnknownOnesNamingTheNearest) {
  const Node n = inline_scene("coupling: {rel_tl: 1.0e-3}\nsolid: {newton: {max_iterations: 3}}");
  expect_error([&] { n.child("coupling").check_keys(); },
               {"coupling.rel_tl", "unknown key", "did you mean `rel_tol`?"});
  EXPECT_NO_THROW(n.child("solid").child("newton").check_keys());
}

TEST(Scene, MissingFileAndSyntaxErrors) {
  expect_error([] { load_scene("/nonexistent/scene.yaml"); }, {"/nonexistent/scene.yaml", "no such file"});
  expect_error([] { load_scene(std::string(ANGIO_TEST_DATA) + "/syntax_error.yaml"); }, {"syntax_error.yaml", "line"});
}

TEST(Scene, ErrorsNameFileKeyAndExpectation) {
  Node n = inline_scene("stent: {material: {E: -3, nu: abc}, rings: 2.5, kind: tube, v: [1, 2]}");
  Node m = n.child("stent").child("material");
  expect_error([&] { m.get<double>("E"); }, {"inline.yaml", "stent.material.E", "positive", "'-3'"});
  expect_error([&] { m.number("nu"); }, {"stent.material.nu", "a number", "'abc'"});
  expect_error([&] { m.number("G"); }, {"stent.material.G", "missing"});
  expect_error([&] { n.child("stent").integer("rings"); }, {"stent.rings", "integer"});
  expect_error(
      [&] {
        n.child("stent").choice("kind", {"corrugated_rings", "explicit"});
      },
      {"stent.kind", "'corrugated_rings'", "'tube'"});
  expect_error([&] { n.child("stent").vec3("v"); }, {"stent.v", "3 numbers"});
  expect_error([&] { n.child("stent").check_keys({"material", "rings", "kind"}); }, {"stent.v", "unknown key"});
}

TEST(Scene, NonFiniteNumbersAreRejected) {
  Node n = inline_scene("a: .nan\nb: .inf\n");
  expect_error([&] { n.number("a"); }, {"a", "finite"});
  expect_error([&] { n.number("b"); }, {"b", "finite"});
}

TEST(Scene, LoadCurvesInterpolateLinearly) {
  Node root = load_scene(kGood);
  LoadCurves curves = load_curves(root);
  const LoadCurve& p = curves.at("pressure");
  EXPECT_DOUBLE_EQ(p.value(0.5), 0.6585);
  EXPECT_DOUBLE_EQ(p.value(1.0), 1.317);
  EXPECT_DOUBLE_EQ(p.value(1.5), 0.6585);
  EXPECT_DOUBLE_EQ(p.value(3.0), 0.0);  // constant beyond the last point
  LoadCurve ref = curve_ref(root.child("stent").child("pressure"), "curve", curves);
  EXPECT_DOUBLE_EQ(ref.value(1.0), 1.317);
}

TEST(Scene, BadLoadCurvesAreRejected) {
  expect_error([] { load_curves(inline_scene("load_curves: {p: [[0, 0], [0, 1]]}")); },
               {"load_curves.p[1][0]", "larger than the previous"});
  expect_error([] { load_curves(inline_scene("load_curves: {p: [[0, 0, 1]]}")); }, {"load_curves.p[0]", "pair"});
  Node n = inline_scene("load_curves: {p: [[0, 0]]}\nload: {curve: q}");
  expect_error([&] { curve_ref(n.child("load"), "curve", load_curves(n)); }, {"load.curve", "'p'", "'q'"});
}

TEST(Scene, TimeSettings) {
  TimeSettings t = time_settings(load_scene(kGood));
  EXPECT_DOUBLE_EQ(t.end, 2.0);
  EXPECT_EQ(t.steps, 100);
  EXPECT_DOUBLE_EQ(t.min_step, 0.02 / 1024.0);
  expect_error([] { time_settings(inline_scene("time: {end: 1, steps: 0}")); },
               {"time.steps", "an integer in 1..1000000"});
  expect_error([] { time_settings(inline_scene("time: {start: 2, end: 1, steps: 3}")); }, {"time.end"});
  // stops: the load-curve corners strictly inside (start, end), sorted, each once
  const TimeSettings c =
      time_settings(inline_scene("time: {end: 2, steps: 4}\nload_curves: {a: [[0, 0], [1.3, 1], [2, 0]], b: [[-1, 0], "
                                 "[0.5, 1], [1.3, 2], [3, 0]]}"));
  EXPECT_EQ(c.stops, (std::vector<double>{0.5, 1.3}));
  EXPECT_EQ(c.max_step, 0.0);  // adaptive steps off unless asked for
  const TimeSettings a =
      time_settings(inline_scene("time: {end: 2, steps: 100, adaptive: {max_step: 0.1, easy_iterations: 3}}"));
  EXPECT_DOUBLE_EQ(a.max_step, 0.1);
  EXPECT_EQ(a.easy_iterations, 3);
  expect_error([] { time_settings(inline_scene("time: {end: 2, steps: 100, adaptive: {max_step: 0.01}}")); },
               {"time.adaptive.max_step", "larger than the nominal"});
  expect_error([] { time_settings(inline_scene("time: {end: 2, steps: 100, adaptive: {max_step: 0.1, easy: 2}}")); },
               {"time.adaptive", "easy"});
  expect_error(
      [] { time_settings(inline_scene("time: {end: 2, steps: 100, adaptive: {max_step: 0.1, easy_iterations: 0}}")); },
      {"time.adaptive.easy_iterations"});
}

// A key given twice in one map is refused with both lines (yaml-cpp alone reads the first one).
TEST(Scene, DuplicateKeysAreRejected) {
  const std::string path = ::testing::TempDir() + "dup_" + std::to_string(::getpid()) + ".yaml";
  {
    std::ofstream f(path);
    f << "time: {end: 1.0, steps: 10}\nstent:\n  material: {E: 1.0}\n  material: {E: 2.0}\n";
  }
  expect_error([&] { load_scene(path); }, {path, "stent.material", "twice", "lines 3 and 4"});
  {
    std::ofstream f(path);
    f << "time: {end: 1.0, steps: 10}\nload_curves:\n  p: [[0, 0], [1, 1]]\ntime: {end: 2.0}\n";
  }
  expect_error([&] { load_scene(path); }, {"time", "lines 1 and 4"});
  std::remove(path.c_str());
}

// A typo names the nearest valid key; an unrelated word does not get a suggestion.
TEST(Scene, UnknownKeySuggestsTheNearest) {
  const Node n = inline_scene("stent: {materail: {E: 1}}");
  expect_error(
      [&] {
        n.child("stent").check_keys({"material", "section", "generator"});
      },
      {"inline.yaml", "stent.materail", "unknown key", "did you mean `material`?"});
  try {
    n.child("stent").check_keys({"rings", "crowns"});
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()).find("did you mean"), std::string::npos) << e.what();
  }
}

// Integers are range-checked before callers cast them to int (4294967296 would wrap to 0).
TEST(Scene, IntegersOutsideIntAreRejected) {
  const Node n = inline_scene("time: {end: 1.0, steps: 4294967296}\nbig: {k: 2147483648, ok: 2147483647}");
  expect_error([&] { time_settings(n); }, {"time.steps", "expected an integer in 1..1000000", "4294967296"});
  expect_error([&] { n.child("big").integer("k"); }, {"big.k", "expected an integer", "2147483648"});
  EXPECT_EQ(n.child("big").integer("ok"), 2147483647L);
  expect_error([&] { n.child("big").integer("ok", 0, 100); }, {"big.ok", "an integer in 0..100"});
}

// Aliases and merge keys are not duplicates: a map reached twice through an alias is one map, and
// `<<` may be given more than once (the launcher's loader accepts the same).
TEST(Scene, AliasesAndMergeKeysAreNotDuplicates) {
  const std::string path = ::testing::TempDir() + "alias_" + std::to_string(::getpid()) + ".yaml";
  {
    std::ofstream f(path);
    f << "defaults: &d {E: 1.0, nu: 0.3}\nmore: &m {k: 2}\nstent:\n  material: *d\n  section: *d\n"
         "balloon:\n  <<: *d\n  <<: *m\n";
  }
  EXPECT_NO_THROW(load_scene(path));
  std::remove(path.c_str());
}
