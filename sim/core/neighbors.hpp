// Cell-linked-list neighbour search (Monaghan & Lattanzio 1985; the "linked list" of Hockney & Eastwood),
// O(N): particles are binned into cubic cells of half the search radius, and the candidates of particle i are
// the particles of the 5 x 5 x 5 cells around its own. The result is a compressed row list (CSR): the
// neighbours of i are index[offset[i] .. offset[i+1]), in a fixed order (cells in z, y, x order, then
// particle index), so every sum over neighbours is bitwise the same for any thread count.
#pragma once

#include <cstdint>
#include <vector>

#include "core/periodic.hpp"
#include "scene.hpp"

namespace aortasph {

class NeighborSearch {
 public:
  // All pairs i != j with |x_i - x_j| < radius, except pairs of two fixed particles (fixed[i] && fixed[j]):
  // fixed walls never interact with each other, and a wall far from anything that moves gets an empty list
  // at almost no cost. fixed may be empty (no fixed particle).
  // Along periodic axes (set_periodic) the distance is the nearest image's and the cells wrap round; the
  // grid then spans the domain on those axes, which must hold at least 2 * kReach + 1 = 5 cells of radius / 2
  // (the loader checks the period; build() throws std::invalid_argument otherwise).
  void build(const std::vector<Vec3>& x, double radius, const std::vector<uint8_t>& fixed = {});
  // Only the cell grid and each particle's cell, as build() makes them, without the lists: enough for
  // spatial_order(), at a fraction of the cost and memory. The lists are left empty (size() == 0).
  void bin(const std::vector<Vec3>& x, double radius);
  // Adds count particles at the end with empty rows (nobody's neighbour either) until the next build.
  void append_rows(std::size_t count) {
    for (std::size_t k = 0; k < count; ++k) {
      offset_.push_back(offset_.back());
      if (!row_end_.empty()) row_end_.push_back(offset_.back());
    }
  }
  // Frees every buffer (lists and cell grid), keeping the periodic axes.
  void release();
  void set_periodic(const Periodic& p) { periodic_ = p; }
  const Periodic& periodic() const { return periodic_; }

  std::size_t size() const { return offset_.empty() ? 0 : offset_.size() - 1; }
  uint32_t begin(std::size_t i) const { return offset_[i]; }
  uint32_t end(std::size_t i) const { return row_end_.empty() ? offset_[i + 1] : row_end_[i]; }
  // Masked rows (sim/boundary/shell_coupling.hpp): a row's pairs may be reordered in place and its end set
  // before offset[i+1], so that every loop over begin(i) .. end(i) skips the masked pairs at the row's tail.
  // enable_row_ends() turns this on (build() then resets every end to the full row); unset, end(i) is the
  // full row and nothing is stored.
  void enable_row_ends() {
    if (row_end_.empty() && !offset_.empty()) row_end_.assign(offset_.begin() + 1, offset_.end());
  }
  bool row_ends_enabled() const { return !row_end_.empty(); }
  uint32_t full_end(std::size_t i) const { return offset_[i + 1]; }
  uint32_t* row_data() { return index_.data(); }
  void set_end(std::size_t i, uint32_t e) { row_end_[i] = e; }
  const std::vector<uint32_t>& index() const { return index_; }
  std::size_t pairs() const { return index_.size(); }
  std::size_t bytes() const;

  // A permutation that puts particles of nearby cells next to each other in memory (Morton / Z-order of
  // the cells, then current index). Valid after build().
  std::vector<uint32_t> spatial_order() const;

 private:
  std::vector<uint32_t> offset_;
  std::vector<uint32_t> index_;
  std::vector<uint32_t> row_end_;  // empty unless enable_row_ends()
  std::size_t index_written_ = 0;  // most entries index_ has held (its capacity may be larger, unwritten)
  // Cell grid of the last build.
  Vec3 origin_ = Vec3::Zero();
  double cell_ = 1.0;
  int dims_[3] = {1, 1, 1};
  std::vector<uint32_t> cell_of_;     // cell index of each particle
  std::vector<uint32_t> cell_start_;  // CSR over cells
  std::vector<uint32_t> cell_items_;
  double cell_size_[3] = {1.0, 1.0, 1.0};  // cell edge per axis (a periodic axis divides its period evenly)
  Periodic periodic_;

  void make_grid(const std::vector<Vec3>& x, double radius);
};

}  // namespace aortasph
