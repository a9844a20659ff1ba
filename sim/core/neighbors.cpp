#include "core/neighbors.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/parallel.hpp"

namespace aortasph {

namespace {

constexpr int kReach = 2;  // cells scanned on each side

// Spread the lower 10 bits of v to every third bit (for a 30-bit Morton code).
uint64_t spread_bits(uint64_t v) {
  v &= 0x3ff;
  v = (v | (v << 16)) & 0x30000ff;
  v = (v | (v << 8)) & 0x300f00f;
  v = (v | (v << 4)) & 0x30c30c3;
  v = (v | (v << 2)) & 0x9249249;
  return v;
}

struct BoundsAcc {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::max());
  Vec3 hi = Vec3::Constant(std::numeric_limits<double>::lowest());
};

}  // namespace

void NeighborSearch::make_grid(const std::vector<Vec3>& x, double radius) {
  const std::size_t n = x.size();
  cell_of_.resize(n);

  // Grid over the particles' bounding box. The cell count is capped at a few per particle so that a
  // sparse scene (two bodies far apart) cannot exhaust memory; bigger cells stay correct, only slower.
  const BoundsAcc box = parallel_reduce(
      n, BoundsAcc{},
      [&](std::size_t i) {
        return BoundsAcc{x[i], x[i]};
      },
      [](const BoundsAcc& a, const BoundsAcc& b) {
        return BoundsAcc{a.lo.cwiseMin(b.lo), a.hi.cwiseMax(b.hi)};
      });
  // Cells of half the search radius, scanned two cells out: the 5^3 cells of edge r/2 cover 42 % less volume
  // than 3^3 cells of edge r, so fewer candidates are tested (measured: a third less build time).
  cell_ = 0.5 * radius;
  const double max_cells = 8.0 * static_cast<double>(n) + 1024.0;
  for (;;) {
    double total = 1.0;
    for (int d = 0; d < 3; ++d) {
      dims_[d] = static_cast<int>(std::floor((box.hi[d] - box.lo[d]) / cell_)) + 1;
      total *= dims_[d];
    }
    if (total <= max_cells) break;
    cell_ *= 1.5;
  }
  origin_ = box.lo;
  // Periodic axes: the grid spans the period in whole cells of at least radius / 2, so that the cells wrap
  // round exactly; the stencil of 5 cells must not meet itself (a pair would be listed twice).
  for (int d = 0; d < 3; ++d) {
    if (!periodic_.on[d]) continue;
    dims_[d] = static_cast<int>(std::floor(periodic_.len[d] / (0.5 * radius)));
    if (dims_[d] < 2 * kReach + 1)
      throw std::invalid_argument("periodic length shorter than 2.5 search radii");
    origin_[d] = periodic_.lo[d];
  }
  for (int d = 0; d < 3; ++d) cell_size_[d] = periodic_.on[d] ? periodic_.len[d] / dims_[d] : cell_;

  auto cell_coord = [&](const Vec3& p, int d) {
    const int c = static_cast<int>(std::floor((p[d] - origin_[d]) / cell_size_[d]));
    return std::clamp(c, 0, dims_[d] - 1);
  };
  parallel_for(n, [&](std::size_t i) {
    const int cx = cell_coord(x[i], 0), cy = cell_coord(x[i], 1), cz = cell_coord(x[i], 2);
    cell_of_[i] = static_cast<uint32_t>((static_cast<std::size_t>(cz) * dims_[1] + cy) * dims_[0] + cx);
  });
}

void NeighborSearch::bin(const std::vector<Vec3>& x, double radius) {
  offset_.clear();
  index_.clear();
  row_end_.clear();
  if (x.empty()) {
    cell_of_.clear();
    return;
  }
  make_grid(x, radius);
}

void NeighborSearch::release() {
  NeighborSearch empty;
  empty.periodic_ = periodic_;
  *this = std::move(empty);
}

void NeighborSearch::build(const std::vector<Vec3>& x, double radius, const std::vector<uint8_t>& fixed) {
  const std::size_t n = x.size();
  offset_.assign(n + 1, 0);
  index_.clear();
  cell_of_.resize(n);
  if (n == 0) {
    row_end_.clear();
    return;
  }
  make_grid(x, radius);
  const std::size_t ncell = static_cast<std::size_t>(dims_[0]) * dims_[1] * dims_[2];

  // Counting sort of particles into cells: stable, so each cell lists its particles by index.
  cell_start_.assign(ncell + 1, 0);
  for (std::size_t i = 0; i < n; ++i) ++cell_start_[cell_of_[i] + 1];
  for (std::size_t c = 0; c < ncell; ++c) cell_start_[c + 1] += cell_start_[c];
  cell_items_.resize(n);
  {
    std::vector<uint32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
    for (std::size_t i = 0; i < n; ++i) cell_items_[fill[cell_of_[i]]++] = static_cast<uint32_t>(i);
  }
  // Positions and fixed flags copied in cell order: the candidate scan below then streams through memory
  // instead of jumping through the particle arrays.
  std::vector<Vec3> xs(n);
  std::vector<uint8_t> fixed_s(fixed.empty() ? 0 : n);
  parallel_for(n, [&](std::size_t k) {
    xs[k] = x[cell_items_[k]];
    if (!fixed.empty()) fixed_s[k] = fixed[cell_items_[k]];
  });

  // Cells that hold a particle that is not fixed: a fixed particle needs neighbours only near one.
  const bool any_fixed = !fixed.empty();
  std::vector<uint8_t> cell_moving;
  if (any_fixed) {
    cell_moving.assign(ncell, 0);
    for (std::size_t i = 0; i < n; ++i)
      if (!fixed[i]) cell_moving[cell_of_[i]] = 1;
  }

  const double r2 = radius * radius;
  const Periodic& per = periodic_;
  // The cell rows of the stencil along one axis: [c - kReach, c + kReach], clamped to the grid, or wrapped
  // round on a periodic axis (there it may fall into two runs, visited in order of the unwrapped offset).
  struct Runs {
    int n = 0;
    int lo[2] = {0, 0}, hi[2] = {0, 0};
  };
  auto runs = [&](int c, int d) {
    Runs r;
    if (!per.on[d]) {
      r.n = 1;
      r.lo[0] = std::max(c - kReach, 0);
      r.hi[0] = std::min(c + kReach, dims_[d] - 1);
      return r;
    }
    const int a = c - kReach, b = c + kReach, m = dims_[d];
    if (a < 0) {
      r = {2, {a + m, 0}, {m - 1, b}};
    } else if (b >= m) {
      r = {2, {a, 0}, {m - 1, b - m}};
    } else {
      r = {1, {a, 0}, {b, 0}};
    }
    return r;
  };
  // The stencil of cell c: run(first, last) for each run of cells first .. last of one row (contiguous in
  // cell_items_), rows in z, then y, order; the one order every sum over neighbours follows.
  auto for_each_run = [&](uint32_t c, auto&& run) {
    const int cx = static_cast<int>(c % dims_[0]);
    const int cy = static_cast<int>((c / dims_[0]) % dims_[1]);
    const int cz = static_cast<int>(c / (static_cast<std::size_t>(dims_[0]) * dims_[1]));
    const Runs rx = runs(cx, 0), ry = runs(cy, 1), rz = runs(cz, 2);
    for (int iz = 0; iz < rz.n; ++iz)
      for (int z = rz.lo[iz]; z <= rz.hi[iz]; ++z)
        for (int iy = 0; iy < ry.n; ++iy)
          for (int y = ry.lo[iy]; y <= ry.hi[iy]; ++y) {
            const std::size_t row = (static_cast<std::size_t>(z) * dims_[1] + y) * dims_[0];
            for (int ix = 0; ix < rx.n; ++ix) run(row + rx.lo[ix], row + rx.hi[ix]);
          }
  };
  // Visit the candidates of i in a fixed order; call found(j) for each neighbour.
  auto visit = [&](std::size_t i, auto&& found) {
    const bool fixed_i = any_fixed && fixed[i];
    const Vec3 xi = x[i];
    for_each_run(cell_of_[i], [&](std::size_t first, std::size_t last) {
      if (fixed_i && std::none_of(&cell_moving[first], &cell_moving[last] + 1, [](uint8_t m) { return m; }))
        return;
      for (uint32_t k = cell_start_[first]; k < cell_start_[last + 1]; ++k) {
        if (fixed_i && fixed_s[k]) continue;
        const Vec3 d = per.any ? per.image(xs[k] - xi) : Vec3(xs[k] - xi);
        if (d.squaredNorm() >= r2) continue;
        const uint32_t j = cell_items_[k];
        if (j != i) found(j);
      }
    });
  };

  // Contiguous chunks of particles, each listed into its own buffer and appended to index_ in chunk order, so
  // the lists are the same whatever the chunks and waves (rows in particle order). The chunks are taken in
  // waves of 8 per thread so that only one wave's buffers exist beside index_ (the lists are never held
  // twice); a wave's chunks are balanced dynamically over the threads. Chunks of 256 particles in waves of 8
  // per thread hold at most a quarter of what chunks of 512 in waves of 32 did on 2 threads (a fluid
  // particle lists about 100 pairs: 3 MiB against up to 13 MiB with the buffers' growth,
  // docs/performance.md).
  const std::size_t chunks = std::clamp<std::size_t>(n / 256, 1, 4096);
  const std::size_t wave =
      std::min<std::size_t>(chunks, 8 * static_cast<std::size_t>(std::max(max_threads(), 1)));
  // index_ keeps its capacity between builds. Before the first one it is sized from the candidates the
  // stencils hold: a ball of the radius fills 4/3 pi / 2.5^3 = 26.8 % of the 5^3 cells of edge radius / 2
  // around it, so 28 % of the candidates (a fixed particle's: the moving ones only) is a slight overestimate
  // for evenly spread particles. Growing index_ by doubling instead would hold the lists twice while it
  // copies them; pages reserved but never written cost no memory.
  if (index_.capacity() == 0) {
    std::vector<uint32_t> moving_in_cell;
    if (any_fixed) {
      moving_in_cell.assign(ncell, 0);
      for (std::size_t i = 0; i < n; ++i)
        if (!fixed[i]) ++moving_in_cell[cell_of_[i]];
    }
    std::size_t candidates = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const bool fixed_i = any_fixed && fixed[i];
      for_each_run(cell_of_[i], [&](std::size_t first, std::size_t last) {
        if (!fixed_i) {
          candidates += cell_start_[last + 1] - cell_start_[first];
        } else {
          for (std::size_t cell = first; cell <= last; ++cell) candidates += moving_in_cell[cell];
        }
      });
    }
    index_.reserve(static_cast<std::size_t>(0.28 * static_cast<double>(candidates)) + n);
  }
  std::vector<std::vector<uint32_t>> local(wave);
  for (std::size_t c0 = 0; c0 < chunks; c0 += wave) {
    const std::size_t cw = std::min(wave, chunks - c0);
    parallel_for_dynamic_chunks(cw, [&](std::size_t w) {
      const std::size_t c = c0 + w;
      const std::size_t b = n * c / chunks, e = n * (c + 1) / chunks;
      auto& out = local[w];
      out.clear();
      for (std::size_t i = b; i < e; ++i) {
        visit(i, [&](uint32_t j) { out.push_back(j); });
        offset_[i + 1] = static_cast<uint32_t>(out.size());  // local count, made global below
      }
    });
    for (std::size_t w = 0; w < cw; ++w) {
      const std::size_t c = c0 + w;
      const std::size_t b = n * c / chunks, e = n * (c + 1) / chunks;
      const std::size_t base = index_.size();
      if (base + local[w].size() > std::numeric_limits<uint32_t>::max())
        throw std::length_error("neighbour list over 4e9 pairs: reduce the resolution");
      for (std::size_t i = b; i < e; ++i) offset_[i + 1] += static_cast<uint32_t>(base);
      index_.insert(index_.end(), local[w].begin(), local[w].end());
    }
  }
  index_written_ = std::max(index_written_, index_.size());
  if (!row_end_.empty()) row_end_.assign(offset_.begin() + 1, offset_.end());
}

std::size_t NeighborSearch::bytes() const {
  // index_: the entries ever written, not its capacity (reserved pages never written are not resident).
  return (offset_.capacity() + index_written_ + cell_of_.capacity() + cell_start_.capacity() +
          cell_items_.capacity()) *
         sizeof(uint32_t);
}

std::vector<uint32_t> NeighborSearch::spatial_order() const {
  const std::size_t n = cell_of_.size();
  std::vector<uint64_t> key(n);
  parallel_for(n, [&](std::size_t i) {
    const uint32_t c = cell_of_[i];
    const uint64_t cx = c % dims_[0];
    const uint64_t cy = (c / dims_[0]) % dims_[1];
    const uint64_t cz = c / (static_cast<uint64_t>(dims_[0]) * dims_[1]);
    const uint64_t morton = spread_bits(cx) | (spread_bits(cy) << 1) | (spread_bits(cz) << 2);
    key[i] = (morton << 32) | i;  // ties broken by index: a total, deterministic order
  });
  std::sort(key.begin(), key.end());
  std::vector<uint32_t> order(n);
  for (std::size_t k = 0; k < n; ++k) order[k] = static_cast<uint32_t>(key[k] & 0xffffffffu);
  return order;
}

}  // namespace aortasph
