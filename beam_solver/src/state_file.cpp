#include "angio/beam/state_file.hpp"

#include <cmath>
#include <cstdio>

#include "angio/common/h5_io.hpp"

namespace angio::beam {

using h5::H5Id;
using Vec4 = Eigen::Matrix<double, 4, 1>;

namespace {
constexpr int kFormat = 1;
constexpr double kCoordinateTolerance = 1e-9;  // mm: the same stent, not a similar one
}  // namespace

void write_beam_state(const BeamModel& m, const std::string& path, int step) {
  const std::string tmp = path + ".tmp";
  {
    H5Id file(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose);
    if (file.id < 0) throw h5::Error("cannot create " + tmp);
    const int format = kFormat;
    const double time = m.time();
    h5::write_attribute(file, "format", H5T_NATIVE_INT, &format);
    h5::write_attribute(file, "time", H5T_NATIVE_DOUBLE, &time);
    h5::write_attribute(file, "step", H5T_NATIVE_INT, &step);
    std::vector<Vec3> X(m.num_nodes()), x(m.num_nodes());
    std::vector<Vec4> R(m.num_nodes()), pl(m.num_elements());
    for (int n = 0; n < m.num_nodes(); ++n) {
      X[n] = m.reference_position(n);
      x[n] = m.position(n);
      const Quat& q = m.rotation(n);
      R[n] = Vec4(q.w(), q.x(), q.y(), q.z());
    }
    for (int e = 0; e < m.num_elements(); ++e) {
      const PlasticState& p = m.committed_state(e);
      pl[e] = Vec4(p.omega_pl(0), p.omega_pl(1), p.omega_pl(2), p.kappa_bar);
    }
    h5::write_rows(file, "reference", X);
    h5::write_rows(file, "position", x);
    h5::write_rows(file, "rotation", R);
    h5::write_rows(file, "plastic", pl);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) throw h5::Error("cannot rename " + tmp + " to " + path);
}

BeamState read_beam_state(const std::string& path) {
  h5::Reader r{path};
  h5::QuietErrors quiet;
  H5Id file(h5::open_for_reading(r), H5Fclose);
  BeamState s;
  s.path = path;
  const int format = r.attribute<int>(file, "format", H5T_NATIVE_INT);
  if (format != kFormat)
    r.fail("state file format " + std::to_string(format) + ", this solver reads " + std::to_string(kFormat));
  s.time = r.attribute<double>(file, "time", H5T_NATIVE_DOUBLE);
  s.step = r.attribute<int>(file, "step", H5T_NATIVE_INT);
  if (!std::isfinite(s.time)) r.fail("time is not finite");
  s.X = r.rows<3>(file, "reference");
  s.x = r.rows<3>(file, "position");
  const auto R = r.rows<4>(file, "rotation");
  const auto pl = r.rows<4>(file, "plastic");
  if (s.x.size() != s.X.size() || R.size() != s.X.size()) r.fail("position/rotation: not one row per node");
  for (const auto& q : R) {
    if (std::abs(q.norm() - 1.0) > 1e-9) r.fail("rotation: not a unit quaternion");
    s.R.emplace_back(q(0), q(1), q(2), q(3));
  }
  for (const auto& p : pl) {
    PlasticState ps;
    ps.omega_pl = p.head<3>();
    ps.kappa_bar = p(3);
    s.plastic.push_back(ps);
  }
  return s;
}

void check_beam_state(const BeamState& s, const BeamModel& m) {
  if (int(s.X.size()) != m.num_nodes() || int(s.plastic.size()) != m.num_elements())
    throw h5::Error(s.path + ": a stent of " + std::to_string(s.X.size()) + " nodes and " +
                    std::to_string(s.plastic.size()) + " elements, this scene's has " + std::to_string(m.num_nodes()) +
                    " and " + std::to_string(m.num_elements()) + " (a different stent)");
  for (int n = 0; n < m.num_nodes(); ++n)
    if ((s.X[n] - m.reference_position(n)).norm() > kCoordinateTolerance)
      throw h5::Error(s.path + ": node " + std::to_string(n) +
                      " of the stent lies elsewhere in this scene (a different stent)");
}

void apply_beam_state(BeamModel& m, const BeamState& s) { m.start_from(s.time, s.x, s.R, s.plastic); }

}  // namespace angio::beam
