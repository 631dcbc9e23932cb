// Petrov–Galerkin residual of 4C's beam3r (Jelenić & Crisfield 1999) as an alternative to the
// consistent variation (ResidualForm, element.hpp):
//   tangent vs finite differences, agreement/disagreement with the consistent form at the
//   element level, refinement of a plastic cantilever under a tip moment with both forms, the
//   LU backends on the non-symmetric tangent, and the scene key stent.element.residual.
#include <unistd.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "angio/beam/model.hpp"
#include "angio/beam/scene.hpp"

using namespace angio::beam;

namespace {

constexpr ResidualForm kC = ResidualForm::consistent;
constexpr ResidualForm kPG = ResidualForm::petrov_galerkin;

// Paper material (Appendix C): E = 380 GPa, ν = 0.3, R = 0.06 mm, M_y0 = 0.08 N mm, E_ep = 64 GPa.
const double E = 380000.0, nu = 0.3, Rs = 0.06, My0 = 0.08, Eep = 64000.0;

Section paper_section() {
  Section s = circular_section(E, nu, Rs);
  add_bending_plasticity(s, E, My0, Eep);
  return s;
}

// Circular section with GJ = EI (J = E I / G): an elastic moment is then parallel to the
// curvature, hence to the element's relative rotation φ when Ω0 = 0.
Section isotropic_torsion_section() {
  const double G = E / (2 * (1 + nu)), A = M_PI * Rs * Rs, I = M_PI * std::pow(Rs, 4) / 4;
  return general_section(E, G, A, I, I, E * I / G, 0.9, 0.9);
}

struct State {
  Vec3 x1, x2;
  Quat R1, R2;
};

Vec12 residual(ResidualForm f, const Section& s, const ElementReference& ref, const State& c, const PlasticState& st,
               const Vec12& d = Vec12::Zero()) {
  const Vec3 x1 = c.x1 + d.segment<3>(0), x2 = c.x2 + d.segment<3>(6);
  const Quat R1 = quat_exp(d.segment<3>(3)) * c.R1, R2 = quat_exp(d.segment<3>(9)) * c.R2;
  return evaluate_element(s, ref, x1, x2, R1, R2, st, false, f).residual;
}

// Central differences of the residual w.r.t. (Δx, Δθ), Λ ← exp(Δθ)Λ.
Mat12 fd_tangent(ResidualForm f, const Section& s, const ElementReference& ref, const State& c, const PlasticState& st,
                 double h) {
  Mat12 K;
  for (int i = 0; i < 12; ++i) {
    Vec12 d = Vec12::Zero();
    d(i) = h;
    K.col(i) = (residual(f, s, ref, c, st, d) - residual(f, s, ref, c, st, -d)) / (2 * h);
  }
  return K;
}

// Straight element of length L along x, reference triad e2 = y (Ω0 = Γ0 = 0).
ElementReference straight_reference(double L) {
  const Vec3 t(L, 0, 0);
  const Quat O = triad_from_tangent(t, Vec3::UnitY());
  return make_element_reference(Vec3::Zero(), t, O, O);
}

// Nodes rotated by exp(∓s a/2) (relative rotation s·Oᵀa); positions put at x2 − x1 =
// L Λ_r (1 + ε, γ2, γ3) so that the shear/axial strains are exactly (ε, γ2, γ3).
State symmetric_state(const ElementReference& ref, double L, const Vec3& a, double s,
                      const Vec3& strain_g = Vec3::Zero()) {
  State c;
  c.R1 = quat_exp(-0.5 * s * a);
  c.R2 = quat_exp(0.5 * s * a);
  const Quat L1 = c.R1 * ref.O1, L2 = c.R2 * ref.O2;
  const Quat Lr = L1 * quat_exp(0.5 * quat_log(L1.conjugate() * L2));
  c.x1 = Vec3(0.3, -0.2, 0.1);
  c.x2 = c.x1 + L * (Lr * (Vec3::UnitX() + strain_g));
  return c;
}

double rel_diff(const Vec12& a, const Vec12& b) { return (a - b).norm() / b.norm(); }

}  // namespace

// (a) The PG tangent is the exact derivative of the PG residual at a generic deformed,
// plastically loading state (curved reference, 3D rotations, shear, radial return active).
// Tolerance: with h = 1e-6 the central-difference truncation error is ~h²|r'''| ≈ 1e-12 ‖K‖
// and the round-off error ~ε‖r‖/h ≈ 1e-10 ‖K‖ (‖r‖ ≈ ‖K‖·O(0.1) here); the radial return is
// smooth as long as the ±h perturbations stay on the plastic branch (trial moment ≈ 10 M_y),
// so 1e-7 leaves two to three orders of margin while any missing term (e.g. the [n]× Δd part,
// ≈ 1e-2 of ‖K‖) fails it.
TEST(BeamPetrovGalerkin, TangentMatchesFiniteDifferencesPlastic) {
  const Section s = paper_section();
  const Vec3 t(1, 0.2, 0.1);
  const ElementReference ref =
      make_element_reference(Vec3::Zero(), t, triad_from_tangent(t, Vec3::UnitZ()),
                             triad_from_tangent(Vec3(1, 0.3, 0.05), Vec3::UnitZ()));  // curved: Ω0 ≠ 0
  State c;
  c.x1 = Vec3(0.01, -0.02, 0.03);
  c.x2 = Vec3(0.98, 0.28, 0.09);
  c.R1 = quat_exp(Vec3(0.1, -0.15, 0.05));
  c.R2 = quat_exp(Vec3(-0.12, 0.2, 0.3));
  PlasticState st;
  st.omega_pl = Vec3(0, 0.05, -0.08);
  st.kappa_bar = 0.1;
  const ElementResult ev = evaluate_element(s, ref, c.x1, c.x2, c.R1, c.R2, st, true, kPG);
  ASSERT_TRUE(ev.section.yielding);
  EXPECT_GT(ev.section.bending_moment_norm, My0);
  const Mat12 Kfd = fd_tangent(kPG, s, ref, c, st, 1e-6);
  const double err = (Kfd - ev.tangent).norm() / ev.tangent.norm();
  std::printf("PG tangent vs FD (plastic): relative error %.2e\n", err);
  EXPECT_LT(err, 1e-7);
  // non-symmetric (Jelenić & Crisfield 1999), also at this state where the consistent one is
  const double asym = (ev.tangent - ev.tangent.transpose()).norm() / ev.tangent.norm();
  std::printf("PG tangent asymmetry ‖K − Kᵀ‖/‖K‖ = %.2e\n", asym);
  EXPECT_GT(asym, 1e-3);
  // same strains and section response as the consistent form (shared kinematics and law)
  const ElementResult cv = evaluate_element(s, ref, c.x1, c.x2, c.R1, c.R2, st, true, kC);
  EXPECT_EQ((cv.strain - ev.strain).norm(), 0.0);
  EXPECT_EQ((cv.section.stress - ev.section.stress).norm(), 0.0);
  // translational residuals (test functions I_a for δx in both forms) agree
  EXPECT_LT((cv.residual.segment<3>(0) - ev.residual.segment<3>(0)).norm(), 1e-12 * cv.residual.norm());
  EXPECT_LT((cv.residual.segment<3>(6) - ev.residual.segment<3>(6)).norm(), 1e-12 * cv.residual.norm());
}

// Same check for an elastic element (no return mapping) in a large-rotation state.
TEST(BeamPetrovGalerkin, TangentMatchesFiniteDifferencesElastic) {
  const Section s = circular_section(1000.0, 0.3, 0.1);
  const Vec3 t(1, 0.2, 0.1);
  const ElementReference ref = make_element_reference(Vec3::Zero(), t, triad_from_tangent(t, Vec3::UnitZ()),
                                                      triad_from_tangent(Vec3(1, 0.25, 0.05), Vec3::UnitZ()));
  State c;
  c.x1 = Vec3(0.01, -0.02, 0.03);
  c.x2 = Vec3(0.9, 0.35, -0.2);
  c.R1 = quat_exp(Vec3(0.3, -0.5, 0.2));
  c.R2 = quat_exp(Vec3(-0.4, 0.7, 0.9));
  const ElementResult ev = evaluate_element(s, ref, c.x1, c.x2, c.R1, c.R2, {}, true, kPG);
  const double err = (fd_tangent(kPG, s, ref, c, {}, 1e-6) - ev.tangent).norm() / ev.tangent.norm();
  EXPECT_LT(err, 1e-7);  // see the plastic test for the tolerance
}

// (b) Agreement to round-off when the moment is parallel to the relative rotation and
// d×n ∥ Λ_r φ: (i) elastic, GJ = EI, straight reference, generic 3D relative rotation, axial
// strain but no shear (d ∥ n, so d×n = 0); (ii) planar bending with shear past yield (M, φ and
// d×n all along the plane normal), where plasticity does not break the agreement.
TEST(BeamPetrovGalerkin, AgreesWithConsistentWhenMomentParallelToRelativeRotation) {
  {
    const Section s = isotropic_torsion_section();
    const double L = 0.4;
    const ElementReference ref = straight_reference(L);
    const State c = symmetric_state(ref, L, Vec3(0.9, -0.7, 0.5), 1.0, Vec3(2e-3, 0, 0));
    const Vec12 rc = residual(kC, s, ref, c, {}), rp = residual(kPG, s, ref, c, {});
    std::printf("GJ = EI, no shear: |r_PG − r_C|/|r_C| = %.2e\n", rel_diff(rp, rc));
    EXPECT_LT(rel_diff(rp, rc), 1e-13);
  }
  {
    const Section s = paper_section();
    const Vec3 t(0.4, 0.05, 0);
    const ElementReference ref =
        make_element_reference(Vec3::Zero(), t, triad_from_tangent(t, Vec3::UnitY()),
                               triad_from_tangent(Vec3(0.4, 0.1, 0), Vec3::UnitY()));  // curved in the x–y plane
    State c;
    c.x1 = Vec3(0.02, 0.01, 0);
    c.x2 = Vec3(0.37, 0.21, 0);
    c.R1 = quat_exp(Vec3(0, 0, 0.1));
    c.R2 = quat_exp(Vec3(0, 0, 0.6));
    PlasticState st;
    st.omega_pl = Vec3(0, 0, 0.05);
    st.kappa_bar = 0.05;
    const ElementResult ev = evaluate_element(s, ref, c.x1, c.x2, c.R1, c.R2, st, false, kPG);
    ASSERT_TRUE(ev.section.yielding);
    ASSERT_GT(std::abs(ev.section.stress(1)), 1.0);  // shear force present
    const Vec12 rc = residual(kC, s, ref, c, st), rp = residual(kPG, s, ref, c, st);
    std::printf("planar, plastic, shear: |r_PG − r_C|/|r_C| = %.2e\n", rel_diff(rp, rc));
    EXPECT_LT(rel_diff(rp, rc), 1e-13);
  }
}

// (b) Otherwise the forms differ at second order in the relative rotation φ: for a shear-free
// state (n = 0) only the moment term differs, Λ1 J⁻ᵀ(φ) M versus Λ1 exp(φ/2) M, by
// Λ1 φ×(φ×M)/24 + O(φ³)|M|, i.e. O(φ²) relative. Halving φ divides the relative difference by
// 4: elastic circular section (GJ = EI/(1+ν), torsion + bending), and GJ = EI with a committed
// plastic bending curvature (bending plasticity, no torsional plasticity).
TEST(BeamPetrovGalerkin, DifferenceIsSecondOrderInRelativeRotation) {
  const double L = 0.4;
  const ElementReference ref = straight_reference(L);
  const Vec3 a(0.9, -0.7, 0.5);  // torsion (x) and both bending components
  struct Case {
    const char* name;
    Section s;
    bool plastic_state;
  };
  Section pl = isotropic_torsion_section();
  add_bending_plasticity(pl, E, My0, Eep);
  const Case cases[2] = {{"elastic GJ != EI", circular_section(E, nu, Rs), false},
                         {"GJ = EI, plastic curvature", pl, true}};
  for (const Case& cs : cases) {
    double prev = 0;
    std::printf("%s: phi, |r_PG − r_C|/|r_C|, ratio\n", cs.name);
    for (double s = 0.8; s > 0.04; s *= 0.5) {
      const State c = symmetric_state(ref, L, a, s);
      PlasticState st;
      if (cs.plastic_state) {  // κ_p ∝ φ, not parallel to it; κ̄ large enough to stay elastic
        st.omega_pl = s / L * Vec3(0, 0.4, 0.6);
        st.kappa_bar = 100.0;
      }
      const ElementResult ev = evaluate_element(cs.s, ref, c.x1, c.x2, c.R1, c.R2, st, false, kC);
      ASSERT_FALSE(ev.section.yielding);
      ASSERT_LT(ev.section.stress.head<3>().norm(), 1e-9 * ev.section.stress.tail<3>().norm());
      const double e = rel_diff(residual(kPG, cs.s, ref, c, st), residual(kC, cs.s, ref, c, st));
      std::printf("  %.3f  %.3e  %.3f\n", s * a.norm(), e, prev > 0 ? prev / e : 0.0);
      if (s < 0.15) {
        EXPECT_NEAR(prev / e, 4.0, 0.1) << cs.name << " s = " << s;
      }
      EXPECT_GT(e, 1e-6 * s * s);  // a real difference, far above round-off
      prev = e;
    }
  }
}

// With shear the d×n term differs at first order: the consistent variation of the midpoint
// triad is δθ_r = ½(δθ1 + δθ2) − ⅛ Λ_rφ × (δθ2 − δθ1) + O(φ²) (differentiate Λ_r = Λ1 exp(φ/2),
// Crisfield & Jelenić 1999), PG uses ½(δθ1 + δθ2). At fixed shear strain, halving φ halves the
// difference, and its leading term is ±⅛ Λ_rφ × (d×n) at the two nodes.
TEST(BeamPetrovGalerkin, ShearTermDiffersAtFirstOrder) {
  const Section s = circular_section(E, nu, Rs);
  const double L = 0.4;
  const ElementReference ref = straight_reference(L);
  const Vec3 a(0.9, -0.7, 0.5), g(0, 1e-3, -5e-4);
  double prev = 0;
  for (double sc = 0.4; sc > 0.01; sc *= 0.5) {
    const State c = symmetric_state(ref, L, a, sc, g);
    const Vec12 rc = residual(kC, s, ref, c, {}), rp = residual(kPG, s, ref, c, {});
    const Vec12 diff = rp - rc;
    const Vec3 phi_s = sc * a;  // Λ_r φ: the spatial relative rotation (R1ᵀR2 = exp(sc a))
    const Vec3 n = rc.segment<3>(6), d = c.x2 - c.x1;
    const Vec3 lead = 0.125 * phi_s.cross(d.cross(n));
    const double e = diff.norm();
    std::printf("shear: |phi| %.3f  |r_PG − r_C| %.3e  ratio %.3f  |diff_θ1 + lead|/|lead| %.2e\n", phi_s.norm(), e,
                prev > 0 ? prev / e : 0.0, (diff.segment<3>(3) + lead).norm() / lead.norm());
    if (sc < 0.15) {
      EXPECT_NEAR(prev / e, 2.0, 0.1);
    }
    EXPECT_LT((diff.segment<3>(3) + lead).norm(), 0.5 * phi_s.norm() * lead.norm());
    EXPECT_LT((diff.segment<3>(9) - lead).norm(), 0.5 * phi_s.norm() * lead.norm());
    prev = e;
  }
}

namespace {

// Plastic cantilever (paper section), L = 10 mm along x, clamped at x = 0, spatially fixed tip
// moment m = (0.12, 0, 0.24) N mm (torsion + bending, 3 M_y0 bending at the start) ramped up in
// 20 steps and removed in 10: the axis becomes a (plastic) space curve, so M is not parallel
// to φ and the two forms differ.
struct CantileverResult {
  Vec3 tip_peak, rot_peak, tip_final, rot_final;
  int max_iterations = 0;
};

CantileverResult plastic_cantilever(int ne, ResidualForm form, const std::string& solver = "klu") {
  BeamModel m;
  const int sec = m.add_section(paper_section());
  const double L = 10.0;
  for (int i = 0; i <= ne; ++i) m.add_node(Vec3(L * i / ne, 0, 0));
  for (int i = 0; i < ne; ++i) m.add_element(i, i + 1, sec, Vec3::UnitY());
  m.fix(0, {true, true, true, true, true, true});
  m.nodal_loads.push_back({ne, Vec3::Zero(), Vec3(0.12, 0, 0.24), [](double t) { return t <= 1 ? t : 2 - t; }});
  m.residual_form = form;
  m.newton.linear_solver = solver;
  m.newton.residual_tol = 1e-11;
  m.newton.increment_tol = 1e-10;
  m.finalize();
  CantileverResult r;
  const int up = 20, down = 10;
  for (int k = 1; k <= up + down; ++k) {
    m.set_time(k <= up ? double(k) / up : 1.0 + double(k - up) / down);
    const NewtonStats st = m.solve();
    EXPECT_TRUE(st.converged) << "ne " << ne << " step " << k << ": " << st.message;
    if (!st.converged) return r;
    r.max_iterations = std::max(r.max_iterations, st.iterations);
    m.commit();
    if (k == up) {
      r.tip_peak = m.position(ne);
      r.rot_peak = quat_log(m.rotation(ne));
    }
  }
  r.tip_final = m.position(ne);
  r.rot_final = quat_log(m.rotation(ne));
  return r;
}

}  // namespace

// (c) Refinement, 4 to 32 elements (64 as the reference): both forms converge to the same tip
// position and rotation, at second order, and the difference between the forms shrinks at
// second order too (O(φ²) per element with φ = O(h)).
TEST(BeamPetrovGalerkin, PlasticCantileverRefinementBothFormsConverge) {
  const int nes[5] = {4, 8, 16, 32, 64};
  CantileverResult rc[5], rp[5];
  for (int i = 0; i < 5; ++i) {
    rc[i] = plastic_cantilever(nes[i], kC);
    rp[i] = plastic_cantilever(nes[i], kPG);
    EXPECT_LE(rp[i].max_iterations, rc[i].max_iterations + 2);  // Newton rate kept (exact tangent)
  }
  std::printf(
      "ne | form | tip at peak (mm) | tip rotation at peak (rad) | tip after unloading | "
      "rotation after unloading | max Newton its\n");
  for (int i = 0; i < 5; ++i)
    for (int f = 0; f < 2; ++f) {
      const CantileverResult& r = f ? rp[i] : rc[i];
      std::printf("%2d | %s | %.6f %.6f %.6f | %.6f %.6f %.6f | %.6f %.6f %.6f | %.6f %.6f %.6f | %d\n", nes[i],
                  f ? "PG" : "C ", r.tip_peak.x(), r.tip_peak.y(), r.tip_peak.z(), r.rot_peak.x(), r.rot_peak.y(),
                  r.rot_peak.z(), r.tip_final.x(), r.tip_final.y(), r.tip_final.z(), r.rot_final.x(), r.rot_final.y(),
                  r.rot_final.z(), r.max_iterations);
    }
  // Reference: Richardson extrapolation of each form from 32 and 64 elements (second order).
  const Vec3 lim_c = (4.0 * rc[4].tip_peak - rc[3].tip_peak) / 3.0;
  const Vec3 lim_p = (4.0 * rp[4].tip_peak - rp[3].tip_peak) / 3.0;
  std::printf(
      "Richardson limits of the tip at peak: C %.7f %.7f %.7f, PG %.7f %.7f %.7f, "
      "|difference| %.2e\n",
      lim_c.x(), lim_c.y(), lim_c.z(), lim_p.x(), lim_p.y(), lim_p.z(), (lim_p - lim_c).norm());
  std::printf(
      "ne | |tip_C − lim_C| | order | |tip_PG − lim_C| | order | |tip_PG − tip_C| (peak) | order | "
      "|rot_PG − rot_C| (peak) | |tip_PG − tip_C| (unloaded) | order\n");
  double cprev = 0, pprev = 0, dprev = 0, uprev = 0;
  auto order = [](double a, double b) { return a > 0 ? std::log2(a / b) : 0.0; };
  for (int i = 0; i < 5; ++i) {
    const double ec = (rc[i].tip_peak - lim_c).norm();
    const double ep = (rp[i].tip_peak - lim_c).norm();
    const double d = (rp[i].tip_peak - rc[i].tip_peak).norm();
    const double dr = (rp[i].rot_peak - rc[i].rot_peak).norm();
    const double u = (rp[i].tip_final - rc[i].tip_final).norm();
    std::printf("%2d | %.3e | %.2f | %.3e | %.2f | %.3e | %.2f | %.3e | %.3e | %.2f\n", nes[i], ec, order(cprev, ec),
                ep, order(pprev, ep), d, order(dprev, d), dr, u, order(uprev, u));
    if (i > 0) {
      EXPECT_GT(cprev / ec, 3.5) << "ne " << nes[i];  // second order: ≈ 4
      EXPECT_GT(pprev / ep, 3.5) << "ne " << nes[i];
      EXPECT_GT(dprev / d, 3.5) << "ne " << nes[i];
      EXPECT_GT(uprev / u, 3.5) << "ne " << nes[i];
    }
    EXPECT_GT(d, 1e-5 * (rc[i].tip_peak - lim_c).norm());  // the forms do differ
    cprev = ec;
    pprev = ep;
    dprev = d;
    uprev = u;
  }
  // Same limit: the extrapolated tips agree far better than the 64-element solutions do.
  EXPECT_LT((lim_p - lim_c).norm(), 0.05 * (rp[4].tip_peak - rc[4].tip_peak).norm());
}

// The PG tangent is non-symmetric: every backend (all LU: KLU, UMFPACK, Eigen SparseLU) solves
// it and they give the same solution.
TEST(BeamPetrovGalerkin, LuBackendsSolveNonSymmetricTangent) {
  const CantileverResult a = plastic_cantilever(8, kPG, "klu");
  const CantileverResult b = plastic_cantilever(8, kPG, "umfpack");
  const CantileverResult c = plastic_cantilever(8, kPG, "sparselu");
  EXPECT_LT((a.tip_final - b.tip_final).norm(), 1e-9);
  EXPECT_LT((a.tip_final - c.tip_final).norm(), 1e-9);
}

namespace {
std::string scene_text(const std::string& element) {
  return "time: {end: 1, steps: 2}\nstent:\n  material: {E: 5, nu: 0.3}\n  section: {radius: 0.06}\n"
         "  lines: [{from: [0,0,0], to: [1,0,0], elements: 2}]\n" +
         element;
}
// Loads a scene text; returns the model's residual form, or the SceneError message in `err`.
ResidualForm load_form(const std::string& text, std::string* err) {
  const auto path = std::filesystem::temp_directory_path() / ("beam_pg_scene_" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(path) << text;
  ResidualForm f = kC;
  try {
    f = load_beam_scene(path.string()).model->residual_form;
  } catch (const angio::scene::SceneError& e) {
    *err = e.what();
  }
  std::filesystem::remove(path);
  return f;
}
}  // namespace

// stent.element.residual: default consistent; petrov_galerkin; bad values and unknown keys are
// errors that name the key.
TEST(BeamPetrovGalerkin, SceneKey) {
  std::string err;
  EXPECT_EQ(load_form(scene_text(""), &err), kC);
  EXPECT_EQ(load_form(scene_text("  element: {residual: consistent}\n"), &err), kC);
  EXPECT_EQ(load_form(scene_text("  element: {residual: petrov_galerkin}\n"), &err), kPG);
  EXPECT_TRUE(err.empty()) << err;
  load_form(scene_text("  element: {residual: bubnov}\n"), &err);
  EXPECT_NE(err.find("stent.element.residual"), std::string::npos) << err;
  err.clear();
  load_form(scene_text("  element: {residul: petrov_galerkin}\n"), &err);
  EXPECT_NE(err.find("residul"), std::string::npos) << err;
}

// At an equilibrium under a conservative (dead) tip force the consistent tangent is symmetric
// (Hessian of the potential energy, spatial increments at equilibrium), the PG tangent is not:
// no energy is behind the PG residual.
TEST(BeamPetrovGalerkin, TangentNonSymmetricAtEquilibrium) {
  double asym[2];
  for (int f = 0; f < 2; ++f) {
    BeamModel m;
    const int sec = m.add_section(circular_section(1.0e4, 0.3, 0.1));
    const int ne = 6;
    for (int i = 0; i <= ne; ++i) m.add_node(Vec3(i, 0, 0));
    for (int i = 0; i < ne; ++i) m.add_element(i, i + 1, sec, Vec3::UnitY());
    m.fix(0, {true, true, true, true, true, true});
    m.nodal_loads.push_back({ne, Vec3(0, 0.02, 0.03), Vec3::Zero(), [](double t) { return t; }});
    m.residual_form = f ? kPG : kC;
    m.newton.residual_tol = 1e-12;
    m.finalize();
    m.set_time(1.0);
    ASSERT_TRUE(m.solve().converged);
    SpMat K;
    Eigen::VectorXd r;
    m.assemble(&K, r);
    const SpMat Kt = K.transpose();
    asym[f] = (K - Kt).norm() / K.norm();
  }
  std::printf("equilibrium: ‖K − Kᵀ‖/‖K‖ consistent %.2e, Petrov–Galerkin %.2e\n", asym[0], asym[1]);
  EXPECT_LT(asym[0], 1e-10);
  EXPECT_GT(asym[1], 1e-6);
}
