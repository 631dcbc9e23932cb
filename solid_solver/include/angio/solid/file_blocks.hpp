// Rows that every rank holds some of, written to one HDF5 file by all ranks together (MPI-IO),
// without gathering them on one rank: the state file's rows (state_file.hpp) and the field output's
// (output.hpp).
#pragma once
#include <hdf5.h>
#include <mpi.h>

#include <string>
#include <vector>

namespace angio::solid {

// Collective on comm (the file's): write of rows [offset, offset + local_rows) of a [total_rows, cols]
// dataset `path` (intermediate groups created; cols = 1: one-dimensional) in a file opened with the
// MPI-IO driver. type: H5T_NATIVE_DOUBLE with double data, H5T_NATIVE_INT with int data. Throws
// std::runtime_error naming the dataset on every rank when HDF5 fails on any (a rank that went on
// alone would wait in the next collective call for ever).
void write_block_rows(MPI_Comm comm, hid_t file, const std::string& path, hid_t type, long total_rows, int cols,
                      long offset, long local_rows, const void* data);

// A contiguous block of a file's rows, [begin, end), with each row's values.
struct FileBlock {
  long begin = 0, end = 0;
  std::vector<long> start;  // end − begin + 1 offsets into values: row begin + i is values[start[i], start[i+1])
  std::vector<double> values;
  long size() const { return end - begin; }
};

// Collective: records that the ranks hold in no particular order, each with its position in the
// file's order (0 ≤ position < total, every position held by exactly one rank) and a payload of any
// length, moved to the rank whose block [total·r/P, total·(r+1)/P) holds their positions (one
// MPI_Alltoallv: the two-phase I/O of MPI-IO's collective buffering, done here so that the file
// keeps its order and each rank writes one contiguous block). payload_start has position.size() + 1
// offsets into payload. Positions are carried as doubles (exact below 2^53). Throws std::logic_error
// when a position is out of range or the block does not receive each of its positions once.
FileBlock to_file_block(MPI_Comm comm, long total, const std::vector<long>& position,
                        const std::vector<long>& payload_start, const std::vector<double>& payload);

}  // namespace angio::solid
