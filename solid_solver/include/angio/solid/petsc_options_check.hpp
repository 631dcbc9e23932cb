// The scene's solid.petsc_options tried before anything runs: a Krylov method, preconditioner or
// factorization package that PETSc does not know fails at the first solve otherwise, after the
// mesh is built and the coupled processes have started.
#pragma once

#include <petscsys.h>

#include <string>
#include <vector>

namespace angio::solid {

struct PetscOptionsCheck {
  std::string error;                // PETSc's own message for the first refused option ("" = accepted)
  std::vector<std::string> unused;  // options of `options` no object asked for (typos, or for other objects)
  std::string ksp_type;             // the Krylov method they select (e.g. "preonly", "gmres")
  bool fieldsplit = false;          // they select -pc_type fieldsplit (one split per part)
};

// Sets up and runs a KSP with petsc_default_options() and then `options` on a small system (this
// rank only, PETSC_COMM_SELF; PETSc initialized), two unknowns per name of `parts` (the mesh's parts,
// Block::part): with -pc_type fieldsplit each part is a split named after it, as SolidModel defines
// them, so that the options of each split (-fieldsplit_artery_pc_type ...) are tried too. Never throws
// for a refused option.
PetscOptionsCheck check_petsc_options(const std::string& options, const std::vector<std::string>& parts = {});

// The options named in `options` that nothing has queried from the database `o` (null: none).
std::vector<std::string> unused_petsc_options(PetscOptions o, const std::string& options);

}  // namespace angio::solid
