#include "physiology/windkessel.hpp"

#include <cmath>

namespace aortasph {

WindkesselState windkessel_start(const WindkesselParams& w, double q0) {
  WindkesselState s;
  s.pc = w.initial_pressure;
  s.q = q0;
  s.p_out = s.pc + w.proximal_resistance * q0;
  return s;
}

void windkessel_step(const WindkesselParams& w, WindkesselState& s, double q1, double dt) {
  if (!(dt > 0.0)) return;
  const double tau = w.distal_resistance * w.capacitance;
  const double x = dt / tau;
  const double one_minus_e = -std::expm1(-x);  // 1 - exp(-dt / tau)
  const double e = 1.0 - one_minus_e;
  const double q0 = s.q;
  // 1 - tau (1 - E) / dt: for small x, x / 2 - x^2 / 6 + ... (the direct form loses digits below x ~ 1e-4).
  const double ramp = x < 1e-4 ? x * (0.5 - x / 6.0 + x * x / 24.0) : 1.0 - one_minus_e / x;
  const double u =
      e * (s.pc - w.distal_pressure) + w.distal_resistance * (q0 * one_minus_e + (q1 - q0) * ramp);
  s.pc = w.distal_pressure + u;
  s.q = q1;
  s.p_out = s.pc + w.proximal_resistance * q1;
}

}  // namespace aortasph
