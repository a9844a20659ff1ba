#include "boundary/mask_density.hpp"

#include <algorithm>

#include "core/parallel.hpp"

namespace aortasph {

void MaskDensity::apply_to(Particles& P, const NeighborSearch& nb, const FluidContext& ctx,
                           const std::vector<uint8_t>& take) {
  const auto& idx = nb.index();
  const CubicSpline& K = ctx.kernel;
  std::vector<uint32_t> order;
  std::size_t id_bound = id_bound_;  // above every id in the record and in the rows now
  for (std::size_t i = 0; i < P.size(); ++i) {
    id_bound = std::max<std::size_t>(id_bound, std::size_t{P.id[i]} + 1);
    if (take[i]) order.push_back(static_cast<uint32_t>(i));
  }
  std::vector<uint32_t> off(order.size() + 1, 0);
  for (std::size_t r = 0; r < order.size(); ++r)
    off[r + 1] = off[r] + (nb.full_end(order[r]) - nb.begin(order[r]));
  std::vector<uint32_t> row(off.back());
  std::vector<double> jump(order.size(), 0.0);
  // The last step's row of i is looked up by neighbour id in a per-thread table indexed by id (1: seen, 2:
  // masked, 0: not in the row), filled from the record and cleared after the row: O(row) per particle, where
  // sorting each row and a binary search per neighbour cost 12 % of the physio scene's step (stop 56). A
  // neighbour listed twice counts as seen, as the first match of the search in the sorted row did.
  parallel_for(order.size(), [&](std::size_t r) {
    const uint32_t i = order[r];
    const uint32_t begin = nb.begin(i), seen_end = nb.end(i), end = nb.full_end(i);
    uint32_t* now = row.data() + off[r];
    for (uint32_t k = begin; k < end; ++k) now[k - begin] = P.id[idx[k]] * 2u + (k >= seen_end ? 1u : 0u);
    const uint32_t id = P.id[i];
    if (!recorded(id)) return;  // new to the band: its masks change nothing yet
    const std::size_t rec = static_cast<std::size_t>(record_of_[id]);
    const uint32_t* b = row_.data() + offset_[rec];
    const uint32_t* e = row_.data() + offset_[rec + 1];
    thread_local std::vector<uint8_t> before;  // by id
    if (before.size() < id_bound) before.assign(id_bound, 0);
    for (const uint32_t* it = b; it != e; ++it) {
      uint8_t& s = before[*it >> 1];
      if (s != 1) s = (*it & 1u) ? 2 : 1;
    }
    double d = 0.0;
    for (uint32_t k = begin; k < end; ++k) {
      const uint32_t j = idx[k];
      const uint8_t s = before[P.id[j]];
      if (s == 0) continue;  // outside the support at the last step
      const bool seen_before = s == 1, seen_now = k < seen_end;
      if (seen_before == seen_now) continue;
      const double c =
          summation_term(P, ctx, i, j, ctx.separation(P.x[i], P.x[j]));  // a sheet: on i's side now
      d += seen_now ? c : -c;
    }
    for (const uint32_t* it = b; it != e; ++it) before[*it >> 1] = 0;
    jump[r] = d;
  });
  // Spread over the fluid round each particle (see the header): source j gives V_j drho_j W_ij / S_j to
  // each fluid particle i in its row (itself included), S_j = sum_k V_k W_jk over the same particles, so
  // that the volume change sum V drho is what the masks made. Gathered: each receiver sums its sources.
  // Only the sources' rows receive; they are marked one source at a time (a few hundred sources per step in
  // the physio scene), then gathered in parallel.
  const std::size_t n = P.size();
  std::vector<double> share(n, 0.0);  // V_j drho_j / S_j of each source
  parallel_for(order.size(), [&](std::size_t r) {
    if (jump[r] == 0.0) return;
    const uint32_t j = order[r];
    double S = P.m[j] / P.rho[j] * K.W(0.0);
    for (uint32_t k = nb.begin(j); k < nb.end(j); ++k) {
      const uint32_t q = idx[k];
      if (P.kind[q] == Kind::Fluid) S += P.m[q] / P.rho[q] * K.W(ctx.separation(P.x[j], P.x[q]).norm());
    }
    share[j] = P.m[j] / P.rho[j] * jump[r] / S;
  });
  std::vector<uint32_t> receivers;
  std::vector<uint8_t> marked(n, 0);
  for (std::size_t r = 0; r < order.size(); ++r) {
    if (jump[r] == 0.0) continue;
    const uint32_t j = order[r];
    auto mark = [&](uint32_t q) {
      if (P.kind[q] == Kind::Fluid && !marked[q]) {
        marked[q] = 1;
        receivers.push_back(q);
      }
    };
    mark(j);
    for (uint32_t k = nb.begin(j); k < nb.end(j); ++k) mark(idx[k]);
  }
  std::vector<double> gain(receivers.size(), 0.0);
  parallel_for(receivers.size(), [&](std::size_t r) {
    const uint32_t i = receivers[r];
    double g = share[i] * K.W(0.0);
    for (uint32_t k = nb.begin(i); k < nb.end(i); ++k) {
      const uint32_t j = idx[k];
      if (share[j] != 0.0) g += share[j] * K.W(ctx.separation(P.x[i], P.x[j]).norm());
    }
    gain[r] = g;
  });
  for (std::size_t r = 0; r < receivers.size(); ++r) P.rho[receivers[r]] += gain[r];
  ids_.clear();
  offset_.assign(1, 0);
  row_.clear();
  for (std::size_t r = 0; r < order.size(); ++r) {
    if (take[order[r]] != 2) continue;
    ids_.push_back(P.id[order[r]]);
    row_.insert(row_.end(), row.begin() + off[r], row.begin() + off[r + 1]);
    offset_.push_back(static_cast<uint32_t>(row_.size()));
  }
  index_ids();
}

void MaskDensity::restore(std::vector<uint32_t> ids, std::vector<uint32_t> offsets,
                          std::vector<uint32_t> rows) {
  ids_ = std::move(ids);
  offset_ = std::move(offsets);
  row_ = std::move(rows);
  if (offset_.empty()) offset_.assign(1, 0);
  index_ids();
}

void MaskDensity::index_ids() {
  uint32_t top = 0;
  for (const uint32_t id : ids_) top = std::max(top, id + 1);
  id_bound_ = top;
  for (const uint32_t e : row_) id_bound_ = std::max<std::size_t>(id_bound_, std::size_t{e >> 1} + 1);
  record_of_.assign(top, -1);
  for (std::size_t r = 0; r < ids_.size(); ++r) record_of_[ids_[r]] = static_cast<int32_t>(r);
}

}  // namespace aortasph
