// solid_solver: balloon and artery as 3D nonlinear solids (MPI + PETSc + HDF5).
//
//   mpirun -n 2 solid_solver --scene configs/solid_free_balloon.yaml --run-dir runs/balloon
//       standalone load stepping (no coupler; every rank runs the stepping loop collectively)
//   mpirun -n 2 solid_solver --scene S --run-dir D --endpoint E --run-id ID
//       coupled: rank 0 serves the solid role to the coupler, ranks > 0 follow over MPI
// Exit codes: 0 success, 2 bad input (scene/mesh), 3 a step could not be completed,
// 4/5 coupler gone / transport failure (coupled mode), 1 internal error.
#include <mpi.h>
#include <petscsys.h>

#include <cstdio>
#include <exception>
#include <iostream>

#include "angio/common/cli.hpp"
#include "angio/common/log.hpp"
#include "angio/participant/standalone.hpp"
#include "angio/solid/contact_scene.hpp"
#include "angio/solid/participant.hpp"
#include "angio/solid/petsc_options_check.hpp"
#include "angio/solid/scene.hpp"
#ifdef ANGIO_SOLID_HAVE_SERVE
#include "angio/participant/role_server.hpp"
#endif

int main(int argc, char** argv) {
  // PETSc must not see our command line (it would complain about unknown options).
  int fake_argc = 1;
  char** fake_argv = argv;
  if (PetscInitialize(&fake_argc, &fake_argv, nullptr, nullptr)) return 1;
  int rank = 0, size = 1;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  int code = 0;
  {
    angio::cli::Parser cli("solid_solver",
                           "Balloon and artery (3D nonlinear solids, MPI + PETSc). Standalone load stepping, or "
                           "the solid role of a coupled run when --endpoint is given.");
    cli.add_common();
    try {
      if (!cli.parse(argc, argv)) {
        PetscFinalize();
        return 0;
      }
      angio::cli::setup_logging(cli, "solid");
      if (rank != 0) angio::log::set_level(angio::log::Level::error);
    } catch (const std::exception& e) {
      if (rank == 0) std::cerr << "solid_solver: " << e.what() << "\n" << cli.usage();
      PetscFinalize();
      return 2;
    }
    angio::solid::SolidScene scene;
    angio::scene::TimeSettings time_settings;
    angio::solid::ContactSpec contact_spec;
    try {
      const auto root = angio::scene::load_scene(cli.get("scene"));
      scene = angio::solid::read_solid_scene(root);
      time_settings = scene.time;
      contact_spec = angio::solid::read_contact_spec(root);
    } catch (const std::exception& e) {
      if (rank == 0) LOG_ERROR(e.what());
      PetscFinalize();
      return 2;
    }
    {  // PETSc's own types and packages: a refused option is bad input, before anything runs
      const auto pc =
          angio::solid::check_petsc_options(scene.options.petsc_options, angio::solid::part_names(scene.mesh));
      if (!pc.error.empty()) {
        if (rank == 0)
          LOG_ERROR(cli.get("scene") << ": solid.petsc_options: expected options PETSc accepts, got \""
                                     << scene.options.petsc_options << "\": " << pc.error);
        PetscFinalize();
        return 2;
      }
      if (scene.options.newton.reuse_preconditioner > 0 && pc.ksp_type == KSPPREONLY) {
        // preonly would take the old preconditioner alone for a solve of the current tangent
        if (rank == 0)
          LOG_ERROR(cli.get("scene") << ": solid.newton.reuse_preconditioner: expected 0 with -ksp_type preonly, or a "
                                        "Krylov solver in solid.petsc_options (-ksp_type gmres)");
        PetscFinalize();
        return 2;
      }
      if (!scene.options.newton.reuse_parts.empty() && !pc.fieldsplit) {
        if (rank == 0)
          LOG_ERROR(cli.get("scene") << ": solid.newton.reuse_parts: expected -pc_type fieldsplit in "
                                        "solid.petsc_options (one split per part), or no reuse_parts");
        PetscFinalize();
        return 2;
      }
      if (rank == 0 && !pc.unused.empty()) {
        std::string list;
        for (const auto& u : pc.unused) list += " " + u;
        LOG_WARN(cli.get("scene") << ": solid.petsc_options: not used by the linear solver (misspelt?):" << list);
      }
    }
    if (cli.has("check")) {  // the scene is valid and its mesh was built (no run directory)
      PetscFinalize();
      return 0;
    }
#ifdef ANGIO_SOLID_HAVE_SERVE
    // the run's key file on every rank before the model is built: missing or loose is bad input
    if (!cli.maybe("endpoint").value_or("").empty()) {
      try {
        angio::participant::run_key(cli);
      } catch (const std::exception& e) {
        if (rank == 0) LOG_ERROR(e.what());
        PetscFinalize();
        return 2;
      }
    }
#endif
    try {
      angio::solid::SolidRunner runner(PETSC_COMM_WORLD, std::move(scene), cli.get("run-dir"));
      const std::string endpoint = cli.maybe("endpoint").value_or("");
      // Without a coupler the solid solves with no stent points (run_standalone; a procedure's
      // balloon-only phase), so it has no stent line contact: none of its couplings (the ring
      // tangent's columns) widen the pattern every factorization pays for (docs/performance.md
      // "The procedures' contact tangent"). The same switch as the scene's `stent_*: off`.
      if (endpoint.empty()) {
        contact_spec.stent_balloon.reset();
        contact_spec.stent_artery.reset();
      }
      angio::solid::ContactSetup contact(runner, contact_spec);
      if (endpoint.empty()) {
        code = angio::participant::run_standalone(runner, time_settings);
      } else {
#ifdef ANGIO_SOLID_HAVE_SERVE
        if (rank == 0) {
          angio::solid::MpiSolidParticipant leader(runner, PETSC_COMM_WORLD);
          const auto so = angio::participant::serve_options(cli, "angio solid_solver");
          code = angio::participant::serve(leader, so);
          leader.shutdown();
        } else {
          code = angio::solid::run_follower(runner, PETSC_COMM_WORLD);
        }
        MPI_Bcast(&code, 1, MPI_INT, 0, PETSC_COMM_WORLD);
#else
        if (rank == 0) LOG_ERROR("this build has no zenoh transport; run without --endpoint");
        code = 2;
#endif
      }
    } catch (const std::exception& e) {
      std::fprintf(stderr, "solid_solver (rank %d): fatal: %s\n", rank, e.what());
      std::fflush(stderr);
      MPI_Abort(PETSC_COMM_WORLD, 1);
    }
  }
  PetscFinalize();
  return code;
}
