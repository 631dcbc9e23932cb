// Small HDF5 tables and attributes for the solvers' state files, with errors that name the file and
// the object (header-only: the beam links serial HDF5, the solid the MPI build of the same API).
#pragma once
#include <hdf5.h>

#include <Eigen/Core>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace angio::h5 {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// An HDF5 identifier closed with its close function at the end of the scope.
struct H5Id {
  hid_t id = -1;
  herr_t (*close)(hid_t) = nullptr;
  H5Id(hid_t i, herr_t (*c)(hid_t)) : id(i), close(c) {}
  ~H5Id() {
    if (id >= 0 && close) close(id);
  }
  H5Id(const H5Id&) = delete;
  H5Id& operator=(const H5Id&) = delete;
  operator hid_t() const { return id; }
};

// HDF5's own error stack printing off for a scope (our messages say what failed instead).
struct QuietErrors {
  H5E_auto2_t func = nullptr;
  void* data = nullptr;
  QuietErrors() {
    H5Eget_auto2(H5E_DEFAULT, &func, &data);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~QuietErrors() { H5Eset_auto2(H5E_DEFAULT, func, data); }
};

// A [rows, cols] dataset (cols = 1: one-dimensional).
inline void write_dataset(hid_t loc, const std::string& name, hid_t type, hsize_t rows, hsize_t cols,
                          const void* data) {
  hsize_t dims[2] = {rows, cols};
  H5Id space(H5Screate_simple(cols > 1 ? 2 : 1, dims, nullptr), H5Sclose);
  H5Id ds(H5Dcreate2(loc, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Dclose);
  if (ds.id < 0 || (rows > 0 && H5Dwrite(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0))
    throw Error("cannot write dataset " + name);
}
inline void write_attribute(hid_t loc, const char* name, hid_t type, const void* value) {
  H5Id space(H5Screate(H5S_SCALAR), H5Sclose);
  H5Id a(H5Acreate2(loc, name, type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (a.id < 0 || H5Awrite(a, type, value) < 0) throw Error(std::string("cannot write attribute ") + name);
}
// Rows of fixed-size vectors as one [n, N] table of doubles.
template <int N>
void write_rows(hid_t loc, const std::string& name, const std::vector<Eigen::Matrix<double, N, 1>>& v) {
  std::vector<double> f(N * v.size());
  for (size_t i = 0; i < v.size(); ++i)
    for (int k = 0; k < N; ++k) f[N * i + k] = v[i](k);
  write_dataset(loc, name, H5T_NATIVE_DOUBLE, v.size(), N, f.data());
}

// Reading: every failure names the file and the object.
struct Reader {
  std::string path;
  [[noreturn]] void fail(const std::string& what) const { throw Error(path + ": " + what); }
  bool exists(hid_t loc, const std::string& name) const { return H5Lexists(loc, name.c_str(), H5P_DEFAULT) > 0; }
  template <class T>
  T attribute(hid_t loc, const char* name, hid_t type) const {
    if (H5Aexists(loc, name) <= 0) fail(std::string("missing attribute '") + name + "' (not a state file?)");
    H5Id a(H5Aopen(loc, name, H5P_DEFAULT), H5Aclose);
    T v{};
    if (a.id < 0 || H5Aread(a, type, &v) < 0) fail(std::string("cannot read attribute ") + name);
    return v;
  }
  // The rows of a [rows, cols] dataset (cols = 1: one-dimensional); fails on another shape.
  hsize_t table_rows(hid_t loc, const std::string& name, int cols) const {
    if (!exists(loc, name)) fail("missing dataset " + name);
    H5Id ds(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), H5Dclose);
    H5Id space(H5Dget_space(ds), H5Sclose);
    hsize_t dims[2] = {0, 1};
    const int nd = H5Sget_simple_extent_ndims(space);
    if (nd < 1 || nd > 2) fail("dataset " + name + " is not a table");
    H5Sget_simple_extent_dims(space, dims, nullptr);
    if (hsize_t(cols) != (nd == 2 ? dims[1] : 1))
      fail("dataset " + name + ": expected " + std::to_string(cols) + " columns");
    return dims[0];
  }
  // Rows [start, start + count) of a [rows, cols] dataset of `type` (table_rows() checked first).
  template <class T>
  std::vector<T> block(hid_t loc, const std::string& name, hid_t type, int cols, hsize_t start, hsize_t count) const {
    std::vector<T> v(count * cols);
    if (count == 0) return v;
    H5Id ds(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), H5Dclose);
    H5Id space(H5Dget_space(ds), H5Sclose);
    const int nd = H5Sget_simple_extent_ndims(space);
    const hsize_t first[2] = {start, 0}, size[2] = {count, hsize_t(cols)};
    H5Sselect_hyperslab(space, H5S_SELECT_SET, first, nullptr, size, nullptr);
    H5Id mem(H5Screate_simple(nd, size, nullptr), H5Sclose);
    if (H5Dread(ds, type, mem, space, H5P_DEFAULT, v.data()) < 0) fail("cannot read " + name);
    return v;
  }
  // A [rows, cols] dataset (cols = 1: one-dimensional) of `type`.
  template <class T>
  std::vector<T> dataset(hid_t loc, const std::string& name, hid_t type, int cols, hsize_t& rows) const {
    rows = table_rows(loc, name, cols);
    return block<T>(loc, name, type, cols, 0, rows);
  }
  // A [n, N] table of doubles as n vectors; every entry finite.
  template <int N>
  std::vector<Eigen::Matrix<double, N, 1>> rows(hid_t loc, const std::string& name) const {
    hsize_t n = 0;
    const auto f = dataset<double>(loc, name, H5T_NATIVE_DOUBLE, N, n);
    std::vector<Eigen::Matrix<double, N, 1>> v(n);
    for (hsize_t i = 0; i < n; ++i) {
      for (int k = 0; k < N; ++k) v[i](k) = f[N * i + k];
      if (!v[i].allFinite()) fail("dataset " + name + ": row " + std::to_string(i) + " is not finite");
    }
    return v;
  }
};

// Opens an existing file read-only (throws naming it when it is missing or not HDF5).
inline hid_t open_for_reading(const Reader& r) {
  if (!std::filesystem::is_regular_file(r.path)) r.fail("no such file");
  if (H5Fis_hdf5(r.path.c_str()) <= 0) r.fail("not an HDF5 file");
  const hid_t f = H5Fopen(r.path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) r.fail("cannot open");
  return f;
}

}  // namespace angio::h5
