#include "angio/solid/file_blocks.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace angio::solid {

void write_block_rows(MPI_Comm comm, hid_t file, const std::string& path, hid_t type, long total_rows, int cols,
                      long offset, long local_rows, const void* data) {
  const hsize_t dims[2] = {hsize_t(total_rows), hsize_t(cols)};
  const int rank = cols > 1 ? 2 : 1;
  const char* failed = nullptr;
  const hid_t space = H5Screate_simple(rank, dims, nullptr);
  const hid_t lcpl = H5Pcreate(H5P_LINK_CREATE);
  H5Pset_create_intermediate_group(lcpl, 1);
  const hid_t ds = space < 0 ? -1 : H5Dcreate2(file, path.c_str(), type, space, lcpl, H5P_DEFAULT, H5P_DEFAULT);
  H5Pclose(lcpl);
  if (ds < 0) failed = "cannot create";
  // an empty dataset has no storage for MPI-IO to write to: nothing to write
  if (!failed && total_rows > 0) {
    const hsize_t start[2] = {hsize_t(offset), 0}, count[2] = {hsize_t(local_rows), hsize_t(cols)};
    if (local_rows > 0)
      H5Sselect_hyperslab(space, H5S_SELECT_SET, start, nullptr, count, nullptr);
    else
      H5Sselect_none(space);
    const hid_t mem = H5Screate_simple(rank, count, nullptr);
    if (local_rows == 0) H5Sselect_none(mem);
    const hid_t xfer = H5Pcreate(H5P_DATASET_XFER);
    H5Pset_dxpl_mpio(xfer, H5FD_MPIO_COLLECTIVE);
    if (H5Dwrite(ds, type, mem, space, xfer, data) < 0) failed = "cannot write";
    H5Pclose(xfer);
    H5Sclose(mem);
  }
  if (ds >= 0) H5Dclose(ds);
  if (space >= 0) H5Sclose(space);
  int ok = failed == nullptr, all = 0;
  MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, comm);
  if (!all)
    throw std::runtime_error("HDF5 error: " + std::string(failed ? failed : "another rank could not write") + " " +
                             path);
}

FileBlock to_file_block(MPI_Comm comm, long total, const std::vector<long>& position,
                        const std::vector<long>& payload_start, const std::vector<double>& payload) {
  int size = 1, rank = 0;
  MPI_Comm_size(comm, &size);
  MPI_Comm_rank(comm, &rank);
  if (payload_start.size() != position.size() + 1) throw std::logic_error("to_file_block: payload offsets");
  std::vector<long> bound(size + 1);  // rank r's block: [bound[r], bound[r + 1])
  for (int r = 0; r <= size; ++r) bound[r] = long((long double)total * r / size);
  // records as [position, length, payload...], grouped by the rank whose block holds them
  std::vector<int> dest(position.size());
  long values = 0;
  std::vector<int> send_count(size, 0);
  for (std::size_t i = 0; i < position.size(); ++i) {
    const long p = position[i];
    if (p < 0 || p >= total) throw std::logic_error("to_file_block: position out of range");
    dest[i] = int(std::upper_bound(bound.begin(), bound.end(), p) - bound.begin()) - 1;
    const long n = 2 + payload_start[i + 1] - payload_start[i];
    values += n;
    if (values > long(std::numeric_limits<int>::max()))  // MPI's counts and offsets are ints
      throw std::runtime_error("to_file_block: more than 2^31 values from one rank");
    send_count[dest[i]] += int(n);
  }
  std::vector<int> send_at(size + 1, 0);
  for (int r = 0; r < size; ++r) send_at[r + 1] = send_at[r] + send_count[r];
  std::vector<double> send(std::size_t(send_at[size]));
  std::vector<int> next(send_at.begin(), send_at.end() - 1);
  for (std::size_t i = 0; i < position.size(); ++i) {
    double* d = send.data() + next[dest[i]];
    const long n = payload_start[i + 1] - payload_start[i];
    d[0] = double(position[i]);
    d[1] = double(n);
    std::copy(payload.begin() + payload_start[i], payload.begin() + payload_start[i + 1], d + 2);
    next[dest[i]] += int(2 + n);
  }
  std::vector<int> recv_count(size), recv_at(size + 1, 0);
  MPI_Alltoall(send_count.data(), 1, MPI_INT, recv_count.data(), 1, MPI_INT, comm);
  for (int r = 0; r < size; ++r) recv_at[r + 1] = recv_at[r] + recv_count[r];
  std::vector<double> recv(std::size_t(recv_at[size]));
  MPI_Alltoallv(send.data(), send_count.data(), send_at.data(), MPI_DOUBLE, recv.data(), recv_count.data(),
                recv_at.data(), MPI_DOUBLE, comm);
  send = {};
  // place the block's records in position order
  FileBlock b;
  b.begin = bound[rank];
  b.end = bound[rank + 1];
  std::vector<long> at(std::size_t(b.size()), -1), length(std::size_t(b.size()), 0);
  for (std::size_t k = 0; k < recv.size(); k += 2 + std::size_t(recv[k + 1])) {
    const long i = long(recv[k]) - b.begin;
    if (i < 0 || i >= b.size() || at[i] >= 0) throw std::logic_error("to_file_block: a position twice or misrouted");
    at[i] = long(k);
    length[i] = long(recv[k + 1]);
  }
  b.start.assign(std::size_t(b.size()) + 1, 0);
  for (long i = 0; i < b.size(); ++i) {
    if (at[i] < 0) throw std::logic_error("to_file_block: no rank holds position " + std::to_string(b.begin + i));
    b.start[i + 1] = b.start[i] + length[i];
  }
  b.values.resize(std::size_t(b.start.back()));
  for (long i = 0; i < b.size(); ++i) std::copy_n(recv.begin() + at[i] + 2, length[i], b.values.begin() + b.start[i]);
  return b;
}

}  // namespace angio::solid
