#include "angio/solid/petsc_options_check.hpp"

#include <petscksp.h>

#include <cctype>
#include <set>
#include <sstream>

#include "angio/solid/model.hpp"

namespace angio::solid {
namespace {

// Keeps the first error message PETSc raises (instead of printing a traceback).
PetscErrorCode keep_message(MPI_Comm, int, const char*, const char*, PetscErrorCode n, PetscErrorType, const char* mess,
                            void* ctx) {
  auto* first = static_cast<std::string*>(ctx);
  if (first->empty() && mess) *first = mess;
  return n;
}

}  // namespace

PetscOptionsCheck check_petsc_options(const std::string& options) {
  PetscOptionsCheck out;
  std::set<std::string> given;  // option names in `options` (tokens "-name", not negative numbers)
  {
    std::istringstream in(options);
    for (std::string tok; in >> tok;)
      if (tok.size() > 1 && tok[0] == '-' && std::isalpha(static_cast<unsigned char>(tok[1]))) given.insert(tok);
  }
  std::string message;
  PetscOptions o = nullptr;
  Mat A = nullptr;
  Vec b = nullptr, x = nullptr;
  KSP ksp = nullptr;
  PetscPushErrorHandler(keep_message, &message);
  bool pushed = false;
  auto run = [&]() -> PetscErrorCode {
    PetscCall(PetscOptionsCreate(&o));
    PetscCall(PetscOptionsInsertString(o, petsc_default_options()));
    PetscCall(PetscOptionsInsertString(o, options.c_str()));
    PetscCall(PetscOptionsPush(o));
    pushed = true;
    PetscCall(MatCreateSeqAIJ(PETSC_COMM_SELF, 2, 2, 2, nullptr, &A));
    const PetscInt idx[2] = {0, 1};
    const PetscScalar v[4] = {2.0, -1.0, -1.0, 2.0};
    PetscCall(MatSetValues(A, 2, idx, 2, idx, v, INSERT_VALUES));
    PetscCall(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY));
    PetscCall(MatCreateVecs(A, &x, &b));
    PetscCall(VecSet(b, 1.0));
    PetscCall(KSPCreate(PETSC_COMM_SELF, &ksp));
    PetscCall(KSPSetOperators(ksp, A, A));
    PetscCall(KSPSetFromOptions(ksp));
    PetscCall(KSPSetUp(ksp));
    PetscCall(KSPSolve(ksp, b, x));
    return PetscErrorCode(0);
  };
  const PetscErrorCode err = run();
  if (err) out.error = message.empty() ? "PETSc error " + std::to_string(int(err)) : message;
  if (pushed) PetscOptionsPop();
  PetscPopErrorHandler();
  if (!err && o) {
    PetscInt n = 0;
    char** names = nullptr;
    char** values = nullptr;
    if (PetscOptionsLeftGet(o, &n, &names, &values) == PetscErrorCode(0)) {
      for (PetscInt i = 0; i < n; ++i) {
        const std::string name = std::string("-") + names[i];
        if (given.count(name)) out.unused.push_back(name);  // the defaults' own options are not the user's
      }
      PetscOptionsLeftRestore(o, &n, &names, &values);
    }
  }
  KSPDestroy(&ksp);
  VecDestroy(&x);
  VecDestroy(&b);
  MatDestroy(&A);
  if (o) PetscOptionsDestroy(&o);
  return out;
}

}  // namespace angio::solid
