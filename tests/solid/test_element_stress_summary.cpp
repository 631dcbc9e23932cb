// The per-step element stress summary computed by each rank on its own elements (element_stress_summary.hpp)
// against the same measures computed from every element at once (consistency: the partition must not
// change them beyond the rounding of the ball averages' sums). Run under mpirun with 1 or 2 ranks.
#include <gtest/gtest.h>
#include <mpi.h>
#include <petscsys.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "angio/solid/artery_measures.hpp"
#include "angio/solid/element_stress_summary.hpp"
#include "angio/solid/elements.hpp"
#include "angio/solid/model.hpp"
#include "angio/solid/stress_average.hpp"

using namespace angio::solid;

namespace angio_test {
Mesh cube_mesh(ElemType t, int n, double perturb, unsigned seed);
}

namespace {

// Every element's value and volume on every rank (element index order).
void all_elements(const SolidModel& model, const std::vector<double>& p1, const std::vector<double>& vol,
                  std::vector<double>& all_p1, std::vector<double>& all_vol) {
  const std::size_t ne = model.mesh().elements.size();
  all_p1.assign(ne, 0.0);
  all_vol.assign(ne, 0.0);
  const auto& le = model.local_elements();
  for (std::size_t i = 0; i < le.size(); ++i) {
    all_p1[std::size_t(le[i])] = p1[i];
    all_vol[std::size_t(le[i])] = vol[i];
  }
  MPI_Allreduce(MPI_IN_PLACE, all_p1.data(), int(ne), MPI_DOUBLE, MPI_SUM, PETSC_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, all_vol.data(), int(ne), MPI_DOUBLE, MPI_SUM, PETSC_COMM_WORLD);
}

}  // namespace

// A stress field peaked at the cube's centre (the origin: the cube spans −0.5..0.5), averaged over
// balls (radius 0.3, 4 × 4 × 4 elements) that reach across a cut of the cube into two: the maximum's
// ball needs the other rank's Gauss points (asserted). The reference takes every element's Gauss points and centres
// (their centroids, then every node) at once, as the summary did on rank 0 before.
TEST(ElementStressSummary, EqualsTheSummaryOfAllElementsOnAnyPartition) {
  const double radius = 0.3;
  for (ElemType t : {ElemType::Hex8, ElemType::Tet10}) {
    Mesh m = angio_test::cube_mesh(t, 4, 0.08, 3);
    for (auto& X : m.X) X -= Vec3d(0.5, 0.5, 0.5);  // negative coordinates: cells below zero
    ModelOptions o;
    o.partitioner = "ptscotch";
    SolidModel model(PETSC_COMM_WORLD, m, {LayerMaterial{"cube", {1.0, 0.3}, {}}}, o);
    std::vector<Vec3d> u(m.X.size());
    for (std::size_t n = 0; n < u.size(); ++n) u[n] = Vec3d(0.05 * m.X[n].y() * m.X[n].z(), 0.03 * m.X[n].x(), 0.0);
    model.set_displacement(u);
    auto position = [&](int n) { return Vec3d(m.X[std::size_t(n)] + u[std::size_t(n)]); };  // any node, any rank
    std::vector<double> p1, vol;
    std::vector<Vec3d> dir;
    model.element_stress(p1, dir, &vol);
    const auto& le = model.local_elements();
    auto centroid = [&](int e) {
      Vec3d c = Vec3d::Zero();
      for (int a = 0; a < m.elements[std::size_t(e)].nn(); ++a) c += position(m.elements[std::size_t(e)].n[a]);
      return Vec3d(c / double(m.elements[std::size_t(e)].nn()));
    };
    for (std::size_t i = 0; i < le.size(); ++i)
      p1[i] = std::exp(-centroid(le[i]).squaredNorm() / 0.05) + 0.01 * double(le[i] % 7);

    const std::vector<ElementStressSummary> s = element_stress_summary(PETSC_COMM_WORLD, model, p1, vol, radius);
    ASSERT_EQ(s.size(), 1u);
    std::vector<double> all_p1, all_vol, owner;
    all_elements(model, p1, vol, all_p1, all_vol);
    {  // each element's rank, to see that the maximum's ball needs another rank's points
      int me = 0;
      MPI_Comm_rank(PETSC_COMM_WORLD, &me);
      std::vector<double> mine(le.size(), double(me));
      std::vector<double> unused;
      all_elements(model, mine, vol, owner, unused);
    }
    int rank = 0;
    MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
    if (rank != 0) continue;

    // the reference: every element at once
    std::vector<Vec3d> centres, points;
    std::vector<double> point_value, point_weight, point_owner;
    double best = -std::numeric_limits<double>::infinity();
    Vec3d where = Vec3d::Zero();
    for (std::size_t e = 0; e < m.elements.size(); ++e) {
      const auto& el = m.elements[e];
      centres.push_back(centroid(int(e)));
      if (all_p1[e] > best) {
        best = all_p1[e];
        where = centres.back();
      }
      const auto& rule = volume_rule(el.type);
      double wsum = 0.0;
      for (const auto& q : rule) wsum += q.w;
      Eigen::VectorXd N;
      Eigen::MatrixXd dN;
      for (const auto& q : rule) {
        shape(el.type, q.xi, N, dN);
        Vec3d x = Vec3d::Zero();
        for (int a = 0; a < el.nn(); ++a) x += N(a) * position(el.n[a]);
        points.push_back(x);
        point_owner.push_back(owner[e]);
        point_value.push_back(all_p1[e]);
        point_weight.push_back(all_vol[e] * q.w / wsum);
      }
    }
    for (std::size_t n = 0; n < m.X.size(); ++n) centres.push_back(position(int(n)));
    const BallMaximum ref = max_ball_average(centres, points, point_value, point_weight, radius);
    ASSERT_NE(ref.centre, BallMaximum::none);
    int size = 1;
    MPI_Comm_size(PETSC_COMM_WORLD, &size);
    if (size > 1) {  // else the test could not tell a missing exchange
      std::vector<char> seen(std::size_t(size), 0);
      for (std::size_t q = 0; q < points.size(); ++q)
        if ((points[q] - centres[ref.centre]).norm() <= radius) seen[std::size_t(point_owner[q])] = 1;
      EXPECT_GT(std::count(seen.begin(), seen.end(), 1), 1) << "the maximum's ball lies on one rank";
    }

    EXPECT_EQ(s[0].max, best);
    EXPECT_EQ((s[0].where - where).norm(), 0.0);
    EXPECT_EQ(s[0].p99, weighted_quantile(all_p1, all_vol, 0.99));
    EXPECT_NEAR(s[0].max_averaged, ref.value, 1e-13 * std::abs(ref.value));
    EXPECT_EQ((s[0].where_averaged - centres[ref.centre]).norm(), 0.0);
  }
}
