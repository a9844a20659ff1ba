// The density's share of the shells' masks (issue 17; docs/model.md, "Fluid on both sides of a shell").
//
// Beside a shell the fluid's neighbour lists are masked step by step (boundary/shell_coupling.hpp): a pair
// that straddles a sheet is out of both rows, and a fluid particle sees a shell particle's imaginary wall
// particles (fluid/shell_wall.hpp) only while that pair is not masked. The masks are decided afresh at
// every step from the particles' positions and side labels, so a neighbour can appear in a row, or vanish
// from it, well inside the kernel's support. The continuity equation (paper eq. 12) is the time derivative
// of the summation density (eq. 11) for a FIXED set of neighbours: it never sees such a change. Where the
// masks flicker, by the free edges of a closed valve's leaflets, that is a ratchet: a particle closes in on
// a neighbour it does not see, without its density rising, and moves away from it once it sees it, with its
// density falling. In the physio scene's diastole (docs/validation.md, "Stop 54") the fluid within 1 mm of
// the leaflets' aortic faces lost 5-10 % of its continuity density per 10 ms against its summation density,
// the aortic root drew in 0.5 % of its particles per 10 ms through the Windkessel outlet to fill the
// volume the density did not see, and the sinuses packed.
//
// This step's masks are compared with the last step's, pair by pair, at the positions now: each fluid
// particle's density gains the summation-density terms of the neighbours it sees now and did not see, and
// loses those of the neighbours it saw and no longer sees,
//
//   delta rho_i = sum_j (s_j^now - s_j^before) m_j W_ij,   s_j = 1 where j is in i's row (not masked),
//
// (a shell particle j contributing its imaginary particles' sum_g m_g W_ig on i's side now): the density
// follows the summation density across a change of masks, as eq. 12 makes it follow the particles' motion
// in between. Each particle's change is spread over the fluid in its row, itself included: particle i gains
// sum_j V_j delta rho_j W_ij / S_j, S_j = sum_k V_k W_jk over j's fluid neighbours and itself, which keeps
// the volume change sum_i V_i delta rho_i that the masks made. (Taken at once by the particle itself, a
// neighbour one spacing away is 8 % of its density: in the sluice of test [mask_density] the largest density
// error was 9.4 %, spread 6.7 %, against 1.2 % without mask_density; the band's summation density over
// density moved by 0.25 % and 0.28 % in 0.24 s, against 5.2 % without.) A neighbour that was not in i's lists
// at the last step was outside the support then and enters smoothly. A change of a side label (the imaginary
// particles jumping to the other side of a sheet) is not counted (in the diastole it moved the balance by
// under 0.2 % per 10 ms against the masks' 5-10 %). Mass is untouched. The last step's masks are kept by
// particle id, so that a sort or an open boundary's new particles do not disturb them, and saved in
// checkpoints.
#pragma once

#include <cstdint>
#include <vector>

#include "core/neighbors.hpp"
#include "core/particles.hpp"
#include "fluid/fluid_wcsph.hpp"

namespace aortasph {

class MaskDensity {
 public:
  // After this step's masks (ShellCoupling::prepare, which set ctx.shell_wall): adds each fluid particle's
  // delta rho (above) to P.rho and records the masks now. in_band(i): whether particle i's row can hold
  // masks (a shell particle in its full row); the rows of the particles recorded at the last step are
  // compared as well. wanted(i): whether fluid particle i's material asks for it (FluidParams::mask_density).
  template <class InBand, class Wanted>
  void apply(Particles& P, const NeighborSearch& nb, const FluidContext& ctx, InBand&& in_band,
             Wanted&& wanted) {
    std::vector<uint8_t> take(P.size(), 0);  // 1: compare with the record, 2: also record now
    for (std::size_t i = 0; i < P.size(); ++i) {
      if (P.kind[i] != Kind::Fluid || !wanted(i)) continue;
      if (in_band(i))
        take[i] = 2;
      else if (recorded(P.id[i]))
        take[i] = 1;  // left the band at this build: its row has no masks now, nor at the next step
    }
    apply_to(P, nb, ctx, take);
  }

  // The record, for checkpoints: by recorded particle, its id, and its row's neighbours as built (ids, each
  // id * 2 + 1 where the pair was masked), in CSR form.
  const std::vector<uint32_t>& ids() const { return ids_; }
  const std::vector<uint32_t>& offsets() const { return offset_; }
  const std::vector<uint32_t>& rows() const { return row_; }
  void restore(std::vector<uint32_t> ids, std::vector<uint32_t> offsets, std::vector<uint32_t> rows);

 private:
  void apply_to(Particles& P, const NeighborSearch& nb, const FluidContext& ctx,
                const std::vector<uint8_t>& take);
  bool recorded(uint32_t id) const { return id < record_of_.size() && record_of_[id] >= 0; }
  void index_ids();

  std::vector<uint32_t> ids_, offset_{0}, row_;  // row_: each record's row as built
  std::vector<int32_t> record_of_;               // by particle id: index into ids_, or -1
  std::size_t id_bound_ = 0;                     // above every id in the record
};

}  // namespace aortasph
