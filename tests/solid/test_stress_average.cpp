// The ball average of an element field (stress_average.hpp): consistency on fields it must leave
// alone, and convergence to the exact ball mean of a line load's 1/r field, where the element
// maximum grows without bound.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "angio/solid/stress_average.hpp"

using namespace angio::solid;

namespace {
// Cubic cells of size h filling [-a, a] x [-a, a] x [-c, c]: centroids and volumes.
struct Grid {
  std::vector<Vec3d> c;
  std::vector<double> v;
};
Grid cube_grid(double a, double c, double h) {
  Grid g;
  const int nx = int(std::lround(2 * a / h)), nz = int(std::lround(2 * c / h));
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < nx; ++j)
      for (int k = 0; k < nz; ++k) {
        g.c.emplace_back(-a + (i + 0.5) * h, -a + (j + 0.5) * h, -c + (k + 0.5) * h);
        g.v.push_back(h * h * h);
      }
  return g;
}
}  // namespace

// Consistency: a constant field is its own average, whatever the volumes.
TEST(StressAverage, ConstantFieldUnchanged) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0), w(0.1, 2.0);
  std::vector<Vec3d> c(500);
  std::vector<double> v(500), f(500, 2.5);
  for (int i = 0; i < 500; ++i) c[i] = Vec3d(u(rng), u(rng), u(rng)), v[i] = w(rng);
  for (double avg : ball_average(c, f, v, 0.3)) EXPECT_NEAR(avg, 2.5, 1e-14);
}

// A ball smaller than the spacing holds only its own element: the field is returned as it is.
TEST(StressAverage, SmallRadiusIsTheElementValue) {
  const Grid g = cube_grid(1.0, 1.0, 0.25);
  std::vector<double> f(g.c.size());
  for (size_t i = 0; i < f.size(); ++i) f[i] = std::sin(3 * g.c[i](0)) + g.c[i](2);
  const auto avg = ball_average(g.c, f, g.v, 0.2);
  for (size_t i = 0; i < f.size(); ++i) EXPECT_EQ(avg[i], f[i]);
}

// Exact: a linear field averaged over a ball that lies inside the grid equals its value at the
// ball's centre (the centroids in a ball around a grid point are symmetric about it).
TEST(StressAverage, LinearFieldInteriorExact) {
  const Grid g = cube_grid(1.0, 1.0, 0.1);
  std::vector<double> f(g.c.size());
  for (size_t i = 0; i < f.size(); ++i) f[i] = 1.0 + 2.0 * g.c[i](0) - 0.5 * g.c[i](1) + 3.0 * g.c[i](2);
  const auto avg = ball_average(g.c, f, g.v, 0.32);
  int interior = 0;
  for (size_t i = 0; i < f.size(); ++i)
    if (g.c[i].cwiseAbs().maxCoeff() < 1.0 - 0.32) {
      EXPECT_NEAR(avg[i], f[i], 1e-12);
      ++interior;
    }
  EXPECT_GT(interior, 1000);
}

// Analytic: the line load's stress field f = 1/s (s the distance from a line, Flamant's 1/r) has
// the exact mean 3π/(4ρ) over a ball of radius ρ centred on the line (∫ over the ball of 1/s =
// ∫_{-ρ}^{ρ} 2π √(ρ² − z²) dz = π²ρ², over the volume 4πρ³/3). Sampled at cell centroids of size
// h, the element maximum (at s = h/√2) grows as √2/h, while the maximum of the ball average
// approaches 3π/(4ρ) as h/ρ → 0.
TEST(StressAverage, LineLoadFieldConverges) {
  const double rho = 0.25, exact = 3.0 * std::numbers::pi / (4.0 * rho);
  double previous_error = std::numeric_limits<double>::infinity();
  for (int m : {2, 4, 8}) {
    const double h = rho / m;
    const Grid g = cube_grid(1.5 * rho, 1.25 * rho, h);
    std::vector<double> f(g.c.size());
    for (size_t i = 0; i < f.size(); ++i) f[i] = 1.0 / std::hypot(g.c[i](0), g.c[i](1));
    const auto avg = ball_average(g.c, f, g.v, rho);
    const double raw = *std::max_element(f.begin(), f.end());
    const double best = *std::max_element(avg.begin(), avg.end());
    EXPECT_NEAR(raw, std::sqrt(2.0) / h, 1e-9 / h);  // the element maximum: 1/h, no limit
    const double error = std::abs(best - exact) / exact;
    // first order in h/ρ (the best ball's centre sits h/√2 off the line): 0.206, 0.088, 0.044
    // measured, each halving of h at least 1.8× closer
    if (m > 2) EXPECT_GT(previous_error / error, 1.8) << "h = rho/" << m;
    previous_error = error;
  }
  EXPECT_LT(previous_error, 0.05);
}

TEST(StressAverage, RefusesBadRadius) {
  const Grid g = cube_grid(0.5, 0.5, 0.25);
  const std::vector<double> f(g.c.size(), 1.0);
  EXPECT_THROW(ball_average(g.c, f, g.v, 0.0), std::invalid_argument);
  EXPECT_THROW(ball_average(g.c, f, g.v, std::nan("")), std::invalid_argument);
  EXPECT_THROW(ball_average(g.c, f, std::vector<double>(3, 1.0), 0.1), std::invalid_argument);
}
