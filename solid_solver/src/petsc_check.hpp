// Private to solid_solver/src: turn a non-zero PetscErrorCode into std::runtime_error naming the call.
#pragma once
#include <petscsys.h>

#include <stdexcept>
#include <string>

#define ANGIO_PETSC(call)                                                                                              \
  do {                                                                                                                 \
    PetscErrorCode ierr_ = (call);                                                                                     \
    if (ierr_)                                                                                                         \
      throw std::runtime_error(std::string("PETSc error in ") + #call + " (code " + std::to_string(int(ierr_)) + ")"); \
  } while (0)
