#include "angio/solid/materials.hpp"

#include <cmath>
#include <numbers>

namespace angio::solid {

Vec6 to_voigt_stress(const Mat3& S) {
  Vec6 s;
  for (int I = 0; I < 6; ++I) s(I) = S(kVoigt[I][0], kVoigt[I][1]);
  return s;
}

Mat3 from_voigt_stress(const Vec6& s) {
  Mat3 S;
  for (int I = 0; I < 6; ++I) {
    S(kVoigt[I][0], kVoigt[I][1]) = s(I);
    S(kVoigt[I][1], kVoigt[I][0]) = s(I);
  }
  return S;
}

double energy(const NeoHooke& m, const Mat3& C) {
  const double J = std::sqrt(C.determinant());
  const double mu = m.mu(), beta = m.beta();
  const double vol = beta == 0.0 ? -mu * std::log(J) : mu / (2.0 * beta) * (std::pow(J, -2.0 * beta) - 1.0);
  return 0.5 * mu * (C.trace() - 3.0) + vol;
}

void add_stress(const NeoHooke& m, const Mat3& C, Mat3& S, Mat6* D) {
  const double mu = m.mu(), beta = m.beta();
  const double detC = C.determinant();
  const Mat3 Ci = C.inverse();
  const double Jm2b = std::pow(detC, -beta);  // J^(-2 beta)
  S += mu * (Mat3::Identity() - Jm2b * Ci);
  if (D) {
    for (int I = 0; I < 6; ++I) {
      const int i = kVoigt[I][0], j = kVoigt[I][1];
      for (int K = 0; K < 6; ++K) {
        const int k = kVoigt[K][0], l = kVoigt[K][1];
        (*D)(I, K) +=
            2.0 * mu * beta * Jm2b * Ci(i, j) * Ci(k, l) + mu * Jm2b * (Ci(i, k) * Ci(j, l) + Ci(i, l) * Ci(j, k));
      }
    }
  }
}

double energy(const FiberFamily& f, const Mat3& C) {
  const double I4 = f.a0.dot(C * f.a0);
  if (f.tension_only && I4 <= 1.0) return 0.0;
  const double e = I4 - 1.0;
  return f.k1 / (2.0 * f.k2) * std::expm1(f.k2 * e * e);  // expm1: no cancellation near I4 = 1
}

void add_stress(const FiberFamily& f, const Mat3& C, Mat3& S, Mat6* D) {
  const double I4 = f.a0.dot(C * f.a0);
  if (f.tension_only && I4 <= 1.0) return;  // fibers carry tension only
  const double e = I4 - 1.0;
  const double ex = std::exp(f.k2 * e * e);
  const double dpsi = f.k1 * e * ex;                            // dPsi/dI4
  const double d2psi = f.k1 * ex * (1.0 + 2.0 * f.k2 * e * e);  // d2Psi/dI4^2
  const Mat3 A = f.a0 * f.a0.transpose();
  S += 2.0 * dpsi * A;
  if (D) {
    const Vec6 a = to_voigt_stress(A);
    *D += 4.0 * d2psi * a * a.transpose();
  }
}

std::vector<FiberFamily> resolve_fibers(const LayerMaterial& m, const Frame& frame) {
  std::vector<FiberFamily> out;
  for (const auto& fs : m.fibers) {
    const double phi = fs.angle_deg * std::numbers::pi / 180.0;
    FiberFamily f;
    f.k1 = fs.k1;
    f.k2 = fs.k2;
    f.tension_only = fs.tension_only;
    f.a0 = (std::cos(phi) * frame.circumferential + std::sin(phi) * frame.axial).normalized();
    out.push_back(f);
    if (fs.pair) {
      f.a0 = (std::cos(phi) * frame.circumferential - std::sin(phi) * frame.axial).normalized();
      out.push_back(f);
    }
  }
  return out;
}

double energy(const NeoHooke& m, const std::vector<FiberFamily>& fibers, const Mat3& C) {
  double psi = energy(m, C);
  for (const auto& f : fibers) psi += energy(f, C);
  return psi;
}

void stress_tangent(const NeoHooke& m, const std::vector<FiberFamily>& fibers, const Mat3& C, Mat3& S, Mat6* D) {
  S.setZero();
  if (D) D->setZero();
  add_stress(m, C, S, D);
  for (const auto& f : fibers) add_stress(f, C, S, D);
}

void first_principal_cauchy(const Mat3& F, const Mat3& S, double& s1, Vec3d& dir) {
  const double J = F.determinant();
  const Mat3 sigma = F * S * F.transpose() / J;
  Eigen::SelfAdjointEigenSolver<Mat3> es(0.5 * (sigma + sigma.transpose()));
  s1 = es.eigenvalues()(2);
  dir = es.eigenvectors().col(2);
}

}  // namespace angio::solid
