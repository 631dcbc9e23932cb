#include "angio/solid/element_stress_summary.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <numeric>
#include <stdexcept>
#include <string>
#include <unordered_set>

#include "angio/solid/artery_measures.hpp"
#include "angio/solid/elements.hpp"
#include "angio/solid/gather.hpp"
#include "angio/solid/model.hpp"
#include "angio/solid/stress_average.hpp"

namespace angio::solid {

namespace {

// One block's share of this rank: its elements (value, volume), the ball centres (element centroids
// with key = element, then nodes with key = n_elements + node) and the sample points (Gauss points
// with the element's value and volume share; those of other ranks appended).
struct BlockShare {
  std::vector<double> values, volumes;
  std::vector<Vec3d> centres;
  std::vector<double> keys;
  std::vector<Vec3d> points;
  std::vector<double> point_value, point_weight;
  double best = -std::numeric_limits<double>::infinity();
  double best_key = -1.0;
  Vec3d best_where = Vec3d::Zero();
};

// A cell of the grid of spacing h within one block.
struct Cell {
  std::int64_t b, i, j, k;
  bool operator==(const Cell& o) const { return b == o.b && i == o.i && j == o.j && k == o.k; }
};
struct CellHash {
  std::size_t operator()(const Cell& c) const {
    std::uint64_t h = std::uint64_t(c.b) * 0x9E3779B97F4A7C15ull;
    h ^= std::uint64_t(c.i) + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
    h ^= std::uint64_t(c.j) + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
    h ^= std::uint64_t(c.k) + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
    return std::size_t(h);
  }
};
Cell cell_of(std::int64_t b, const Vec3d& x, double h) {
  return {b, std::int64_t(std::floor(x(0) / h)), std::int64_t(std::floor(x(1) / h)),
          std::int64_t(std::floor(x(2) / h))};
}

// The other ranks' Gauss points near this rank's centres, appended to `share`: every point within h
// of a centre lies in the centre's cell of spacing h or in one of its 26 neighbours (h at least the
// ball's radius, so all points a ball needs arrive, and some more). Collective.
void exchange_points(MPI_Comm comm, std::vector<BlockShare>& share, double h) {
  int size = 1, rank = 0;
  MPI_Comm_size(comm, &size);
  MPI_Comm_rank(comm, &rank);
  if (size == 1) return;
  // this rank's cells next to a centre (its centres' cells dilated by one), as (block, i, j, k), to
  // every rank; a non-finite position lies in no ball
  std::unordered_set<Cell, CellHash> own, near;
  for (std::size_t b = 0; b < share.size(); ++b)
    for (const Vec3d& c : share[b].centres)
      if (c.allFinite()) own.insert(cell_of(std::int64_t(b), c, h));
  for (const Cell& m : own)
    for (int di = -1; di <= 1; ++di)
      for (int dj = -1; dj <= 1; ++dj)
        for (int dk = -1; dk <= 1; ++dk) near.insert({m.b, m.i + di, m.j + dj, m.k + dk});
  std::vector<std::int64_t> mine;
  mine.reserve(4 * near.size());
  for (const Cell& c : near) mine.insert(mine.end(), {c.b, c.i, c.j, c.k});
  const int count = int(mine.size());
  std::vector<int> counts(size), displs(size, 0);
  MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  for (int r = 1; r < size; ++r) displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<std::int64_t> all(std::size_t(displs.back() + counts.back()));
  MPI_Allgatherv(mine.data(), count, MPI_INT64_T, all.data(), counts.data(), displs.data(), MPI_INT64_T, comm);
  // this rank's points in another rank's cells, as (block, x, y, z, value, weight)
  std::vector<std::vector<double>> out(static_cast<std::size_t>(size));
  for (int r = 0; r < size; ++r) {
    if (r == rank) continue;
    std::unordered_set<Cell, CellHash> theirs;
    for (int k = displs[r]; k + 3 < displs[r] + counts[r]; k += 4)
      theirs.insert({all[k], all[k + 1], all[k + 2], all[k + 3]});
    if (theirs.empty()) continue;
    for (std::size_t b = 0; b < share.size(); ++b) {
      const BlockShare& s = share[b];
      for (std::size_t q = 0; q < s.points.size(); ++q)
        if (s.points[q].allFinite() && theirs.count(cell_of(std::int64_t(b), s.points[q], h)))
          out[std::size_t(r)].insert(out[std::size_t(r)].end(), {double(b), s.points[q](0), s.points[q](1),
                                                                 s.points[q](2), s.point_value[q], s.point_weight[q]});
    }
  }
  std::vector<int> send_counts(size), recv_counts(size), send_displs(size, 0), recv_displs(size, 0);
  for (int r = 0; r < size; ++r) send_counts[r] = int(out[std::size_t(r)].size());
  MPI_Alltoall(send_counts.data(), 1, MPI_INT, recv_counts.data(), 1, MPI_INT, comm);
  for (int r = 1; r < size; ++r) {
    send_displs[r] = send_displs[r - 1] + send_counts[r - 1];
    recv_displs[r] = recv_displs[r - 1] + recv_counts[r - 1];
  }
  std::vector<double> send(std::size_t(send_displs.back() + send_counts.back()));
  for (int r = 0; r < size; ++r) std::copy(out[r].begin(), out[r].end(), send.begin() + send_displs[r]);
  out.clear();
  std::vector<double> recv(std::size_t(recv_displs.back() + recv_counts.back()));
  MPI_Alltoallv(send.data(), send_counts.data(), send_displs.data(), MPI_DOUBLE, recv.data(), recv_counts.data(),
                recv_displs.data(), MPI_DOUBLE, comm);
  for (std::size_t k = 0; k + 5 < recv.size(); k += 6) {
    BlockShare& s = share[std::size_t(recv[k])];
    s.points.emplace_back(recv[k + 1], recv[k + 2], recv[k + 3]);
    s.point_value.push_back(recv[k + 4]);
    s.point_weight.push_back(recv[k + 5]);
  }
}

// Per block on rank 0: the largest of every rank's (value, key, x, y, z) candidates; ties to the
// lowest key. NaN values are no candidates. Collective.
std::vector<double> best_on_root(MPI_Comm comm, const std::vector<double>& candidates, std::size_t nb) {
  const std::vector<double> all = gather_on_root(comm, candidates);
  std::vector<double> best(5 * nb, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t k = 0; k + 4 < all.size(); k += 5) {
    const std::size_t b = (k / 5) % nb;
    const double v = all[k], key = all[k + 1];
    if (std::isnan(v)) continue;
    if (std::isnan(best[5 * b]) || v > best[5 * b] || (v == best[5 * b] && key < best[5 * b + 1]))
      std::copy(all.begin() + std::ptrdiff_t(k), all.begin() + std::ptrdiff_t(k + 5),
                best.begin() + std::ptrdiff_t(5 * b));
  }
  return best;
}

}  // namespace

std::vector<ElementStressSummary> element_stress_summary(MPI_Comm comm, const SolidModel& model,
                                                         const std::vector<double>& p1, const std::vector<double>& vol,
                                                         double radius) {
  // the same on every rank (the scene's key): refused before any collective call
  if (!(std::isfinite(radius) && radius > 0.0))
    throw std::invalid_argument("element stress summary: ball radius must be positive and finite, got " +
                                std::to_string(radius));
  const auto& le = model.local_elements();
  if (p1.size() != le.size() || vol.size() != le.size())
    throw std::invalid_argument("element stress summary: one p1 and one volume per local element expected");
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const Mesh& mesh = model.mesh();
  const std::size_t nb = mesh.blocks.size();
  std::vector<BlockShare> share(nb);
  // shape functions at the Gauss points and their volume shares w_q / Σw, once per element type
  std::map<ElemType, std::pair<std::vector<Eigen::VectorXd>, std::vector<double>>> at_gauss;
  auto gauss_of = [&](ElemType t) -> const auto& {
    auto [it, fresh] = at_gauss.try_emplace(t);
    if (fresh) {
      const auto& rule = volume_rule(t);
      double wsum = 0.0;
      for (const auto& q : rule) wsum += q.w;
      Eigen::MatrixXd dN;
      for (const auto& q : rule) {
        it->second.first.emplace_back();
        shape(t, q.xi, it->second.first.back(), dN);
        it->second.second.push_back(q.w / wsum);
      }
    }
    return it->second;
  };
  // elements by index (local_elements() is ascending today; sorted here so that the tie rule, the
  // first of equal centres is the one of the lowest key, does not depend on it)
  std::vector<std::size_t> order(le.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return le[a] < le[b]; });
  std::vector<std::vector<int>> nodes(nb);
  for (std::size_t i : order) {
    const int e = le[i];
    const auto& el = mesh.elements[std::size_t(e)];
    BlockShare& s = share[std::size_t(el.block)];
    s.values.push_back(p1[i]);
    s.volumes.push_back(vol[i]);
    Vec3d c = Vec3d::Zero();
    for (int a = 0; a < el.nn(); ++a) {
      c += model.position(el.n[a]);
      nodes[std::size_t(el.block)].push_back(el.n[a]);
    }
    c /= double(el.nn());
    s.centres.push_back(c);
    s.keys.push_back(double(e));
    if (p1[i] > s.best) {
      s.best = p1[i];
      s.best_key = double(e);
      s.best_where = c;
    }
    const auto& [N, weight_share] = gauss_of(el.type);
    for (std::size_t q = 0; q < N.size(); ++q) {
      Vec3d x = Vec3d::Zero();
      for (int a = 0; a < el.nn(); ++a) x += N[q](a) * model.position(el.n[a]);
      s.points.push_back(x);
      s.point_value.push_back(p1[i]);
      s.point_weight.push_back(vol[i] * weight_share[q]);
    }
  }
  // nodes of the block's elements as centres too (a ball also sits on the lumen); a node on several
  // ranks is a centre on each, with the same ball
  const double ne = double(mesh.elements.size());
  for (std::size_t b = 0; b < nb; ++b) {
    std::sort(nodes[b].begin(), nodes[b].end());
    nodes[b].erase(std::unique(nodes[b].begin(), nodes[b].end()), nodes[b].end());
    for (int n : nodes[b]) {
      share[b].centres.push_back(model.position(n));
      share[b].keys.push_back(ne + double(n));
    }
  }
  // cells at least the ball's radius (a hair more, so that rounding in x / h cannot put a point
  // within the radius two cells away) and at least the mean element's size (a radius far below the
  // elements would otherwise make every rank send cells by the million)
  double volume_count[2] = {0.0, double(le.size())};
  for (double v : vol) volume_count[0] += v;
  MPI_Allreduce(MPI_IN_PLACE, volume_count, 2, MPI_DOUBLE, MPI_SUM, comm);
  const double element_size = volume_count[1] > 0.0 ? std::cbrt(volume_count[0] / volume_count[1]) : 0.0;
  exchange_points(comm, share, std::max(radius * (1.0 + 1e-6), element_size));

  std::vector<double> element_max, averaged_max, percentile;
  for (std::size_t b = 0; b < nb; ++b) {
    const BlockShare& s = share[b];
    const Vec3d& w = s.best_where;
    element_max.insert(element_max.end(), {s.values.empty() ? std::numeric_limits<double>::quiet_NaN() : s.best,
                                           s.best_key, w(0), w(1), w(2)});
    const BallMaximum m = max_ball_average(s.centres, s.points, s.point_value, s.point_weight, radius);
    if (m.centre == BallMaximum::none) {
      averaged_max.insert(averaged_max.end(), 5, std::numeric_limits<double>::quiet_NaN());
    } else {
      const Vec3d& c = s.centres[m.centre];
      averaged_max.insert(averaged_max.end(), {m.value, s.keys[m.centre], c(0), c(1), c(2)});
    }
    for (std::size_t k = 0; k < s.values.size(); ++k)
      percentile.insert(percentile.end(), {double(b), s.values[k], s.volumes[k]});
  }
  share.clear();
  const std::vector<double> best = best_on_root(comm, element_max, nb);
  const std::vector<double> best_averaged = best_on_root(comm, averaged_max, nb);
  const std::vector<double> all = gather_on_root(comm, percentile);
  std::vector<ElementStressSummary> out(nb);
  if (rank != 0) return out;
  std::vector<std::vector<double>> values(nb), volumes(nb);
  for (std::size_t k = 0; k + 2 < all.size(); k += 3) {
    values[std::size_t(all[k])].push_back(all[k + 1]);
    volumes[std::size_t(all[k])].push_back(all[k + 2]);
  }
  for (std::size_t b = 0; b < nb; ++b) {
    ElementStressSummary& o = out[b];
    o.p99 = weighted_quantile(values[b], volumes[b], 0.99);
    if (!std::isnan(best[5 * b])) {
      o.max = best[5 * b];
      o.where = Vec3d(best[5 * b + 2], best[5 * b + 3], best[5 * b + 4]);
    }
    if (!std::isnan(best_averaged[5 * b])) {
      o.max_averaged = best_averaged[5 * b];
      o.where_averaged = Vec3d(best_averaged[5 * b + 2], best_averaged[5 * b + 3], best_averaged[5 * b + 4]);
    }
  }
  return out;
}

}  // namespace angio::solid
