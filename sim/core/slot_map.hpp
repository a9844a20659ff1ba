// The map between a body model's own slots s (fixed at set-up: elastic solids, shells) and the particle
// arrays, which the spatial sort and the open boundaries reorder: after each reorder, at[s] is the particle
// index of slot s and slot[i] the slot of particle i (kSlotNone for particles of other kinds), found through
// the particle ids (s_of_id: id -> s). A slot whose particle is gone (it left the domain) is an instability:
// the body cannot hold together without it.
#pragma once

#include <sstream>
#include <vector>

#include "core/particles.hpp"
#include "core/sim_errors.hpp"

namespace aortasph {

inline constexpr uint32_t kSlotNone = 0xffffffffu;

// what: the kind of particle, for the message ("elastic", "shell"). id and X: per slot, its particle id and
// reference position.
inline void map_slots(const Particles& P, Kind kind, const std::vector<uint32_t>& s_of_id,
                      const std::vector<uint32_t>& id, const std::vector<Vec3>& X, const char* what,
                      std::vector<uint32_t>& at, std::vector<uint32_t>& slot) {
  at.assign(X.size(), kSlotNone);
  slot.assign(P.size(), kSlotNone);
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (P.kind[i] != kind || P.id[i] >= s_of_id.size()) continue;
    const uint32_t s = s_of_id[P.id[i]];
    if (s == kSlotNone) continue;
    at[s] = static_cast<uint32_t>(i);
    slot[i] = s;
  }
  for (std::size_t s = 0; s < X.size(); ++s)
    if (at[s] == kSlotNone) {
      std::ostringstream msg;
      msg << what << " particle " << id[s] << " (reference position " << X[s].transpose()
          << ") left the domain: its body cannot hold together without it";
      throw InstabilityError(msg.str());
    }
}

}  // namespace aortasph
