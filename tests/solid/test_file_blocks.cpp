// Rows written in a file's order by all ranks (file_blocks.hpp): each rank's records, held in no
// particular order, arrive at the rank whose block of positions holds them, in position order with
// their payloads (exact: a permutation of data, nothing computed); a position held twice or by no
// rank is refused on the rank whose block it is, never written as garbage.
#include <gtest/gtest.h>
#include <mpi.h>
#include <petscsys.h>

#include <stdexcept>
#include <vector>

#include "angio/solid/file_blocks.hpp"
#include "mpi_test.hpp"

using angio::solid::FileBlock;
using angio::solid::to_file_block;
using angio_test::world_rank;
using angio_test::world_size;

namespace {
// Position p's payload: p mod 4 values (none for some) that name p and their place.
std::vector<double> payload_of(long p) {
  std::vector<double> v;
  for (long k = 0; k < p % 4; ++k) v.push_back(double(p) + 0.01 * double(k));
  return v;
}

// Rank r holds the positions p with (7 p + 3) mod size == r (spread over the blocks), in descending order.
void records(long total, std::vector<long>& position, std::vector<long>& start, std::vector<double>& payload) {
  position.clear();
  start.assign(1, 0);
  payload.clear();
  for (long p = total - 1; p >= 0; --p)
    if ((7 * p + 3) % world_size() == world_rank()) {
      position.push_back(p);
      const auto v = payload_of(p);
      payload.insert(payload.end(), v.begin(), v.end());
      start.push_back(long(payload.size()));
    }
}
}  // namespace

TEST(FileBlocks, RecordsArriveAtTheirBlockInPositionOrder) {
  for (const long total : {0L, 1L, 5L, 37L}) {  // fewer positions than ranks too: empty blocks
    std::vector<long> position, start;
    std::vector<double> payload;
    records(total, position, start, payload);
    const FileBlock b = to_file_block(PETSC_COMM_WORLD, total, position, start, payload);
    // the blocks tile [0, total) in rank order
    EXPECT_EQ(b.begin, long((long double)total * world_rank() / world_size())) << total;
    EXPECT_EQ(b.end, long((long double)total * (world_rank() + 1) / world_size())) << total;
    ASSERT_EQ(b.start.size(), std::size_t(b.size() + 1)) << total;
    for (long i = 0; i < b.size(); ++i) {
      const std::vector<double> got(b.values.begin() + b.start[i], b.values.begin() + b.start[i + 1]);
      EXPECT_EQ(got, payload_of(b.begin + i)) << "position " << b.begin + i << " of " << total;
    }
    long rows = b.size(), all = 0;
    MPI_Allreduce(&rows, &all, 1, MPI_LONG, MPI_SUM, PETSC_COMM_WORLD);
    EXPECT_EQ(all, total);
  }
}

TEST(FileBlocks, APositionTwiceOrNowhereIsRefused) {
  const long total = 6;
  std::vector<long> position, start{0};
  std::vector<double> payload;
  // rank 0 holds every position but the last, and position 0 twice
  if (world_rank() == 0)
    for (const long p : {0L, 0L, 1L, 2L, 3L, 4L}) {
      position.push_back(p);
      start.push_back(0);
    }
  // every rank's block is checked on that rank: the first block holds 0 twice, the last misses 5
  const long begin = long((long double)total * world_rank() / world_size());
  const long end = long((long double)total * (world_rank() + 1) / world_size());
  const bool refused_here = begin == 0 || end == total;
  bool refused = false;
  try {
    to_file_block(PETSC_COMM_WORLD, total, position, start, payload);
  } catch (const std::logic_error&) {
    refused = true;
  }
  EXPECT_EQ(refused, refused_here);
  // a position outside [0, total) is refused on the rank that holds it, before any message
  if (world_rank() == 0) {
    EXPECT_THROW(to_file_block(MPI_COMM_SELF, 3, {3}, {0, 0}, {}), std::logic_error);
    EXPECT_THROW(to_file_block(MPI_COMM_SELF, 3, {0}, {0}, {}), std::logic_error);  // offsets: one per record + 1
  }
}
