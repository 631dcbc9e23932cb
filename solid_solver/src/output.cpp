#include "angio/solid/output.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "angio/solid/file_blocks.hpp"

namespace angio::solid {

void make_directories(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error("cannot create directory " + dir + ": " + ec.message());
}

namespace {
// Static per-element vectors written once under /mesh/<type>/ when the mesh has fiber frames
// (Mesh::frames, one per element): the local material frame (e_c, e_a, e_r) and the directions a0
// of the element's fiber families resolved from it (materials.hpp, resolve_fibers), so that fiber
// directions can be checked in ParaView (glyphs).
std::vector<std::string> cell_vector_names(const SolidModel& model) {
  const Mesh& mesh = model.mesh();
  if (mesh.elements.empty() || mesh.frames.size() != mesh.elements.size()) return {};
  std::vector<std::string> names{"frame_circumferential", "frame_axial", "frame_radial"};
  size_t families = 0;
  for (const auto& mat : model.materials()) families = std::max(families, resolve_fibers(mat, Frame{}).size());
  for (size_t k = 0; k < families; ++k) names.push_back("fiber_" + std::to_string(k + 1));
  return names;
}

// The vectors of cell_vector_names() for element e; fiber_k is zero where e has fewer families.
std::vector<Vec3d> cell_vectors(const SolidModel& model, int e, size_t count) {
  const Frame& f = model.mesh().frames[e];
  std::vector<Vec3d> v{f.circumferential, f.axial, f.radial};
  for (const auto& fiber : resolve_fibers(model.materials()[model.mesh().elements[e].block], f)) v.push_back(fiber.a0);
  v.resize(count, Vec3d::Zero());
  return v;
}

// <Attribute> of an XDMF grid: `cols` = 1 (Scalar) or 3 (Vector) values per node or cell
// (center "Node"/"Cell") from the HDF5 dataset `path` ("solid.h5:/...") of `rows` rows.
void xdmf_attribute(std::ostream& x, const std::string& name, const char* center, long rows, int cols,
                    const std::string& path, const char* number = "Float") {
  const bool real = std::string(number) == "Float";
  x << "     <Attribute Name=\"" << name << "\" AttributeType=\"" << (cols == 3 ? "Vector" : "Scalar") << "\" Center=\""
    << center << "\">\n      <DataItem Dimensions=\"" << rows << (cols == 3 ? " 3" : "") << "\" NumberType=\"" << number
    << "\"" << (real ? " Precision=\"8\"" : "") << " Format=\"HDF\">" << path << "</DataItem>\n     </Attribute>\n";
}

const char* xdmf_topology(ElemType t) {
  switch (t) {
    case ElemType::Hex8:
      return "Hexahedron";
    case ElemType::Tet4:
      return "Tetrahedron";
    case ElemType::Tet10:
      return "Tetrahedron_10";
  }
  return "";
}
}  // namespace

FieldWriter::FieldWriter(const SolidModel& model, const std::string& dir) : model_(model), dir_(dir) {
  MPI_Comm comm = model.comm();
  if (model.rank() == 0) make_directories(dir);
  MPI_Barrier(comm);
  hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
  H5Pset_fapl_mpio(fapl, comm, MPI_INFO_NULL);
  file_ = H5Fcreate((dir + "/solid.h5").c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
  H5Pclose(fapl);
  if (file_ < 0) throw std::runtime_error("cannot create " + dir + "/solid.h5");
  const auto& mesh = model.mesh();
  // nodes: rank owns [owned_node_begin, owned_node_end) in the new numbering
  const long n0 = model.owned_node_begin(), n1 = model.owned_node_end(), N = long(mesh.X.size());
  std::vector<double> xyz(3 * (n1 - n0));
  std::vector<int> orig(n1 - n0);
  for (long i = n0; i < n1; ++i) {
    const int o = model.old_index(int(i));
    orig[i - n0] = o;
    for (int k = 0; k < 3; ++k) xyz[3 * (i - n0) + k] = mesh.X[o](k);
  }
  write_block_rows(model_.comm(), file_, "/mesh/coordinates", H5T_NATIVE_DOUBLE, N, 3, n0, n1 - n0, xyz.data());
  write_block_rows(model_.comm(), file_, "/mesh/original_node_id", H5T_NATIVE_INT, N, 1, n0, n1 - n0, orig.data());
  cell_vectors_ = cell_vector_names(model);
  // element types present anywhere
  for (ElemType t : {ElemType::Hex8, ElemType::Tet4, ElemType::Tet10}) {
    TypeInfo ti{t, 0, 0, {}};
    const auto& le = model.local_elements();
    for (size_t i = 0; i < le.size(); ++i)
      if (mesh.elements[le[i]].type == t) ti.local.push_back(int(i));
    long nloc = long(ti.local.size());
    MPI_Allreduce(&nloc, &ti.total, 1, MPI_LONG, MPI_SUM, comm);
    MPI_Exscan(&nloc, &ti.offset, 1, MPI_LONG, MPI_SUM, comm);
    if (model.rank() == 0) ti.offset = 0;
    if (ti.total == 0) continue;
    const int nn = num_nodes(t);
    std::vector<int> conn(nn * nloc), block(nloc), oid(nloc);
    static const int vtk_tet10[10] = {0, 1, 2, 3, 4, 5, 6, 7, 9, 8};  // gmsh 8=(3,2),9=(3,1) -> VTK 8=(1,3),9=(2,3)
    for (long i = 0; i < nloc; ++i) {
      const int e = le[ti.local[i]];
      const auto& el = mesh.elements[e];
      for (int a = 0; a < nn; ++a) {
        const int src = t == ElemType::Tet10 ? vtk_tet10[a] : a;
        conn[nn * i + a] = model.new_index(el.n[src]);
      }
      block[i] = el.block;
      oid[i] = e;
    }
    const std::string base = std::string("/mesh/") + name(t);
    write_block_rows(model_.comm(), file_, base + "/connectivity", H5T_NATIVE_INT, ti.total, nn, ti.offset, nloc,
                     conn.data());
    write_block_rows(model_.comm(), file_, base + "/block_id", H5T_NATIVE_INT, ti.total, 1, ti.offset, nloc,
                     block.data());
    write_block_rows(model_.comm(), file_, base + "/original_element_id", H5T_NATIVE_INT, ti.total, 1, ti.offset, nloc,
                     oid.data());
    write_cell_vectors_(ti, base);
    types_.push_back(std::move(ti));
  }
  H5Fflush(file_, H5F_SCOPE_GLOBAL);
}

void FieldWriter::write_cell_vectors_(const TypeInfo& ti, const std::string& base) {
  const long nloc = long(ti.local.size());
  std::vector<std::vector<double>> data(cell_vectors_.size(), std::vector<double>(3 * nloc));
  for (long i = 0; i < nloc; ++i) {
    const auto v = cell_vectors(model_, model_.local_elements()[ti.local[i]], cell_vectors_.size());
    for (size_t f = 0; f < v.size(); ++f)
      for (int k = 0; k < 3; ++k) data[f][3 * i + k] = v[f](k);
  }
  for (size_t f = 0; f < cell_vectors_.size(); ++f)
    write_block_rows(model_.comm(), file_, base + "/" + cell_vectors_[f], H5T_NATIVE_DOUBLE, ti.total, 3, ti.offset,
                     nloc, data[f].data());
}

FieldWriter::~FieldWriter() {
  try {
    close();
  } catch (...) {
  }
}

void FieldWriter::close() {
  if (file_ >= 0) {
    H5Fclose(file_);
    file_ = -1;
  }
}

std::vector<std::string> nodal_stress_field_names(const Mesh& mesh) {
  std::vector<std::string> names;
  for (const auto& b : mesh.blocks) {
    std::string n = "stress_p1_nodal_" + b.name;
    for (auto& c : n)
      if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-')) c = '_';
    names.push_back(n);
  }
  std::vector<std::string> out = names;
  for (size_t b = 0; b < names.size(); ++b)
    if (std::count(names.begin(), names.end(), names[b]) > 1) out[b].append("_").append(std::to_string(b));
  return out;
}

void FieldWriter::write_step(int step, double time, const std::vector<double>& p1, const std::vector<Vec3d>& dir,
                             const std::vector<std::pair<std::string, const std::vector<double>*>>& nodal) {
  const std::string g = "/steps/" + std::to_string(step);
  const long n0 = model_.owned_node_begin(), n1 = model_.owned_node_end(), N = long(model_.mesh().X.size());
  std::vector<double> u(3 * (n1 - n0));
  for (long i = n0; i < n1; ++i) {
    const Vec3d d = model_.displacement(model_.old_index(int(i)));
    for (int k = 0; k < 3; ++k) u[3 * (i - n0) + k] = d(k);
  }
  write_block_rows(model_.comm(), file_, g + "/displacement", H5T_NATIVE_DOUBLE, N, 3, n0, n1 - n0, u.data());
  StepInfo info{step, time, {}};
  for (const auto& [field, values] : nodal) {
    if (long(values->size()) != n1 - n0)
      throw std::invalid_argument("write_step: nodal field " + field + " has " + std::to_string(values->size()) +
                                  " values for " + std::to_string(n1 - n0) + " owned nodes");
    write_block_rows(model_.comm(), file_, g + "/" + field, H5T_NATIVE_DOUBLE, N, 1, n0, n1 - n0, values->data());
    info.nodal.push_back(field);
  }
  for (const auto& ti : types_) {
    const long nloc = long(ti.local.size());
    std::vector<double> s(nloc), d(3 * nloc);
    for (long i = 0; i < nloc; ++i) {
      s[i] = p1[ti.local[i]];
      for (int k = 0; k < 3; ++k) d[3 * i + k] = dir[ti.local[i]](k);
    }
    const std::string base = g + "/" + name(ti.type);
    write_block_rows(model_.comm(), file_, base + "/stress_p1", H5T_NATIVE_DOUBLE, ti.total, 1, ti.offset, nloc,
                     s.data());
    write_block_rows(model_.comm(), file_, base + "/stress_p1_dir", H5T_NATIVE_DOUBLE, ti.total, 3, ti.offset, nloc,
                     d.data());
  }
  {  // pseudo-time as an attribute of the step group (collective, same value on all ranks)
    hid_t grp = H5Gopen2(file_, g.c_str(), H5P_DEFAULT);
    hid_t sp = H5Screate(H5S_SCALAR);
    hid_t at = H5Acreate2(grp, "time", H5T_NATIVE_DOUBLE, sp, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(at, H5T_NATIVE_DOUBLE, &time);
    H5Aclose(at);
    H5Sclose(sp);
    H5Gclose(grp);
  }
  H5Fflush(file_, H5F_SCOPE_GLOBAL);
  steps_.push_back(std::move(info));
  if (model_.rank() == 0) write_xdmf_();
}

void FieldWriter::write_xdmf_() {
  const long N = long(model_.mesh().X.size());
  std::ostringstream x;
  x << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n <Domain>\n"
    << "  <Grid Name=\"solid\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (const auto& [step, time, nodal] : steps_) {
    const std::string g = "solid.h5:/steps/" + std::to_string(step);
    x << "   <Grid Name=\"step_" << step << "\" GridType=\"Collection\" CollectionType=\"Spatial\">\n"
      << "    <Time Value=\"" << time << "\"/>\n";
    for (const auto& ti : types_) {
      const std::string tn = name(ti.type);
      const int nn = num_nodes(ti.type);
      x << "    <Grid Name=\"" << tn << "\" GridType=\"Uniform\">\n"
        << "     <Topology TopologyType=\"" << xdmf_topology(ti.type) << "\" NumberOfElements=\"" << ti.total
        << "\">\n      <DataItem Dimensions=\"" << ti.total << " " << nn
        << "\" NumberType=\"Int\" Format=\"HDF\">solid.h5:/mesh/" << tn << "/connectivity</DataItem>\n"
        << "     </Topology>\n"
        << "     <Geometry GeometryType=\"XYZ\">\n      <DataItem Dimensions=\"" << N
        << " 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">solid.h5:/mesh/coordinates</DataItem>\n"
        << "     </Geometry>\n";
      xdmf_attribute(x, "displacement", "Node", N, 3, g + "/displacement");
      for (const auto& field : nodal) xdmf_attribute(x, field, "Node", N, 1, g + "/" + field);
      const std::string mesh = "solid.h5:/mesh/" + tn + "/";  // static cell data, shared by all steps
      xdmf_attribute(x, "block_id", "Cell", ti.total, 1, mesh + "block_id", "Int");
      for (const auto& v : cell_vectors_) xdmf_attribute(x, v, "Cell", ti.total, 3, mesh + v);
      xdmf_attribute(x, "stress_p1", "Cell", ti.total, 1, g + "/" + tn + "/stress_p1");
      xdmf_attribute(x, "stress_p1_dir", "Cell", ti.total, 3, g + "/" + tn + "/stress_p1_dir");
      x << "    </Grid>\n";
    }
    x << "   </Grid>\n";
  }
  x << "  </Grid>\n </Domain>\n</Xdmf>\n";
  const std::string tmp = dir_ + "/solid.xdmf.tmp";
  {
    std::ofstream f(tmp);
    f << x.str();
  }
  std::filesystem::rename(tmp, dir_ + "/solid.xdmf");
}

}  // namespace angio::solid
