#include "angio/solid/state_file.hpp"

#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "angio/common/h5_io.hpp"
#include "angio/solid/file_blocks.hpp"

namespace angio::solid {

using h5::H5Id;
using h5::Reader;
using h5::write_attribute;

namespace {
constexpr int kFormat = 1;
constexpr double kCoordinateTolerance = 1e-9;  // mm: the same mesh generator or file, not a similar mesh

int viscous_points_of(const Mesh& mesh, const std::vector<LayerMaterial>& materials, int e) {
  const auto& el = mesh.elements[e];
  return materials[el.block].viscous ? int(volume_rule(el.type).size()) : 0;
}

// A part's elements and nodes, ascending: the order of its rows in the file.
struct PartRows {
  std::vector<int> elements, nodes;
};
PartRows part_rows(const Mesh& mesh, const std::string& part) {
  PartRows p{part_elements(mesh, part), {}};
  std::vector<char> in(mesh.X.size(), 0);
  for (int e : p.elements)
    for (int a = 0; a < mesh.elements[e].nn(); ++a) in[mesh.elements[e].n[a]] = 1;
  for (size_t n = 0; n < in.size(); ++n)
    if (in[n]) p.nodes.push_back(int(n));
  return p;
}

// (row in `sorted`, index in `items`) of each of `items` that `sorted` (ascending) holds: where the
// rows of this rank's nodes or elements sit in a part's table.
std::vector<std::pair<long, std::size_t>> rows_of(const std::vector<int>& sorted, const std::vector<int>& items) {
  std::vector<std::pair<long, std::size_t>> out;
  for (std::size_t i = 0; i < items.size(); ++i)
    if (const auto it = std::lower_bound(sorted.begin(), sorted.end(), items[i]); it != sorted.end() && *it == items[i])
      out.emplace_back(long(it - sorted.begin()), i);
  return out;
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

std::vector<int> part_nodes(const Mesh& mesh, const std::string& part) { return part_rows(mesh, part).nodes; }

void write_state_file(SolidModel& model, const std::string& path, int step) {
  // Written by all ranks together (MPI-IO), each rank's rows sent to the rank that writes their
  // block of the file (file_blocks.hpp): no rank gathers the whole mesh's state.
  const Mesh& mesh = model.mesh();
  MPI_Comm comm = model.comm();
  const std::string tmp = path + ".tmp";
  const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
  H5Pset_fapl_mpio(fapl, comm, MPI_INFO_NULL);
  {
    H5Id file(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl), H5Fclose);
    H5Pclose(fapl);
    if (file.id < 0) throw StateFileError("cannot create " + tmp);
    const int format = kFormat;
    const double time = model.committed_time();
    write_attribute(file, "format", H5T_NATIVE_INT, &format);
    write_attribute(file, "time", H5T_NATIVE_DOUBLE, &time);
    write_attribute(file, "step", H5T_NATIVE_INT, &step);
    const bool before = model.has_commit_before();
    const double before_time = model.before_time();
    const auto& le = model.local_elements();
    std::vector<int> owned;  // this rank's owned nodes (mesh numbers)
    owned.reserve(std::size_t(model.owned_node_end() - model.owned_node_begin()));
    for (int i = model.owned_node_begin(); i < model.owned_node_end(); ++i) owned.push_back(model.old_index(i));
    for (const auto& name : part_names(mesh)) {
      const std::string g = "/parts/" + name + "/";
      // the part's nodes this rank owns: reference coordinates, displacement and the one before
      const PartRows part = part_rows(mesh, name);
      std::vector<long> position, start{0};
      std::vector<double> rows;
      for (const auto& [row, i] : rows_of(part.nodes, owned)) {
        const int n = owned[i];
        position.push_back(row);
        const Vec3d u = model.committed_displacement(n);
        rows.insert(rows.end(), mesh.X[n].data(), mesh.X[n].data() + 3);
        rows.insert(rows.end(), u.data(), u.data() + 3);
        if (before) {
          const Vec3d ub = model.displacement_before(n);
          rows.insert(rows.end(), ub.data(), ub.data() + 3);
        }
        start.push_back(long(rows.size()));
      }
      const int width = before ? 9 : 6;
      FileBlock b = to_file_block(comm, long(part.nodes.size()), position, start, rows);
      rows = {};
      std::vector<double> column(3 * std::size_t(b.size()));
      auto write_column = [&](int first, const char* dataset) {  // values first..first+2 of each row
        for (long i = 0; i < b.size(); ++i)
          for (int k = 0; k < 3; ++k) column[3 * i + k] = b.values[std::size_t(width * i + first + k)];
        write_block_rows(comm, file, g + dataset, H5T_NATIVE_DOUBLE, long(part.nodes.size()), 3, b.begin, b.size(),
                         column.data());
      };
      write_column(0, "coordinates");
      write_column(3, "displacement");
      if (before) {
        write_column(6, "displacement_before");
        H5Id ds(H5Dopen2(file, (g + "displacement_before").c_str(), H5P_DEFAULT), H5Dclose);
        write_attribute(ds, "before_time", H5T_NATIVE_DOUBLE, &before_time);
      }
      // the part's elements this rank assembles: their Gauss points' viscous history (Q, then Sv)
      position.clear();
      start.assign(1, 0);
      for (const auto& [row, i] : rows_of(part.elements, le)) {
        position.push_back(row);
        const auto v = model.viscous_state(i);
        for (int p = 0; p < v.points; ++p) rows.insert(rows.end(), v.Q[p].data(), v.Q[p].data() + 6);
        for (int p = 0; p < v.points; ++p) rows.insert(rows.end(), v.Sv[p].data(), v.Sv[p].data() + 6);
        start.push_back(long(rows.size()));
      }
      b = to_file_block(comm, long(part.elements.size()), position, start, rows);
      rows = {};
      std::vector<int> points(std::size_t(b.size()));
      long mine = 0, first = 0, all = 0;  // this block's Gauss points, the row of its first, all of them
      for (long i = 0; i < b.size(); ++i) mine += points[i] = int((b.start[i + 1] - b.start[i]) / 12);
      MPI_Exscan(&mine, &first, 1, MPI_LONG, MPI_SUM, comm);
      if (model.rank() == 0) first = 0;
      MPI_Allreduce(&mine, &all, 1, MPI_LONG, MPI_SUM, comm);
      write_block_rows(comm, file, g + "viscous_points", H5T_NATIVE_INT, long(part.elements.size()), 1, b.begin,
                       b.size(), points.data());
      std::vector<double> Q, Sv;
      Q.reserve(6 * std::size_t(mine));
      Sv.reserve(6 * std::size_t(mine));
      for (long i = 0; i < b.size(); ++i) {
        const auto q = b.values.begin() + b.start[i];
        Q.insert(Q.end(), q, q + 6 * points[i]);
        Sv.insert(Sv.end(), q + 6 * points[i], q + 12 * points[i]);
      }
      write_block_rows(comm, file, g + "viscous_Q", H5T_NATIVE_DOUBLE, all, 6, first, mine, Q.data());
      write_block_rows(comm, file, g + "viscous_Sv", H5T_NATIVE_DOUBLE, all, 6, first, mine, Sv.data());
    }
  }
  // the complete file replaces the last one only once every rank has closed it
  MPI_Barrier(comm);
  int renamed = 1;
  if (model.rank() == 0) renamed = std::rename(tmp.c_str(), path.c_str()) == 0;
  MPI_Bcast(&renamed, 1, MPI_INT, 0, comm);
  if (!renamed) throw StateFileError("cannot rename " + tmp + " to " + path);
}

namespace {
constexpr hsize_t kChunkRows = 1 << 16;  // rows read at a time: a rank holds a chunk, never a part's table

// f(first row, values) for consecutive chunks of the first `rows` rows of a [rows, cols] table.
template <class T, class F>
void for_each_chunk(const Reader& r, hid_t g, const char* table, hid_t type, int cols, long rows, F&& f) {
  for (hsize_t first = 0; first < hsize_t(rows); first += kChunkRows) {
    const hsize_t n = std::min(kChunkRows, hsize_t(rows) - first);
    f(long(first), r.block<T>(g, table, type, cols, first, n));
  }
}

// A part's group of an open state file.
hid_t open_part(const Reader& r, hid_t file, const std::string& part) {
  const hid_t g = H5Gopen2(file, ("parts/" + part).c_str(), H5P_DEFAULT);
  if (g < 0) r.fail("cannot open /parts/" + part);
  return g;
}
}  // namespace

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
    H5Id g(open_part(r, file, p.name), H5Gclose);
    const std::string at = "/parts/" + p.name + "/";
    auto finite_rows = [&](const char* table, int cols) {  // its rows, every value checked finite
      const long rows = long(r.table_rows(g, table, cols));
      for_each_chunk<double>(r, g, table, H5T_NATIVE_DOUBLE, cols, rows, [&](long first, const std::vector<double>& v) {
        for (std::size_t k = 0; k < v.size(); ++k)
          if (!std::isfinite(v[k]))
            r.fail("dataset " + std::string(table) + ": row " + std::to_string(first + long(k) / cols) +
                   " is not finite");
      });
      return rows;
    };
    p.nodes = finite_rows("coordinates", 3);
    if (finite_rows("displacement", 3) != p.nodes) r.fail(at + "displacement: not one row per node");
    if (r.exists(g, "displacement_before")) {
      if (finite_rows("displacement_before", 3) != p.nodes) r.fail(at + "displacement_before: not one row per node");
      H5Id ds(H5Dopen2(g, "displacement_before", H5P_DEFAULT), H5Dclose);
      s.before_time = r.attribute<double>(ds, "before_time", H5T_NATIVE_DOUBLE);
      s.has_before = true;
    }
    p.elements = long(r.table_rows(g, "viscous_points", 1));
    for_each_chunk<int>(r, g, "viscous_points", H5T_NATIVE_INT, 1, p.elements, [&](long, const std::vector<int>& v) {
      for (int np : v) {
        if (np < 0) r.fail(at + "viscous_points: negative");
        p.points += np;
      }
    });
    if (finite_rows("viscous_Q", 6) != p.points || finite_rows("viscous_Sv", 6) != p.points)
      r.fail(at + "viscous_Q/Sv: not one row per point");
    s.parts.push_back(std::move(p));
  }
  return s;
}

void check_state(const StateFile& state, const Mesh& mesh, const std::vector<std::string>& parts,
                 const std::vector<LayerMaterial>& materials) {
  const Reader r{state.path};
  h5::QuietErrors quiet;
  H5Id file(h5::open_for_reading(r), H5Fclose);
  for (const auto& name : parts) {
    const PartState* p = state.part(name);
    if (!p) throw StateFileError(state.path + ": has no part '" + name + "'");
    const PartRows part = part_rows(mesh, name);
    const auto& nodes = part.nodes;
    if (nodes.empty()) throw StateFileError(state.path + ": part '" + name + "' is not in this scene's mesh");
    if (long(nodes.size()) != p->nodes)
      throw StateFileError(state.path + ": part '" + name + "' has " + std::to_string(p->nodes) +
                           " nodes, this scene's mesh " + std::to_string(nodes.size()) + " (a different mesh)");
    H5Id g(open_part(r, file, name), H5Gclose);
    for_each_chunk<double>(
        r, g, "coordinates", H5T_NATIVE_DOUBLE, 3, p->nodes, [&](long first, const std::vector<double>& X) {
          for (std::size_t i = 0; 3 * i < X.size(); ++i)
            if ((mesh.X[nodes[first + i]] - Vec3d(X[3 * i], X[3 * i + 1], X[3 * i + 2])).norm() > kCoordinateTolerance)
              throw StateFileError(state.path + ": part '" + name + "' node " + std::to_string(first + long(i)) +
                                   " lies elsewhere in this scene's mesh (a different mesh)");
        });
    const auto& elems = part.elements;
    if (long(elems.size()) != p->elements)
      throw StateFileError(state.path + ": part '" + name + "' has " + std::to_string(p->elements) +
                           " elements, this scene's mesh " + std::to_string(elems.size()));
    for_each_chunk<int>(r, g, "viscous_points", H5T_NATIVE_INT, 1, p->elements,
                        [&](long first, const std::vector<int>& points) {
                          for (std::size_t k = 0; k < points.size(); ++k)
                            if (viscous_points_of(mesh, materials, elems[first + k]) != points[k])
                              throw StateFileError(state.path + ": part '" + name + "' element " +
                                                   std::to_string(first + long(k)) + ": viscous history " +
                                                   (points[k] ? "in the file, not in this scene's material"
                                                              : "in this scene's material, not in the file"));
                        });
  }
}

namespace {
// apply_state's reading, on this rank: u and ub (held order) and its elements' viscous history.
void read_rows(SolidModel& model, const StateFile& state, const std::vector<std::string>& parts, std::vector<double>& u,
               std::vector<double>& ub) {
  const Mesh& mesh = model.mesh();
  const Reader r{state.path};
  h5::QuietErrors quiet;
  H5Id file(h5::open_for_reading(r), H5Fclose);
  // read again since the scene reader checked it: a run that still writes it may have replaced it
  if (r.attribute<double>(file, "time", H5T_NATIVE_DOUBLE) != state.time ||
      r.attribute<int>(file, "step", H5T_NATIVE_INT) != state.step)
    r.fail("replaced since the scene was read (another time or step): continue from a state file no run writes");
  // this rank's elements' viscous history (elements of other parts: none)
  const auto& le = model.local_elements();
  for (std::size_t i = 0; i < le.size(); ++i) {
    const auto v = model.viscous_state(i);
    std::fill(v.Q, v.Q + v.points, Vec6::Zero());
    std::fill(v.Sv, v.Sv + v.points, Vec6::Zero());
  }
  for (const auto& name : parts) {
    const PartState* p = state.part(name);
    H5Id g(open_part(r, file, name), H5Gclose);
    const PartRows part = part_rows(mesh, name);
    auto take = [&](const char* table, std::vector<double>& into) {  // the held nodes' rows of a table
      for_each_chunk<double>(r, g, table, H5T_NATIVE_DOUBLE, 3, p->nodes,
                             [&](long first, const std::vector<double>& v) {
                               for (std::size_t i = 0; 3 * i < v.size(); ++i)
                                 if (const int h = model.held_index(part.nodes[first + i]); h >= 0)
                                   std::copy_n(v.begin() + 3 * i, 3, into.begin() + 3 * h);
                             });
    };
    take("displacement", u);
    if (state.has_before) take(r.exists(g, "displacement_before") ? "displacement_before" : "displacement", ub);
    // the Gauss points of this rank's elements of the part, by their row in viscous_Q and viscous_Sv
    const auto want = rows_of(part.elements, le);  // (element row, local element), ascending
    struct Point {
      long row;           // in viscous_Q and viscous_Sv
      std::size_t local;  // the element's index in local_elements()
      int point;          // the Gauss point's index in the element
    };
    std::vector<Point> points;  // ascending row
    long row = 0;
    std::size_t next = 0;
    for_each_chunk<int>(r, g, "viscous_points", H5T_NATIVE_INT, 1, p->elements,
                        [&](long first, const std::vector<int>& n) {
                          for (std::size_t k = 0; k < n.size(); row += n[k], ++k)
                            if (next < want.size() && want[next].first == first + long(k)) {
                              for (int q = 0; q < n[k]; ++q) points.push_back({row + q, want[next].second, q});
                              ++next;
                            }
                        });
    for (const bool is_q : {true, false}) {
      std::size_t at = 0;  // the next Gauss point to fill
      for_each_chunk<double>(r, g, is_q ? "viscous_Q" : "viscous_Sv", H5T_NATIVE_DOUBLE, 6, p->points,
                             [&](long first, const std::vector<double>& v) {
                               const long end = first + long(v.size() / 6);
                               for (; at < points.size() && points[at].row < end; ++at) {
                                 const auto s = model.viscous_state(points[at].local);
                                 Vec6& dst = is_q ? s.Q[points[at].point] : s.Sv[points[at].point];
                                 for (int c = 0; c < 6; ++c) dst(c) = v[std::size_t(6 * (points[at].row - first) + c)];
                               }
                             });
    }
  }
}
}  // namespace

void apply_state(SolidModel& model, const StateFile& state, const std::vector<std::string>& parts) {
  // the held nodes' displacement and the commit before (held order; nodes of other parts: none)
  std::vector<double> u(3 * std::size_t(model.num_held_nodes()), 0.0), ub(state.has_before ? u.size() : 0, 0.0);
  std::string error;  // every rank reads the file: one that fails must not go on alone into collective calls
  try {
    read_rows(model, state, parts, u, ub);
  } catch (const std::exception& e) {
    error = e.what();
  }
  int ok = error.empty(), all = 0;
  MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, model.comm());
  if (!all) throw StateFileError(ok ? state.path + ": another rank could not read it" : error);
  model.start_from_held(state.time, std::move(u), std::move(ub), state.before_time);
}

}  // namespace angio::solid
