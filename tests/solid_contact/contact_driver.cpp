// Standalone solid run with the scene's contact (same path as solid_solver's standalone mode plus
// make_contact); used until/besides the call in solid_solver/src/main.cpp. Prints the contact summary.
//   mpirun -n 2 solid_contact_driver <scene.yaml> <run-dir> [--expect-contact]
#include <mpi.h>
#include <petscsys.h>

#include <cstdio>
#include <algorithm>
#include <exception>
#include <string>

#include "angio/participant/standalone.hpp"
#include "angio/scene/node.hpp"
#include "angio/solid/contact_scene.hpp"
#include "angio/solid/participant.hpp"
#include "angio/solid/scene.hpp"

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: solid_contact_driver <scene.yaml> <run-dir>\n");
    return 2;
  }
  int fake_argc = 1;
  if (PetscInitialize(&fake_argc, &argv, nullptr, nullptr)) return 1;
  int rank = 0, code = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  try {
    const auto root = angio::scene::load_scene(argv[1]);
    auto scene = angio::solid::read_solid_scene(root);
    const auto time = scene.time;
    angio::solid::SolidRunner runner(PETSC_COMM_WORLD, std::move(scene), argv[2]);
    auto contact = angio::solid::make_contact(root, runner);
    const double t0 = MPI_Wtime();
    code = angio::participant::run_standalone(runner, time);
    const double wall = MPI_Wtime() - t0;
    // --expect-contact: fail unless balloon-artery contact is active in the final state
    if (argc > 3 && std::string(argv[3]) == "--expect-contact" && code == 0 &&
        !(contact->balloon_artery() && contact->balloon_artery()->last().num_active > 0)) {
      if (rank == 0) std::fprintf(stderr, "solid_contact_driver: no active balloon-artery contact at the end\n");
      code = 4;
    }
    if (rank == 0)
      std::printf("contact driver: exit %d, wall %.2f s, solid solves %.2f s, contact add() %.2f s (%.1f %%)\n", code,
                  wall, contact->solve_seconds(), contact->contact_seconds(),
                  100.0 * contact->contact_seconds() / std::max(contact->solve_seconds(), 1e-300));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "solid_contact_driver (rank %d): %s\n", rank, e.what());
    code = 2;
  }
  PetscFinalize();
  return code;
}
