#include "angio/coupler/interface_scheme.hpp"

#include <stdexcept>

#include "angio/coupler/dirichlet_neumann.hpp"
#include "angio/coupler/robin.hpp"

namespace angio::coupler {

std::unique_ptr<InterfaceScheme> make_interface_scheme(const std::string& name, std::size_t n_points,
                                                       bool surface_compliance) {
  if (name == "robin") return std::make_unique<Robin>(n_points, surface_compliance);
  if (name == "dirichlet-neumann") return std::make_unique<DirichletNeumann>(n_points);
  throw std::invalid_argument("unknown coupling scheme '" + name + "' (dirichlet-neumann | robin)");
}

}  // namespace angio::coupler
