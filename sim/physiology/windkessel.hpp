// Three-element (RCR) Windkessel outlet: a proximal resistance R_p in series with a capacitance C parallel to
// a distal resistance R_d that drains to the distal (venous) pressure P_d (Westerhof, Lankhaar & Westerhof
// 2009, "The arterial Windkessel", Med. Biol. Eng. Comput. 47:131-141, fig. 1c; the "RCR" outlet of
// SimVascular and CRIMSON, with the same names and order R_p, C, R_d). With Q the flow leaving the domain
// through the outlet:
//
//   C dP_c/dt = Q - (P_c - P_d) / R_d,        P_out = P_c + R_p Q.
//
// Time integration, over a step t -> t + dt with Q linear in between (Q0 at t, Q1 at t + dt; first-order
// hold), exactly: with tau = R_d C, E = exp(-dt / tau), u = P_c - P_d,
//
//   u(t + dt) = E u(t) + R_d [ Q0 (1 - E) + (Q1 - Q0) (1 - tau (1 - E) / dt) ].
//
// This is the exact solution of the linear ODE for that Q (the exponential integrator, e.g. Hochbruck &
// Ostermann 2010, Acta Numerica 19:209-286, eq. 2.9 with linear interpolation of the forcing): |E| < 1 for
// any dt > 0, so the update is stable at any fluid step, for any R_d C, and a constant Q gives the analytic
// charging curve P_c -> P_d + R_d Q with time constant R_d C to round-off. 1 - E is computed as
// -expm1(-dt / tau) (no cancellation for dt << tau). Deterministic: plain arithmetic on a few doubles.
#pragma once

namespace aortasph {

// SI units: resistances [Pa s / m^3], capacitance [m^3 / Pa], pressures [Pa] (absolute in the fluid's
// terms, as an outflow's `pressure`).
struct WindkesselParams {
  double proximal_resistance = 0.0;  // R_p (> 0)
  double capacitance = 0.0;          // C (> 0)
  double distal_resistance = 0.0;    // R_d (> 0)
  double distal_pressure = 0.0;      // P_d
  double initial_pressure = 0.0;     // P_c at t = 0
};

// The model's state: plain values (checkpoints save them).
struct WindkesselState {
  double pc = 0.0;     // capacitor pressure P_c [Pa]
  double q = 0.0;      // the flow of the last update [m^3/s] (Q0 of the next one)
  double p_out = 0.0;  // outlet pressure P_out = P_c + R_p Q [Pa]
};

// The state at t = 0 for an initial flow q0.
WindkesselState windkessel_start(const WindkesselParams& w, double q0);

// Advances the state by dt > 0 to the flow q1 at the end of the step (see above).
void windkessel_step(const WindkesselParams& w, WindkesselState& s, double q1, double dt);

}  // namespace aortasph
