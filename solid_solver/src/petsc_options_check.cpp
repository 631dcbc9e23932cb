#include "angio/solid/petsc_options_check.hpp"

#include <petscksp.h>

#include <algorithm>
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

std::vector<std::string> unused_petsc_options(PetscOptions o, const std::string& options) {
  std::set<std::string> given;  // option names in `options` (tokens "-name", not negative numbers)
  {
    std::istringstream in(options);
    for (std::string tok; in >> tok;)
      if (tok.size() > 1 && tok[0] == '-' && std::isalpha(static_cast<unsigned char>(tok[1]))) given.insert(tok);
  }
  std::vector<std::string> unused;
  PetscInt n = 0;
  char** names = nullptr;
  char** values = nullptr;
  if (o && PetscOptionsLeftGet(o, &n, &names, &values) == PetscErrorCode(0)) {
    for (PetscInt i = 0; i < n; ++i) {
      const std::string name = std::string("-") + names[i];
      if (given.count(name)) unused.push_back(name);  // the defaults' own options are not the user's
    }
    PetscOptionsLeftRestore(o, &n, &names, &values);
  }
  return unused;
}

PetscOptionsCheck check_petsc_options(const std::string& options, const std::vector<std::string>& parts) {
  PetscOptionsCheck out;
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
    // the 1D Laplacian (tridiagonal, SPD) on two unknowns per part
    const PetscInt n = 2 * PetscInt(std::max<std::size_t>(parts.size(), 1));
    PetscCall(MatCreateSeqAIJ(PETSC_COMM_SELF, n, n, 3, nullptr, &A));
    for (PetscInt i = 0; i < n; ++i) {
      PetscCall(MatSetValue(A, i, i, 2.0, INSERT_VALUES));
      if (i > 0) PetscCall(MatSetValue(A, i, i - 1, -1.0, INSERT_VALUES));
      if (i + 1 < n) PetscCall(MatSetValue(A, i, i + 1, -1.0, INSERT_VALUES));
    }
    PetscCall(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY));
    PetscCall(MatCreateVecs(A, &x, &b));
    PetscCall(VecSet(b, 1.0));
    PetscCall(KSPCreate(PETSC_COMM_SELF, &ksp));
    PetscCall(KSPSetOperators(ksp, A, A));
    PetscCall(KSPSetFromOptions(ksp));
    PC pc;
    PetscCall(KSPGetPC(ksp, &pc));
    PetscBool split = PETSC_FALSE;
    PetscCall(PetscObjectTypeCompare((PetscObject)pc, PCFIELDSPLIT, &split));
    for (std::size_t k = 0; split && k < parts.size(); ++k) {
      IS is;
      PetscCall(ISCreateStride(PETSC_COMM_SELF, 2, 2 * PetscInt(k), 1, &is));
      PetscCall(PCFieldSplitSetIS(pc, parts[k].c_str(), is));
      PetscCall(ISDestroy(&is));
    }
    PetscCall(KSPSetUp(ksp));
    PetscCall(KSPSolve(ksp, b, x));
    KSPType type;
    PetscCall(KSPGetType(ksp, &type));
    out.ksp_type = type;
    out.fieldsplit = split;
    return PetscErrorCode(0);
  };
  const PetscErrorCode err = run();
  if (err) out.error = message.empty() ? "PETSc error " + std::to_string(int(err)) : message;
  if (pushed) PetscOptionsPop();
  PetscPopErrorHandler();
  if (!err) out.unused = unused_petsc_options(o, options);
  KSPDestroy(&ksp);
  VecDestroy(&x);
  VecDestroy(&b);
  MatDestroy(&A);
  if (o) PetscOptionsDestroy(&o);
  return out;
}

}  // namespace angio::solid
