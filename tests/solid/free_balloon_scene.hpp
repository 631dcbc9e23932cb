// The free balloon of configs/solid_free_balloon.yaml inflated 0 -> 13 atm in `steps` load steps
// (its first half, t in [0, 1]), no step cuts, MUMPS and a tight Newton atol: the reference for the
// tests that compare two ways of reaching the same equilibria (elastic, pressure-controlled, one
// equilibrium per pressure).
#pragma once
#include <string>

#include "angio/solid/scene.hpp"

inline angio::solid::SolidScene free_balloon_inflation(int steps) {
  const auto root = angio::scene::load_scene(std::string(ANGIO_CONFIGS_DIR) + "/solid_free_balloon.yaml");
  angio::solid::SolidScene sc = angio::solid::read_solid_scene(root);
  sc.time.end = 1.0;  // inflation only: 0 -> 13 atm
  sc.time.steps = steps;
  sc.time.max_cuts = 0;  // a failed step ends the run
  sc.options.petsc_options = "-ksp_type preonly -pc_type lu -pc_factor_mat_solver_type mumps";
  sc.options.newton.atol = 1e-8;
  return sc;
}
