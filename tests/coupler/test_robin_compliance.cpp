// The robin scheme's surface compliance alone (robin.hpp), driven with crafted solid replies: which
// stiffness each plane is softened with. Consistency property of the diagonal model: a plane softened
// with stiffness k carries penalty ε k / (ε + k).
#include <gtest/gtest.h>

#include "angio/coupler/iqn_ils.hpp"
#include "angio/coupler/robin.hpp"
#include "spring_participants.hpp"

using namespace angio;

namespace {
// A beam that records the planes of its last robin solve and leaves its points where they are.
struct RecordingBeam : test::SpringBeam {
  explicit RecordingBeam(int points) : test::SpringBeam(points) {}
  participant::ContactPlanes last;
  participant::SolveStats solve_with_planes(const std::vector<participant::Vec3>&,
                                            const participant::ContactPlanes& p) override {
    last = p;
    participant::SolveStats st;
    st.converged = true;
    return st;
  }
};

// A reply of one plane per point along +x (normal toward the beam) whose surface lies `surface[i]`
// beyond point i's contact position; only positions, normals and penalties are read by the scheme.
participant::ContactReply reply_of(const participant::SamplePoints& x, const std::vector<double>& surface, double eps) {
  participant::ContactReply r;
  for (std::size_t i = 0; i < surface.size(); ++i) {
    // the plane law of plane_penalty.hpp: gap (x − S)·n − R, S = surface − 2R: penetration surface − x − R
    r.surface_points.push_back({surface[i] - 2.0 * x.radius[i], x.x[i][1], x.x[i][2]});
    r.normals.push_back({1.0, 0.0, 0.0});
    r.penalty.push_back(eps);
    r.line_loads.push_back({0.0, 0.0, 0.0});
  }
  return r;
}

// One accepted step of the scheme: the solid's reply `first` at the points x, one update, then the
// reply `last` at the points x_last (the secant's two ends).
void accepted_step(coupler::Robin& robin, RecordingBeam& beam, coupler::Acceleration& acc,
                   const participant::SamplePoints& x, const std::vector<double>& first,
                   const participant::SamplePoints& x_last, const std::vector<double>& last, double eps) {
  robin.begin_step(0.1, false);
  robin.solve_beam(beam);
  robin.force_residual(x, reply_of(x, first, eps));
  robin.next_iterate(acc, 0);
  robin.solve_beam(beam);
  robin.force_residual(x_last, reply_of(x_last, last, eps));
  robin.accept(0.1);
}
}  // namespace

// 24 planes loaded by 0.01 mm of penetration (0.1 N/mm). Within the step the first `estimated` points
// go 0.51 mm deeper while their surface gives way by 0.5 mm (load 0.2 N/mm: a secant of 0.2 N/mm²),
// the others stay (no secant of their own). After the step every plane of the second group is
// softened with the first group's median, ε' = ε k / (ε + k); with fewer than 10 estimates on the
// surface none is (a median of a few secants is their noise).
TEST(RobinCompliance, PlanesWithoutTheirOwnSecantTakeTheSurfacesMedian) {
  for (const int estimated : {12, 6}) {
    constexpr int n = 24;
    constexpr double eps = 10.0, k = 0.2;
    RecordingBeam beam(n);
    const participant::SamplePoints x = beam.sample_points();
    participant::SamplePoints x_last = x;
    std::vector<double> first(n), last(n);
    for (std::size_t i = 0; i < std::size_t(n); ++i) {
      const double contact = x.x[i][0] + x.radius[i];
      first[i] = last[i] = contact + 0.01;
      if (int(i) < estimated) {
        last[i] -= 0.5;
        x_last.x[i][0] -= 0.51;
      }
    }
    coupler::Robin robin(std::size_t(n), true);
    coupler::IqnIls iqn(coupler::IqnIlsOptions{});
    accepted_step(robin, beam, iqn, x, first, x_last, last, eps);
    robin.begin_step(0.1, false);
    robin.solve_beam(beam);
    ASSERT_EQ(beam.last.eps.size(), std::size_t(n));
    const double softened = eps * k / (eps + k);
    for (std::size_t i = 0; i < std::size_t(n); ++i) {
      const bool own = int(i) < estimated;
      EXPECT_NEAR(beam.last.eps[i], own || estimated >= 10 ? softened : eps, 1e-12)
          << "plane " << i << " with " << estimated << " estimates";
    }
  }
}

// A plane that goes from the bare penalty to a softened one between two accepted steps is not
// extrapolated into the next step: the difference of the two is the softening's own shift f/k
// (0.5 mm here), not a motion of the surface, and extrapolated it took the wall's planes away from
// the struts (the beam's Newton diverged on the post-dilated wall).
TEST(RobinCompliance, NoExtrapolationAcrossTheChangeFromBareToSoftened) {
  constexpr int n = 24, estimated = 12;
  constexpr double eps = 10.0;
  RecordingBeam beam(n);
  const participant::SamplePoints x = beam.sample_points();
  coupler::Robin robin(std::size_t(n), true);
  coupler::IqnIls iqn(coupler::IqnIlsOptions{});
  // step 1: every plane 0.01 mm in, no secant (bare planes); step 2: every surface 0.001 mm further
  // in (a motion to extrapolate), and the first 12 points with their secant as in the test above
  std::vector<double> s1(n), s2(n), s2_last(n);
  participant::SamplePoints x2 = x;
  for (std::size_t i = 0; i < std::size_t(n); ++i) {
    s1[i] = x.x[i][0] + x.radius[i] + 0.01;
    s2[i] = s2_last[i] = s1[i] + 0.001;
    if (int(i) < estimated) {
      s2_last[i] -= 0.5;
      x2.x[i][0] -= 0.51;
    }
  }
  accepted_step(robin, beam, iqn, x, s1, x, s1, eps);
  accepted_step(robin, beam, iqn, x, s2, x2, s2_last, eps);
  robin.begin_step(0.1, false);
  robin.solve_beam(beam);
  const participant::ContactPlanes held = beam.last;
  robin.begin_step(0.1, true);
  robin.solve_beam(beam);
  for (std::size_t i = 0; i < std::size_t(n); ++i)
    EXPECT_DOUBLE_EQ(beam.last.s[i][0], held.s[i][0]) << "plane " << i << " changed from bare to softened";
}
