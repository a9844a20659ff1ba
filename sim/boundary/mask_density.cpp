#include "boundary/mask_density.hpp"

#include <algorithm>

#include "core/parallel.hpp"

namespace aortasph {

double MaskDensity::apply_to(Particles& P, const NeighborSearch& nb, const ShellWall& sw,
                             const CubicSpline& K, const Periodic& per, const std::vector<uint8_t>& take) {
  const auto& idx = nb.index();
  std::vector<uint32_t> order;
  for (std::size_t i = 0; i < P.size(); ++i)
    if (take[i]) order.push_back(static_cast<uint32_t>(i));
  std::vector<uint32_t> off(order.size() + 1, 0);
  for (std::size_t r = 0; r < order.size(); ++r)
    off[r + 1] = off[r] + (nb.full_end(order[r]) - nb.begin(order[r]));
  std::vector<uint32_t> row(off.back());
  std::vector<double> jump(order.size(), 0.0);
  parallel_for(order.size(), [&](std::size_t r) {
    const uint32_t i = order[r];
    const uint32_t begin = nb.begin(i), seen_end = nb.end(i), end = nb.full_end(i);
    uint32_t* now = row.data() + off[r];
    for (uint32_t k = begin; k < end; ++k) now[k - begin] = P.id[idx[k]] * 2u + (k >= seen_end ? 1u : 0u);
    std::sort(now, now + (end - begin));
    const uint32_t id = P.id[i];
    if (!recorded(id)) return;  // new to the band: its masks change nothing yet
    const std::size_t rec = static_cast<std::size_t>(record_of_[id]);
    const uint32_t* b = row_.data() + offset_[rec];
    const uint32_t* e = row_.data() + offset_[rec + 1];
    double d = 0.0;
    for (uint32_t k = begin; k < end; ++k) {
      const uint32_t j = idx[k];
      const uint32_t* it = std::lower_bound(b, e, P.id[j] * 2u);
      if (it == e || (*it >> 1) != P.id[j]) continue;  // outside the support at the last step
      const bool seen_before = (*it & 1u) == 0u, seen_now = k < seen_end;
      if (seen_before == seen_now) continue;
      const Vec3 xij = per.any ? per.image(P.x[i] - P.x[j]) : Vec3(P.x[i] - P.x[j]);
      double c = 0.0;
      if (P.kind[j] == Kind::Shell)  // its imaginary particles on i's side of the sheet now
        sw.for_each_ghost(xij, i, j, P.body[j],
                          [&](const Vec3& rg) { c += sw.ghost_mass[j] * K.W(rg.norm()); });
      else
        c = P.m[j] * K.W(xij.norm());
      d += seen_now ? c : -c;
    }
    jump[r] = d;
  });
  // Spread over the fluid round each particle (see the header): source j gives V_j drho_j W_ij / S_j to
  // each fluid particle i in its row (itself included), S_j = sum_k V_k W_jk over the same particles, so
  // that the volume change sum V drho is what the masks made. Gathered: each receiver sums its sources.
  const std::size_t n = P.size();
  std::vector<double> share(n, 0.0);  // V_j drho_j / S_j of each source
  parallel_for(order.size(), [&](std::size_t r) {
    if (jump[r] == 0.0) return;
    const uint32_t j = order[r];
    double S = P.m[j] / P.rho[j] * K.W(0.0);
    for (uint32_t k = nb.begin(j); k < nb.end(j); ++k) {
      const uint32_t q = idx[k];
      if (P.kind[q] != Kind::Fluid) continue;
      const Vec3 x = per.any ? per.image(P.x[j] - P.x[q]) : Vec3(P.x[j] - P.x[q]);
      S += P.m[q] / P.rho[q] * K.W(x.norm());
    }
    share[j] = P.m[j] / P.rho[j] * jump[r] / S;
  });
  std::vector<double> gain(n, 0.0);
  parallel_for(n, [&](std::size_t i) {
    if (P.kind[i] != Kind::Fluid) return;
    double g = share[i] * K.W(0.0);
    for (uint32_t k = nb.begin(i); k < nb.end(i); ++k) {
      const uint32_t j = idx[k];
      if (share[j] == 0.0) continue;
      const Vec3 x = per.any ? per.image(P.x[i] - P.x[j]) : Vec3(P.x[i] - P.x[j]);
      g += share[j] * K.W(x.norm());
    }
    gain[i] = g;
  });
  double total = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    P.rho[i] += gain[i];
    total += gain[i];
  }
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
  return total;
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
  record_of_.assign(top, -1);
  for (std::size_t r = 0; r < ids_.size(); ++r) record_of_[ids_[r]] = static_cast<int32_t>(r);
}

}  // namespace aortasph
