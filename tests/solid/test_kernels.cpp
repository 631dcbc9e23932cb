// Unit tests of the pure solid kernels (no MPI): materials, elements, faces, patch tests.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

#include "angio/solid/elements.hpp"
#include "angio/solid/materials.hpp"
#include "angio/solid/mesh.hpp"
#include "fd_tangent.hpp"

using namespace angio::solid;

namespace {

// Symmetric basis with unit engineering strain: normal components E_ii = 1, shear E_ij = E_ji = 1/2.
Mat3 basis(int I) {
  Mat3 B = Mat3::Zero();
  const int i = kVoigt[I][0], j = kVoigt[I][1];
  if (i == j)
    B(i, i) = 1.0;
  else
    B(i, j) = B(j, i) = 0.5;
  return B;
}

std::vector<Mat3> test_deformations() {
  std::vector<Mat3> Fs;
  Mat3 F;
  F << 1.10, 0.05, -0.02, 0.03, 0.95, 0.04, -0.01, 0.02, 1.20;  // general, mixed tension/compression
  Fs.push_back(F);
  F << 1.6, 0.2, 0.0, -0.1, 1.3, 0.1, 0.05, 0.0, 0.8;  // large
  Fs.push_back(F);
  F << 0.85, 0.0, 0.0, 0.0, 0.9, 0.0, 0.0, 0.0, 0.92;  // all compressed
  Fs.push_back(F);
  F << 2.6, 0.0, 0.0, 0.0, 1.01, 0.05, 0.0, 0.0, 1.02;  // balloon-like hoop stretch (I4 != 1: the
  // fiber energy is only C1 at I4 = 1, where a central difference of S straddles the kink)
  Fs.push_back(F);
  return Fs;
}

// Checks S = dPsi/dE and D = dS/dE by central finite differences.
void check_material(const NeoHooke& m, const std::vector<FiberFamily>& fibers, const Mat3& F, double tol_s,
                    double tol_d) {
  const Mat3 C = F.transpose() * F;
  Mat3 S;
  Mat6 D;
  stress_tangent(m, fibers, C, S, &D);
  const double h = 1e-6;
  const double scale_s = std::max(1e-12, S.cwiseAbs().maxCoeff());
  const double scale_d = std::max(1e-12, D.cwiseAbs().maxCoeff());
  for (int I = 0; I < 6; ++I) {
    const Mat3 dC = 2.0 * basis(I);  // C = I + 2E
    const double dpsi = (energy(m, fibers, C + h * dC) - energy(m, fibers, C - h * dC)) / (2 * h);
    EXPECT_NEAR(dpsi, S(kVoigt[I][0], kVoigt[I][1]), tol_s * scale_s) << "S component " << I;
    Mat3 Sp, Sm;
    stress_tangent(m, fibers, C + h * dC, Sp, nullptr);
    stress_tangent(m, fibers, C - h * dC, Sm, nullptr);
    const Vec6 dS = (to_voigt_stress(Sp) - to_voigt_stress(Sm)) / (2 * h);
    for (int J = 0; J < 6; ++J) EXPECT_NEAR(dS(J), D(J, I), tol_d * scale_d) << "D(" << J << "," << I << ")";
  }
}

}  // namespace

// Compares S and the material tangent with finite differences of the strain energy.
TEST(Materials, NeoHookeStressAndTangentMatchFiniteDifferences) {
  for (double nu : {0.0, 0.3, 0.45}) {
    const NeoHooke m{17.0, nu};
    for (const auto& F : test_deformations()) check_material(m, {}, F, 1e-6, 1e-5);
  }
}

// Compares with the closed-form small-strain limit: lambda = 2 mu beta = E nu / ((1+nu)(1-2nu)).
TEST(Materials, NeoHookeReducesToLinearElasticity) {
  const NeoHooke m{2.0, 0.3};
  Mat3 S;
  Mat6 D;
  stress_tangent(m, {}, Mat3::Identity(), S, &D);
  EXPECT_NEAR(S.norm(), 0.0, 1e-14);
  const double lam = 2.0 * 0.3 / (1.3 * 0.4), mu = 2.0 / 2.6;
  EXPECT_NEAR(D(0, 0), lam + 2 * mu, 1e-12);
  EXPECT_NEAR(D(0, 1), lam, 1e-12);
  EXPECT_NEAR(D(3, 3), mu, 1e-12);
}

// Fibers in tension (I4 > 1) and compression (I4 < 1, must carry nothing): FD of the energy.
TEST(Materials, FiberFamiliesTensionAndCompression) {
  Frame fr;
  fr.circumferential = Vec3d(0, 1, 0);
  fr.axial = Vec3d(0, 0, 1);
  fr.radial = Vec3d(1, 0, 0);
  const LayerMaterial balloon{"balloon", {17.0, 0.0}, {{1000.0, 0.01, 90.0, false}, {1.5e-7, 0.35, 0.0, false}}};
  const LayerMaterial media{"media", {0.1566, 0.45}, {{0.00064, 3.54, 0.0, true}}};
  const LayerMaterial adv{"adventitia", {0.01566, 0.45}, {{0.0051, 15.4, 40.0, true}}};
  for (const auto* mat : {&balloon, &media, &adv}) {
    const auto fibers = resolve_fibers(*mat, fr);
    for (const auto& F : test_deformations()) {
      if (mat == &adv && F(0, 0) > 2.0) continue;  // exp(15.4 (I4-1)^2) overflows double: not a test point
      check_material(mat->matrix, fibers, F, 1e-6, 1e-4);
    }
  }
  // compression along the fiber: fiber adds nothing
  FiberFamily f{1.0, 2.0, Vec3d(1, 0, 0)};
  Mat3 F = Mat3::Identity();
  F(0, 0) = 0.9;
  Mat3 S = Mat3::Zero();
  Mat6 D = Mat6::Zero();
  add_stress(f, F.transpose() * F, S, &D);
  EXPECT_EQ(S.norm(), 0.0);
  EXPECT_EQ(D.norm(), 0.0);
  EXPECT_EQ(energy(f, F.transpose() * F), 0.0);
  // tension: uniaxial fiber stress 2 k1 (I4-1) exp(k2 (I4-1)^2)
  F(0, 0) = 1.1;
  add_stress(f, F.transpose() * F, S, &D);
  const double e = 1.21 - 1.0;
  EXPECT_NEAR(S(0, 0), 2.0 * e * std::exp(2.0 * e * e), 1e-12);
  EXPECT_GT(D(0, 0), 0.0);
}

// Fibers that also carry compression (tension_only = false, eq. B.4 as printed): FD of the energy
// (the tangent is smooth through I4 = 1), the analytic uniaxial value in compression, and the
// flag passed on from the spec.
TEST(Materials, FibersInCompressionWhenNotTensionOnly) {
  Frame fr;
  fr.circumferential = Vec3d(0, 1, 0);
  fr.axial = Vec3d(0, 0, 1);
  fr.radial = Vec3d(1, 0, 0);
  FiberSpec spec{1000.0, 0.01, 90.0, false};
  spec.tension_only = false;
  const LayerMaterial balloon{"balloon", {17.0, 0.0}, {spec}};
  const auto fibers = resolve_fibers(balloon, fr);
  ASSERT_EQ(fibers.size(), 1u);
  EXPECT_FALSE(fibers[0].tension_only);
  for (const auto& F : test_deformations()) check_material(balloon.matrix, fibers, F, 1e-6, 1e-4);
  Mat3 F = Mat3::Identity();
  F(2, 2) = 0.999999;  // across I4 = 1: FD stays consistent
  check_material(balloon.matrix, fibers, F, 1e-6, 1e-4);
  FiberFamily f{1.0, 2.0, Vec3d(1, 0, 0)};
  f.tension_only = false;
  F = Mat3::Identity();
  F(0, 0) = 0.9;
  Mat3 S = Mat3::Zero();
  add_stress(f, F.transpose() * F, S, nullptr);
  const double e = 0.81 - 1.0;
  EXPECT_NEAR(S(0, 0), 2.0 * e * std::exp(2.0 * e * e), 1e-12);  // negative: the fiber pushes back
  EXPECT_LT(S(0, 0), 0.0);
}

TEST(Materials, FiberAnglesFromFrame) {
  Frame fr;
  fr.circumferential = Vec3d(0, 1, 0);
  fr.axial = Vec3d(0, 0, 1);
  const LayerMaterial adv{"adventitia", {0.01566, 0.45}, {{0.0051, 15.4, 40.0, true}}};
  const auto f = resolve_fibers(adv, fr);
  ASSERT_EQ(f.size(), 2u);
  EXPECT_NEAR(f[0].a0.dot(fr.circumferential), std::cos(40.0 * M_PI / 180), 1e-14);
  EXPECT_NEAR(f[0].a0.dot(fr.axial), std::sin(40.0 * M_PI / 180), 1e-14);
  EXPECT_NEAR(f[1].a0.dot(fr.axial), -std::sin(40.0 * M_PI / 180), 1e-14);
}

// ---------------------------------------------------------------------------------------------
namespace {
Eigen::MatrixXd reference_element(ElemType t, std::mt19937& rng, double perturb) {
  std::uniform_real_distribution<double> U(-perturb, perturb);
  auto ref = reference_nodes(t);
  Eigen::MatrixXd X(ref.size(), 3);
  Mat3 A;
  A << 1.0, 0.2, 0.1, -0.1, 0.9, 0.15, 0.05, -0.2, 1.1;
  for (size_t a = 0; a < ref.size(); ++a) {
    X.row(a) = (A * ref[a]).transpose();
    for (int k = 0; k < 3; ++k) X(a, k) += U(rng);
  }
  return X;
}
}  // namespace

// Element tangent vs finite differences of the internal force (all element types).
TEST(Elements, InternalForceTangentMatchesFiniteDifferences) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-0.08, 0.08);
  Frame fr;
  const LayerMaterial adv{"adventitia", {1.0, 0.45}, {{0.5, 2.0, 40.0, true}}};
  const auto fibers = resolve_fibers(adv, fr);
  for (ElemType t : {ElemType::Hex8, ElemType::Tet4, ElemType::Tet10}) {
    const Eigen::MatrixXd X = reference_element(t, rng, 0.05);
    Eigen::MatrixXd u(X.rows(), 3);
    for (int i = 0; i < u.size(); ++i) u.data()[i] = U(rng);
    for (int a = 0; a < X.rows(); ++a) u(a, 0) += 0.3 * X(a, 0);  // stretch fibers
    Eigen::VectorXd f;
    Eigen::MatrixXd K;
    ASSERT_TRUE(element_internal(t, X, u, adv.matrix, fibers, f, &K));
    const Eigen::MatrixXd Kfd = angio_test::fd_tangent(u, [&](const Eigen::MatrixXd& v, Eigen::VectorXd& fv) {
      element_internal(t, X, v, adv.matrix, fibers, fv, nullptr);
    });
    EXPECT_LT((K - Kfd).norm(), 1e-6 * K.norm()) << name(t);
    EXPECT_LT((K - K.transpose()).norm(), 1e-10 * K.norm()) << name(t);
  }
}

// Follower-pressure residual tangent vs finite differences (quad4, tri3, tri6), and the total
// force of a constant pressure on a flat face vs p * area * normal.
TEST(Elements, FollowerPressureTangentMatchesFiniteDifferences) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-0.1, 0.1);
  for (FaceType t : {FaceType::Quad4, FaceType::Tri3, FaceType::Tri6}) {
    const int n = num_nodes(t);
    Eigen::MatrixXd x(n, 3);
    const std::vector<Vec3d> ref =
        t == FaceType::Quad4
            ? std::vector<Vec3d>{{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}
            : std::vector<Vec3d>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.5, 0, 0}, {0.5, 0.5, 0}, {0, 0.5, 0}};
    for (int a = 0; a < n; ++a) x.row(a) = ref[a].transpose();
    Eigen::VectorXd r;
    face_pressure(t, x, 2.0, r, nullptr);
    Vec3d total = Vec3d::Zero();
    for (int a = 0; a < n; ++a) total += r.segment<3>(3 * a);
    const double area = t == FaceType::Quad4 ? 4.0 : 0.5;
    EXPECT_NEAR(total.z(), 2.0 * area, 1e-12) << name(t);
    for (int i = 0; i < x.size(); ++i) x.data()[i] += U(rng);
    Eigen::MatrixXd K;
    face_pressure(t, x, 1.7, r, &K);
    const double h = 1e-6;
    Eigen::VectorXd rp, rm;
    Eigen::MatrixXd Kfd(3 * n, 3 * n);
    for (int j = 0; j < 3 * n; ++j) {
      Eigen::MatrixXd xp = x, xm = x;
      xp(j / 3, j % 3) += h;
      xm(j / 3, j % 3) -= h;
      face_pressure(t, xp, 1.7, rp, nullptr);
      face_pressure(t, xm, 1.7, rm, nullptr);
      Kfd.col(j) = (rp - rm) / (2 * h);
    }
    EXPECT_LT((K - Kfd).norm(), 1e-7 * K.norm()) << name(t);
  }
}

TEST(Elements, SpringsIntegrateReferenceArea) {
  Eigen::MatrixXd X(4, 3), u(4, 3);
  X << 0, 0, 0, 2, 0, 0, 2, 3, 0, 0, 3, 0;
  for (int a = 0; a < 4; ++a) u.row(a) = Eigen::RowVector3d(0.1, -0.2, 0.3);
  Eigen::VectorXd r;
  Eigen::MatrixXd K;
  face_springs(FaceType::Quad4, X, u, 5.0, r, &K);
  Vec3d total = Vec3d::Zero();
  for (int a = 0; a < 4; ++a) total += r.segment<3>(3 * a);
  EXPECT_NEAR(total.x(), 5.0 * 6.0 * 0.1, 1e-12);
  EXPECT_NEAR(total.z(), 5.0 * 6.0 * 0.3, 1e-12);
}

// ---------------------------------------------------------------------------------------------
// Patch tests: a distorted mesh of a cube under a homogeneous (finite) deformation u = G X must
// be in exact equilibrium at every interior node (residual ~ round-off) for any material.
namespace angio_test {
Mesh cube_mesh(ElemType t, int n, double perturb, unsigned seed);
}
using angio_test::cube_mesh;

TEST(Elements, PatchTestHomogeneousDeformation) {
  Mat3 G;
  G << 0.2, 0.05, -0.03, 0.02, -0.1, 0.04, 0.06, 0.01, 0.15;
  Frame fr;
  const LayerMaterial mat{"m", {1.0, 0.45}, {{0.5, 2.0, 30.0, true}}};
  const auto fibers = resolve_fibers(mat, fr);
  for (ElemType t : {ElemType::Hex8, ElemType::Tet4, ElemType::Tet10}) {
    const Mesh m = cube_mesh(t, 3, 0.08, 11);
    Eigen::VectorXd R = Eigen::VectorXd::Zero(3 * m.X.size());
    Eigen::MatrixXd X, u;
    Eigen::VectorXd fe;
    double scale = 0;
    for (const auto& el : m.elements) {
      X.resize(el.nn(), 3);
      u.resize(el.nn(), 3);
      for (int a = 0; a < el.nn(); ++a) {
        X.row(a) = m.X[el.n[a]].transpose();
        u.row(a) = (G * m.X[el.n[a]]).transpose();
      }
      ASSERT_TRUE(element_internal(el.type, X, u, mat.matrix, fibers, fe, nullptr));
      for (int a = 0; a < el.nn(); ++a) R.segment<3>(3 * el.n[a]) += fe.segment<3>(3 * a);
      scale = std::max(scale, fe.cwiseAbs().maxCoeff());
    }
    const auto& boundary = m.node_sets.at("boundary");
    std::vector<bool> on_b(m.X.size(), false);
    for (int b : boundary) on_b[b] = true;
    int interior = 0;
    for (size_t i = 0; i < m.X.size(); ++i) {
      if (on_b[i]) continue;
      ++interior;
      EXPECT_LT(R.segment<3>(3 * i).norm(), 1e-12 * scale) << name(t) << " node " << i;
    }
    EXPECT_GT(interior, 0);
  }
}

// A thin tet10 under a curved face, as gmsh meshes a narrow lumen coarsely (this element and face
// are from a 1 mm mesh of the patient-like artery's 1.36 mm lesion with plaque carved into it, where
// 15 of 430 lumen faces came out wrong): the face's mid-edge nodes bow into the wall and move the
// six-node centroid past the element's corner centroid. orient_surfaces must still turn the face out
// of the element: away from its fourth corner. Judged by the six-node centroid it turned the face
// into the wall, and stent points in front of it counted as 0.1-0.3 mm deep in contact.
TEST(Mesh, CurvedFaceOfAThinTetPointsOutOfIt) {
  Mesh m;
  const double x[10][3] = {
      {8.219162, 3.332721, 1.454312}, {8.179306, 3.380959, 1.50664},  {8.119849, 3.474949, 0.939782},
      {7.530878, 3.134531, 0.900369}, {8.198921, 3.357263, 1.479589}, {8.115566, 3.470217, 1.235681},
      {8.137649, 3.443211, 1.214865}, {7.863435, 3.267579, 1.203866}, {7.842443, 3.292725, 0.92304},
      {7.844935, 3.295282, 1.224847}};  // gmsh's order: edges 01 12 20 30 32 31
  for (const auto& p : x) m.X.push_back(Vec3d(p[0], p[1], p[2]) - Vec3d(8, 3, 1));
  Element el;
  el.type = ElemType::Tet10;
  for (int a = 0; a < 10; ++a) el.n[a] = a;
  m.elements.push_back(el);
  m.blocks.push_back({"intima", "artery"});
  // a valid element: positive Jacobian at its Gauss points
  Eigen::MatrixXd X(10, 3);
  for (int a = 0; a < 10; ++a) X.row(a) = m.X[a].transpose();
  Eigen::VectorXd N;
  Eigen::MatrixXd dN;
  for (const auto& q : volume_rule(ElemType::Tet10)) {
    shape(ElemType::Tet10, q.xi, N, dN);
    ASSERT_GT((X.transpose() * dN).determinant(), 0.0);
  }
  Face f;
  f.type = FaceType::Tri6;
  f.n = {2, 3, 0, 8, 7, 6};  // corners 2 3 0, mid-edge nodes 23 30 02, as the mesh file gives them
  m.surfaces.push_back({"endothelium", {f}});
  m.orient_surfaces();
  const Face& g = m.surfaces[0].faces[0];
  const Vec3d A = (m.X[g.n[1]] - m.X[g.n[0]]).cross(m.X[g.n[2]] - m.X[g.n[0]]);
  const Vec3d centre = (m.X[g.n[0]] + m.X[g.n[1]] + m.X[g.n[2]]) / 3.0;
  EXPECT_GT(A.dot(centre - m.X[1]), 0.0);  // node 1: the fourth corner
  Eigen::MatrixXd Xf(6, 3);
  for (int a = 0; a < 6; ++a) Xf.row(a) = m.X[g.n[a]].transpose();
  EXPECT_GT(face_area_vector(FaceType::Tri6, Xf).dot(A), 0.0);  // the curved face turned with its corners
}

TEST(Mesh, TubeGeneratorCountsAndOrientation) {
  TubeSpec s;
  s.part = "balloon";
  s.surface_prefix = "balloon_";
  s.length = 9.4;
  s.inner_radius = 0.45;
  s.layers = {{"balloon", 0.04, 1}};
  s.n_circ = 22;
  s.n_axial = 58;
  const Mesh m = make_tube(s);
  EXPECT_EQ(m.elements.size(), 1276u);
  EXPECT_EQ(m.X.size(), 22u * 2 * 59);
  // inner faces point toward the axis (outward of the wall)
  for (const auto& f : m.surface("balloon_inner")->faces) {
    Eigen::MatrixXd X(4, 3);
    Vec3d c = Vec3d::Zero();
    for (int a = 0; a < 4; ++a) {
      X.row(a) = m.X[f.n[a]].transpose();
      c += m.X[f.n[a]] / 4;
    }
    const Vec3d A = face_area_vector(FaceType::Quad4, X);
    EXPECT_LT(A.dot(Vec3d(c.x(), c.y(), 0)), 0.0);
  }
  for (const auto& f : m.surface("balloon_end1")->faces) {
    Eigen::MatrixXd X(4, 3);
    for (int a = 0; a < 4; ++a) X.row(a) = m.X[f.n[a]].transpose();
    EXPECT_GT(face_area_vector(FaceType::Quad4, X).z(), 0.0);
  }
  // positive element volumes
  Eigen::VectorXd f;
  for (size_t e = 0; e < m.elements.size(); e += 97) {
    Eigen::MatrixXd X(8, 3), u = Eigen::MatrixXd::Zero(8, 3);
    for (int a = 0; a < 8; ++a) X.row(a) = m.X[m.elements[e].n[a]].transpose();
    EXPECT_TRUE(element_internal(ElemType::Hex8, X, u, {1.0, 0.0}, {}, f, nullptr));
  }
}

// gmsh 4.1 ASCII reader: physical volumes -> blocks, physical surfaces -> oriented surface sets.
TEST(Mesh, ReadsGmshV4Ascii) {
  const Mesh m = read_gmsh(std::string(ANGIO_SOLID_TEST_DATA) + "/two_blocks.msh", "artery", "artery_");
  ASSERT_EQ(m.elements.size(), 2u);
  EXPECT_EQ(m.X.size(), 9u);
  ASSERT_EQ(m.blocks.size(), 2u);
  EXPECT_EQ(m.blocks[m.elements[0].block].name, "media");
  EXPECT_EQ(m.blocks[m.elements[1].block].name, "adventitia");
  EXPECT_EQ(m.elements[1].type, ElemType::Tet4);
  const SurfaceSet* endo = m.surface("artery_endo");
  ASSERT_NE(endo, nullptr);
  ASSERT_EQ(endo->faces.size(), 1u);
  Eigen::MatrixXd X(4, 3);
  for (int a = 0; a < 4; ++a) X.row(a) = m.X[endo->faces[0].n[a]].transpose();
  EXPECT_NEAR(face_area_vector(FaceType::Quad4, X).z(), -1.0, 1e-14);  // flipped to point out of the hex
  const SurfaceSet* end0 = m.surface("artery_end0");
  ASSERT_NE(end0, nullptr);
  for (int a = 0; a < 4; ++a) X.row(a) = m.X[end0->faces[0].n[a]].transpose();
  EXPECT_NEAR(face_area_vector(FaceType::Quad4, X).y(), -1.0, 1e-14);
  EXPECT_THROW(read_gmsh(std::string(ANGIO_SOLID_TEST_DATA) + "/small_artery.yaml", "a", "a_"), std::runtime_error);
}

// Frames from a polyline centerline: compared with the straight-axis frames of the tube generator
// (a straight two-segment centerline along z) and with a bent centerline's local tangent.
TEST(Mesh, CenterlineFrames) {
  TubeSpec s;
  s.part = "artery";
  s.surface_prefix = "artery_";
  s.length = 4.0;
  s.inner_radius = 1.0;
  s.layers = {{"media", 0.3, 1}};
  s.n_circ = 8;
  s.n_axial = 4;
  Mesh m = make_tube(s);
  const auto axis_frames = m.frames;
  set_frames_from_centerline(m, {Vec3d(0, 0, -3), Vec3d(0, 0, 0.5), Vec3d(0, 0, 3)});
  for (size_t e = 0; e < m.frames.size(); ++e) {
    EXPECT_NEAR((m.frames[e].circumferential - axis_frames[e].circumferential).norm(), 0.0, 1e-12);
    EXPECT_NEAR((m.frames[e].radial - axis_frames[e].radial).norm(), 0.0, 1e-12);
  }
  // bent centerline: elements above z = 1 follow the tilted segment
  const Vec3d t = Vec3d(0.3, 0, 1).normalized();
  set_frames_from_centerline(m, {Vec3d(0, 0, -3), Vec3d(0, 0, 1), Vec3d(0, 0, 1) + 5 * t});
  for (size_t e = 0; e < m.frames.size(); ++e) {
    EXPECT_NEAR(m.frames[e].axial.dot(m.frames[e].radial), 0.0, 1e-12);
    if (element_centroid(m, int(e)).z() > 1.6 && std::abs(element_centroid(m, int(e)).x()) < 0.5) {
      EXPECT_NEAR(m.frames[e].axial.dot(t), 1.0, 1e-12);
    }
  }
}
