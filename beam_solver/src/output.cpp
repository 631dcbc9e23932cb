#include "angio/beam/output.hpp"

#include <hdf5.h>

#include <nlohmann/json.hpp>

#include "angio/common/h5_io.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace angio::beam {

namespace {

// a number in the XDMF text (the summary is written with nlohmann::json)
std::string num(double v) {
  if (!std::isfinite(v)) return "null";
  std::ostringstream os;
  os << std::setprecision(10) << v;
  return os.str();
}

}  // namespace

BeamOutput::BeamOutput(const std::string& dir) : dir_(dir) {
  std::filesystem::create_directories(dir_);
  const std::string path = dir_ + "/beam.h5";
  file_ = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (file_ < 0) throw std::runtime_error("cannot create " + path);
}

BeamOutput::~BeamOutput() { close(); }

void BeamOutput::close() {
  if (file_ >= 0) {
    H5Fclose(static_cast<hid_t>(file_));
    file_ = -1;
  }
}

void BeamOutput::write_step(const BeamModel& m, int step, double time) {
  if (file_ < 0) return;
  const hid_t f = static_cast<hid_t>(file_);
  nn_ = m.num_nodes();
  ne_ = m.num_elements();
  ng_ = m.num_sample_points();
  if (steps_.empty()) {
    h5::H5Id g(H5Gcreate2(f, "/mesh", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    if (g.id < 0) throw std::runtime_error("HDF5: cannot create group /mesh");
    std::vector<int> conn;
    for (int e = 0; e < ne_; ++e) {
      conn.push_back(m.element_nodes(e)[0]);
      conn.push_back(m.element_nodes(e)[1]);
    }
    h5::write_dataset(g, "connectivity", H5T_NATIVE_INT, ne_, 2, conn.data());
    std::vector<Vec3> X(nn_);
    for (int n = 0; n < nn_; ++n) X[n] = m.reference_position(n);
    h5::write_rows(g, "reference_positions", X);
  }
  char name[64];
  std::snprintf(name, sizeof name, "/step_%06d", static_cast<int>(steps_.size()));
  h5::H5Id g(H5Gcreate2(f, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
  if (g.id < 0) throw std::runtime_error(std::string("HDF5: cannot create group ") + name);
  h5::write_attribute(g, "time", H5T_NATIVE_DOUBLE, &time);
  h5::write_attribute(g, "step", H5T_NATIVE_INT, &step);
  std::vector<Vec3> x(nn_), u(nn_), rv(nn_);
  std::vector<double> quat;
  for (int n = 0; n < nn_; ++n) {
    x[n] = m.position(n);
    u[n] = x[n] - m.reference_position(n);
    rv[n] = quat_log(m.rotation(n));
    const Quat& q = m.rotation(n);
    quat.insert(quat.end(), {q.w(), q.x(), q.y(), q.z()});
  }
  h5::write_rows(g, "positions", x);
  h5::write_rows(g, "displacement", u);
  h5::write_rows(g, "rotation_vector", rv);
  h5::write_dataset(g, "rotation_quaternion_wxyz", H5T_NATIVE_DOUBLE, nn_, 4, quat.data());
  h5::write_rows(g, "contact_force", m.sample_load_nodal_forces());
  std::vector<double> mb(ne_), kp(ne_), nx(ne_), mt(ne_);
  for (int e = 0; e < ne_; ++e) {
    mb[e] = m.bending_moment_norm(e);
    kp[e] = m.committed_state(e).kappa_bar;
    const Vec6 s = m.stress_resultants(e);
    nx[e] = s(0);
    mt[e] = s(3);
  }
  h5::write_dataset(g, "bending_moment_norm", H5T_NATIVE_DOUBLE, ne_, 1, mb.data());
  h5::write_dataset(g, "accumulated_plastic_curvature", H5T_NATIVE_DOUBLE, ne_, 1, kp.data());
  h5::write_dataset(g, "axial_force", H5T_NATIVE_DOUBLE, ne_, 1, nx.data());
  h5::write_dataset(g, "torsion_moment", H5T_NATIVE_DOUBLE, ne_, 1, mt.data());
  std::vector<Vec3> sx(ng_);
  for (int i = 0; i < ng_; ++i) sx[i] = m.sample_position(i);
  h5::write_rows(g, "sample_positions", sx);
  h5::write_rows(g, "contact_line_loads", m.sample_contact_loads());
  H5Fflush(f, H5F_SCOPE_GLOBAL);
  steps_.push_back({step, time, std::string(name).substr(1)});
  write_xdmf();
}

void BeamOutput::write_xdmf() const {
  std::ostringstream os;
  os << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n<Domain>\n";
  auto item = [&](const std::string& path, int rows, int cols, const char* type = "Float") {
    std::ostringstream s;
    s << "<DataItem Dimensions=\"" << rows;
    if (cols > 1) s << " " << cols;
    s << "\" NumberType=\"" << type << "\" Precision=\"" << (type[0] == 'I' ? 4 : 8)
      << "\" Format=\"HDF\">beam.h5:" << path << "</DataItem>";
    return s.str();
  };
  os << "<Grid Name=\"stent\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (const auto& s : steps_) {
    const std::string G = "/" + s.group + "/";
    os << "<Grid Name=\"stent_" << s.step << "\" GridType=\"Uniform\">\n<Time Value=\"" << num(s.time)
       << "\"/>\n<Topology TopologyType=\"Polyline\" NodesPerElement=\"2\" NumberOfElements=\"" << ne_ << "\">"
       << item("/mesh/connectivity", ne_, 2, "Int") << "</Topology>\n"
       << "<Geometry GeometryType=\"XYZ\">" << item(G + "positions", nn_, 3) << "</Geometry>\n";
    for (const char* a : {"displacement", "rotation_vector", "contact_force"})
      os << "<Attribute Name=\"" << a << "\" AttributeType=\"Vector\" Center=\"Node\">" << item(G + a, nn_, 3)
         << "</Attribute>\n";
    for (const char* a : {"bending_moment_norm", "accumulated_plastic_curvature", "axial_force", "torsion_moment"})
      os << "<Attribute Name=\"" << a << "\" AttributeType=\"Scalar\" Center=\"Cell\">" << item(G + a, ne_, 1)
         << "</Attribute>\n";
    os << "</Grid>\n";
  }
  os << "</Grid>\n";
  os << "<Grid Name=\"contact_samples\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (const auto& s : steps_) {
    const std::string G = "/" + s.group + "/";
    os << "<Grid Name=\"samples_" << s.step << "\" GridType=\"Uniform\">\n<Time Value=\"" << num(s.time)
       << "\"/>\n<Topology TopologyType=\"Polyvertex\" NumberOfElements=\"" << ng_ << "\"/>\n"
       << "<Geometry GeometryType=\"XYZ\">" << item(G + "sample_positions", ng_, 3) << "</Geometry>\n"
       << "<Attribute Name=\"contact_line_load\" AttributeType=\"Vector\" Center=\"Node\">"
       << item(G + "contact_line_loads", ng_, 3) << "</Attribute>\n</Grid>\n";
  }
  os << "</Grid>\n</Domain>\n</Xdmf>\n";
  const std::string tmp = dir_ + "/beam.xdmf.tmp";
  {
    std::ofstream f(tmp);
    f << os.str();
  }
  std::filesystem::rename(tmp, dir_ + "/beam.xdmf");
}

std::string write_summary(const std::string& path, const BeamModel& m, const std::vector<StepRecord>& steps,
                          bool generated_stent, const std::string& status, double newton_seconds,
                          long newton_iterations, const StepRecord& initial) {
  using nlohmann::ordered_json;
  // non-finite numbers (e.g. the NaN stent measures of a model that is not a generated stent)
  // are written as null, never as NaN tokens
  auto finite = [](double v) { return std::isfinite(v) ? ordered_json(v) : ordered_json(nullptr); };
  ordered_json j;
  j["status"] = status;
  j["units"] = {{"length", "mm"}, {"force", "N"}, {"moment", "N mm"}, {"time", "s"}};
  j["num_nodes"] = m.num_nodes();
  j["num_elements"] = m.num_elements();
  j["generated_stent"] = generated_stent;
  const double D0 = initial.diameter;  // initial (crimped) diameter
  double Dmax = D0, tmax = 0;
  for (const auto& s : steps)
    if (s.diameter > Dmax) {
      Dmax = s.diameter;
      tmax = s.time;
    }
  const double Dfinal = steps.empty() ? D0 : steps.back().diameter;
  j["diameter"] = {
      {"initial", finite(D0)},
      {"max", finite(Dmax)},
      {"time_of_max", finite(tmax)},
      {"final", finite(Dfinal)},
      {"recoil", finite(Dmax - Dfinal)},
      {"recoil_percent", finite(Dmax > 0 ? 100.0 * (Dmax - Dfinal) / Dmax : 0.0)},
      {"definition", std::string("2 x mean radial distance of all nodes from the device axis") +
                         (generated_stent ? " of the deformed stent (polyline through the ring centroids)" : "")}};
  if (generated_stent && !steps.empty()) {
    // dogboning = (D_distal − D_central)/D_distal; foreshortening = (L0 − L)/L0
    double dbmax = -1e300, tdb = 0;
    for (const auto& s : steps) {
      const double db = (s.distal_diameter - s.central_diameter) / s.distal_diameter;
      if (db > dbmax) {
        dbmax = db;
        tdb = s.time;
      }
    }
    const auto& pk = *std::max_element(steps.begin(), steps.end(),
                                       [](const auto& a, const auto& b) { return a.diameter < b.diameter; });
    const auto& fin = steps.back();
    const double L0 = initial.length;
    j["stent"] = {
        {"length_initial", finite(L0)},
        {"length_at_max_diameter", finite(pk.length)},
        {"length_final", finite(fin.length)},
        {"foreshortening_at_max_diameter_percent", finite(100.0 * (L0 - pk.length) / L0)},
        {"foreshortening_final_percent", finite(100.0 * (L0 - fin.length) / L0)},
        {"distal_diameter_at_max", finite(pk.distal_diameter)},
        {"central_diameter_at_max", finite(pk.central_diameter)},
        {"dogboning_at_max_diameter_percent",
         finite(100.0 * (pk.distal_diameter - pk.central_diameter) / pk.distal_diameter)},
        {"dogboning_max_percent", finite(100.0 * dbmax)},
        {"time_of_dogboning_max", finite(tdb)},
        {"axis_sagitta_initial", finite(initial.axis_sagitta)},
        {"axis_sagitta_at_max_diameter", finite(pk.axis_sagitta)},
        {"axis_sagitta_final", finite(fin.axis_sagitta)},
        {"axis_radius_initial", finite(initial.axis_radius)},
        {"axis_radius_at_max_diameter", finite(pk.axis_radius)},
        {"axis_radius_final", finite(fin.axis_radius)},
        {"axis_radius_halves_initial", {finite(initial.axis_radius_half[0]), finite(initial.axis_radius_half[1])}},
        {"axis_radius_halves_at_max_diameter", {finite(pk.axis_radius_half[0]), finite(pk.axis_radius_half[1])}},
        {"axis_radius_halves_final", {finite(fin.axis_radius_half[0]), finite(fin.axis_radius_half[1])}},
        {"definitions",
         "D_distal: outer crowns of the end rings, D_central: crowns of the middle ring(s); "
         "dogboning = (D_distal - D_central)/D_distal; foreshortening = (L0 - L)/L0, L = extent of the nodes along "
         "the deformed axis (through the ring centroids); "
         "axis sagitta: distance of the middle crowns' centroid from the chord through the centroids of the end "
         "rings' outer crowns, axis radius: radius of the circle through the three (null: straight); "
         "axis radius of the halves: the circles through the centroids of the end, quarter and middle rings "
         "(null: straight or fewer than 5 rings)"}};
  }
  int total_it = 0;
  double total_wall = 0;
  for (const auto& s : steps) {
    total_it += s.iterations;
    total_wall += s.wall_seconds;
  }
  j["newton_iterations_total"] = total_it;
  j["wall_seconds_total"] = finite(total_wall);
  j["newton_seconds_total"] = finite(newton_seconds);
  j["seconds_per_newton_iteration"] = finite(newton_iterations > 0 ? newton_seconds / newton_iterations : 0.0);
  j["steps"] = ordered_json::array();
  for (const auto& s : steps) {
    ordered_json e;
    e["step"] = s.step;
    e["time"] = finite(s.time);
    e["diameter"] = finite(s.diameter);
    e["iterations"] = s.iterations;
    e["residual"] = finite(s.residual);
    e["max_bending_moment"] = finite(s.max_bending_moment);
    if (generated_stent) {
      e["distal_diameter"] = finite(s.distal_diameter);
      e["central_diameter"] = finite(s.central_diameter);
      e["length"] = finite(s.length);
      e["axis_sagitta"] = finite(s.axis_sagitta);
      e["axis_radius"] = finite(s.axis_radius);
      e["axis_radius_halves"] = {finite(s.axis_radius_half[0]), finite(s.axis_radius_half[1])};
    }
    e["wall_seconds"] = finite(s.wall_seconds);
    j["steps"].push_back(std::move(e));
  }
  j["final_positions"] = ordered_json::array();
  for (int n = 0; n < m.num_nodes(); ++n) {
    const Vec3& x = m.position(n);
    j["final_positions"].push_back({finite(x.x()), finite(x.y()), finite(x.z())});
  }
  // invalid UTF-8 in a string (a status or path from outside) is replaced, not an exception
  const std::string text = j.dump(2, ' ', false, ordered_json::error_handler_t::replace) + "\n";
  std::ofstream f(path);
  if (!f) throw std::runtime_error("cannot write " + path);
  f << text;
  return text;
}

}  // namespace angio::beam
