#include "angio/solid/state_file.hpp"

#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "angio/common/h5_io.hpp"
#include "angio/solid/gather.hpp"

namespace angio::solid {

using h5::H5Id;
using h5::Reader;
using h5::write_attribute;
using h5::write_dataset;
using h5::write_rows;

namespace {
constexpr int kFormat = 1;
constexpr double kCoordinateTolerance = 1e-9;  // mm: the same mesh generator or file, not a similar mesh

int viscous_points_of(const Mesh& mesh, const std::vector<LayerMaterial>& materials, int e) {
  const auto& el = mesh.elements[e];
  return materials[el.block].viscous ? int(volume_rule(el.type).size()) : 0;
}
}  // namespace

const PartState* StateFile::part(const std::string& name) const {
  for (const auto& p : parts)
    if (p.name == name) return &p;
  return nullptr;
}

std::vector<int> part_elements(const Mesh& mesh, const std::string& part) {
  std::vector<int> elems;
  for (size_t e = 0; e < mesh.elements.size(); ++e)
    if (mesh.blocks[mesh.elements[e].block].part == part) elems.push_back(int(e));
  return elems;
}

std::vector<int> part_nodes(const Mesh& mesh, const std::string& part) {
  std::vector<char> in(mesh.X.size(), 0);
  for (int e : part_elements(mesh, part))
    for (int a = 0; a < mesh.elements[e].nn(); ++a) in[mesh.elements[e].n[a]] = 1;
  std::vector<int> nodes;
  for (size_t n = 0; n < in.size(); ++n)
    if (in[n]) nodes.push_back(int(n));
  return nodes;
}

void write_state_file(SolidModel& model, const std::string& path, int step) {
  const Mesh& mesh = model.mesh();
  // every rank's viscous history as (element, points, Q..., Sv...) rows, gathered on rank 0
  std::vector<double> mine;
  const auto& le = model.local_elements();
  for (size_t i = 0; i < le.size(); ++i) {
    const auto v = model.viscous_state(i);
    if (v.points == 0) continue;
    mine.push_back(le[i]);
    mine.push_back(v.points);
    for (int g = 0; g < v.points; ++g) mine.insert(mine.end(), v.Q[g].data(), v.Q[g].data() + 6);
    for (int g = 0; g < v.points; ++g) mine.insert(mine.end(), v.Sv[g].data(), v.Sv[g].data() + 6);
  }
  const std::vector<double> all = gather_on_root(model.comm(), mine);
  std::vector<Vec3d> committed, before;
  double before_time = 0.0;
  const bool has_before = model.gather_committed(committed, before, before_time);  // on rank 0
  if (model.rank() != 0) return;
  std::map<int, size_t> at;  // element -> offset of its row in `all`
  for (size_t k = 0; k < all.size(); k += 2 + 12 * size_t(all[k + 1])) at[int(all[k])] = k;

  const std::string tmp = path + ".tmp";
  {
    H5Id file(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose);
    if (file.id < 0) throw StateFileError("cannot create " + tmp);
    const int format = kFormat;
    const double time = model.committed_time();
    write_attribute(file, "format", H5T_NATIVE_INT, &format);
    write_attribute(file, "time", H5T_NATIVE_DOUBLE, &time);
    write_attribute(file, "step", H5T_NATIVE_INT, &step);
    H5Id parts(H5Gcreate2(file, "parts", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    for (const auto& name : part_names(mesh)) {
      H5Id g(H5Gcreate2(parts, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
      const auto nodes = part_nodes(mesh, name);
      std::vector<Vec3d> X(nodes.size()), u(nodes.size()), ub(nodes.size());
      for (size_t i = 0; i < nodes.size(); ++i) {
        X[i] = mesh.X[nodes[i]];
        u[i] = committed[nodes[i]];
        if (has_before) ub[i] = before[nodes[i]];
      }
      write_rows(g, "coordinates", X);
      write_rows(g, "displacement", u);
      if (has_before) {
        write_rows(g, "displacement_before", ub);
        H5Id ds(H5Dopen2(g, "displacement_before", H5P_DEFAULT), H5Dclose);
        write_attribute(ds, "before_time", H5T_NATIVE_DOUBLE, &before_time);
      }
      std::vector<int> points;
      std::vector<double> Q, Sv;
      for (int e : part_elements(mesh, name)) {
        const auto it = at.find(e);
        const int np = it == at.end() ? 0 : int(all[it->second + 1]);
        points.push_back(np);
        if (!np) continue;
        const double* q = all.data() + it->second + 2;
        Q.insert(Q.end(), q, q + 6 * np);
        Sv.insert(Sv.end(), q + 6 * np, q + 12 * np);
      }
      write_dataset(g, "viscous_points", H5T_NATIVE_INT, points.size(), 1, points.data());
      write_dataset(g, "viscous_Q", H5T_NATIVE_DOUBLE, Q.size() / 6, 6, Q.data());
      write_dataset(g, "viscous_Sv", H5T_NATIVE_DOUBLE, Sv.size() / 6, 6, Sv.data());
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) throw StateFileError("cannot rename " + tmp + " to " + path);
}

StateFile read_state_file(const std::string& path) {
  Reader r{path};
  StateFile s;
  s.path = path;
  h5::QuietErrors quiet;
  H5Id file(h5::open_for_reading(r), H5Fclose);
  const int format = r.attribute<int>(file, "format", H5T_NATIVE_INT);
  if (format != kFormat)
    r.fail("state file format " + std::to_string(format) + ", this solver reads " + std::to_string(kFormat));
  s.time = r.attribute<double>(file, "time", H5T_NATIVE_DOUBLE);
  s.step = r.attribute<int>(file, "step", H5T_NATIVE_INT);
  if (!std::isfinite(s.time)) r.fail("time is not finite");
  if (!r.exists(file, "parts")) r.fail("missing group /parts");
  H5Id parts(H5Gopen2(file, "parts", H5P_DEFAULT), H5Gclose);
  H5G_info_t info;
  H5Gget_info(parts, &info);
  for (hsize_t i = 0; i < info.nlinks; ++i) {
    char name[256];
    if (H5Lget_name_by_idx(parts, ".", H5_INDEX_NAME, H5_ITER_INC, i, name, sizeof name, H5P_DEFAULT) < 0)
      r.fail("cannot list /parts");
    PartState p;
    p.name = name;
    H5Id g(H5Gopen2(parts, name, H5P_DEFAULT), H5Gclose);
    const std::string at = "/parts/" + p.name + "/";
    p.X = r.rows<3>(g, "coordinates");
    p.u = r.rows<3>(g, "displacement");
    if (p.u.size() != p.X.size()) r.fail(at + "displacement: not one row per node");
    if (r.exists(g, "displacement_before")) {
      p.u_before = r.rows<3>(g, "displacement_before");
      if (p.u_before.size() != p.X.size()) r.fail(at + "displacement_before: not one row per node");
      H5Id ds(H5Dopen2(g, "displacement_before", H5P_DEFAULT), H5Dclose);
      s.before_time = r.attribute<double>(ds, "before_time", H5T_NATIVE_DOUBLE);
      s.has_before = true;
    }
    hsize_t rows = 0;
    p.viscous_points = r.dataset<int>(g, "viscous_points", H5T_NATIVE_INT, 1, rows);
    p.Q = r.rows<6>(g, "viscous_Q");
    p.Sv = r.rows<6>(g, "viscous_Sv");
    long total = 0;
    for (int np : p.viscous_points) {
      if (np < 0) r.fail(at + "viscous_points: negative");
      total += np;
    }
    if (size_t(total) != p.Q.size() || p.Q.size() != p.Sv.size()) r.fail(at + "viscous_Q/Sv: not one row per point");
    s.parts.push_back(std::move(p));
  }
  return s;
}

void check_state(const StateFile& state, const Mesh& mesh, const std::vector<std::string>& parts,
                 const std::vector<LayerMaterial>& materials) {
  for (const auto& name : parts) {
    const PartState* p = state.part(name);
    if (!p) throw StateFileError(state.path + ": has no part '" + name + "'");
    const auto nodes = part_nodes(mesh, name);
    if (nodes.empty()) throw StateFileError(state.path + ": part '" + name + "' is not in this scene's mesh");
    if (nodes.size() != p->X.size())
      throw StateFileError(state.path + ": part '" + name + "' has " + std::to_string(p->X.size()) +
                           " nodes, this scene's mesh " + std::to_string(nodes.size()) + " (a different mesh)");
    for (size_t i = 0; i < nodes.size(); ++i)
      if ((mesh.X[nodes[i]] - p->X[i]).norm() > kCoordinateTolerance)
        throw StateFileError(state.path + ": part '" + name + "' node " + std::to_string(i) +
                             " lies elsewhere in this scene's mesh (a different mesh)");
    const auto elems = part_elements(mesh, name);
    if (elems.size() != p->viscous_points.size())
      throw StateFileError(state.path + ": part '" + name + "' has " + std::to_string(p->viscous_points.size()) +
                           " elements, this scene's mesh " + std::to_string(elems.size()));
    for (size_t k = 0; k < elems.size(); ++k)
      if (viscous_points_of(mesh, materials, elems[k]) != p->viscous_points[k])
        throw StateFileError(state.path + ": part '" + name + "' element " + std::to_string(k) + ": viscous history " +
                             (p->viscous_points[k] ? "in the file, not in this scene's material"
                                                   : "in this scene's material, not in the file"));
  }
}

void apply_state(SolidModel& model, const StateFile& state, const std::vector<std::string>& parts) {
  const Mesh& mesh = model.mesh();
  std::vector<Vec3d> u(mesh.X.size(), Vec3d::Zero()), ub;
  if (state.has_before) ub.assign(mesh.X.size(), Vec3d::Zero());
  std::vector<long> offset(mesh.elements.size(), -1);  // first history row of each element in its part
  std::vector<const PartState*> of(mesh.elements.size(), nullptr);
  for (const auto& name : parts) {
    const PartState* p = state.part(name);
    const auto nodes = part_nodes(mesh, name);
    for (size_t i = 0; i < nodes.size(); ++i) {
      u[nodes[i]] = p->u[i];
      if (state.has_before) ub[nodes[i]] = p->u_before.empty() ? p->u[i] : p->u_before[i];
    }
    const auto elems = part_elements(mesh, name);
    long row = 0;
    for (size_t k = 0; k < elems.size(); ++k) {
      offset[elems[k]] = row;
      of[elems[k]] = p;
      row += p->viscous_points[k];
    }
  }
  model.start_from(state.time, u, ub, state.before_time);
  const auto& le = model.local_elements();
  for (size_t i = 0; i < le.size(); ++i) {
    auto v = model.viscous_state(i);
    for (int g = 0; g < v.points; ++g) {
      const PartState* p = of[le[i]];
      v.Q[g] = p ? p->Q[offset[le[i]] + g] : Vec6::Zero();
      v.Sv[g] = p ? p->Sv[offset[le[i]] + g] : Vec6::Zero();
    }
  }
}

}  // namespace angio::solid
