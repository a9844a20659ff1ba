// Clinical valve metrics per cardiac cycle, from probe time series (docs/valve-metrics.md gives every
// definition with its source). Pure functions on sampled signals: no World, no files. A signal is sampled at
// the probe times and read as piecewise linear between samples; NaN marks a quantity that cannot be measured
// (a signal that is absent, a valve that never closes in the window).
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace aortasph {

inline constexpr double kPaPerMmHg = 133.322387415;  // 1 mmHg = 133.322387415 Pa (conventional)
// The acoustic noise of a pressure (issue 17 item 3): RMS about a 10 ms centred running mean, from samples
// at most 1 ms apart (scripts/acoustic_noise.py computes the same from probes.csv).
inline constexpr double kNoiseWindow = 0.01, kNoiseMaxSpacing = 0.001;

// The signals of one run (all sampled at `t`); an empty vector is a signal the scene does not measure.
struct CycleSignals {
  std::vector<double> t;                // [s], strictly increasing
  std::vector<double> lv_pressure;      // [Pa] upstream of the valve (left ventricle / LVOT)
  std::vector<double> aortic_pressure;  // [Pa] downstream of the valve
  std::vector<double> valve_flow;       // [m^3/s] through the valve plane, positive forward
  std::vector<double> orifice_area;     // [m^2] geometric orifice area
  std::vector<double> jet_speed;        // [m/s] largest fluid speed near the valve
  std::vector<double> lvot_flow;        // [m^3/s] through the LVOT (continuity EOA); empty: valve_flow
  std::vector<double> stress_max, stress_mean, stress_p95;  // [Pa] leaflet von Mises stress
  std::vector<double> strain_max;                           // [-] leaflet peak strain
  // Coaptation probe: per leaflet pair (names like "0_1"), height and length [m]; the central coaptation
  // height and the effective height [m].
  std::vector<std::string> pair_names;
  std::vector<std::vector<double>> coaptation_height, coaptation_length;
  std::vector<double> central_height, effective_height;
  std::vector<std::vector<double>> effective_height_cusp;  // per leaflet (coaptation probe, per_leaflet)
  // Gap areas (a gap_area probe) [m^2]: the central part and per commissure.
  std::vector<double> gap_central;
  std::vector<std::vector<double>> gap_commissural;
  // Per cusp (a per_body stress probe): peak and 95th-percentile von Mises stress [Pa], the peak's height
  // above the annulus plane [m] and fraction of the cusp's span [-].
  std::vector<std::vector<double>> cusp_stress_max, cusp_stress_p95, cusp_peak_height, cusp_peak_s;
  // Leaflet-wall distance (a wall_distance probe) [m]: over all leaflets and per leaflet.
  std::vector<double> wall_min;
  std::vector<std::vector<double>> wall_min_cusp;
  // The fluid's largest relative density error |rho / rho0 - 1| (diagnostics.csv's max_density_error) [-].
  std::vector<double> density_error;
  // The fluid's summation density over its continuity density (diagnostics.csv's volume_ratio,
  // fluid/volume_check.hpp) [-].
  std::vector<double> volume_ratio;
};

struct CycleOptions {
  double period = 0.8;          // T [s]
  double start = 0.0;           // cycle k is the window [start + k T, start + (k+1) T)
  double lvot_area = 0.0;       // [m^2], continuity EOA; 0: not measurable
  double density = 1060.0;      // fluid density [kg/m^3], Gorlin EOA (ISO 5840 form)
  double hold_level = 9332.57;  // [Pa] the diastolic pressure difference counted as held (70 mmHg)
  // [Pa] the pressure that reads 0 mmHg in the LV and aortic pressures (clinical pressures are gauge
  // pressures; the fluid's are absolute in its terms, its background pressure included). Differences
  // (gradients, the diastolic difference) do not depend on it.
  double pressure_zero = 0.0;
};

// The metrics of one cycle, in the units of their names; NaN where not measurable.
struct CycleMetrics {
  int cycle = 0;
  double t_start = 0, t_end = 0;
  double stroke_volume_ml = 0, cardiac_output_l_min = 0, peak_forward_flow_ml_s = 0, ejection_time_ms = 0;
  double peak_jet_velocity_m_s = 0;
  double peak_gradient_mmHg = 0, mean_gradient_mmHg = 0;
  double peak_goa_cm2 = 0, eoa_gorlin_cm2 = 0, eoa_continuity_cm2 = 0;
  double opening_time_ms = 0, closing_time_ms = 0;
  double closing_volume_ml = 0, leakage_volume_ml = 0, regurgitant_fraction_pct = 0;
  double diastolic_dp_mean_mmHg = 0, diastolic_dp_peak_mmHg = 0, diastolic_dp_held_s = 0;
  double lv_peak_mmHg = 0, lv_end_diastolic_mmHg = 0;
  double aortic_systolic_mmHg = 0, aortic_diastolic_mmHg = 0, aortic_end_diastolic_mmHg = 0;
  double stress_systole_peak_kPa = 0, stress_systole_p95_kPa = 0, stress_systole_mean_kPa = 0;
  double stress_diastole_peak_kPa = 0, stress_diastole_p95_kPa = 0, stress_diastole_mean_kPa = 0;
  double strain_systole_peak = 0, strain_diastole_peak = 0;
  std::vector<std::string> pair_names;
  std::vector<double> coaptation_height_mm, coaptation_length_mm;  // per pair
  double central_coaptation_height_mm = 0, effective_height_mm = 0;
  std::vector<double> effective_height_mm_per;  // per cusp
  // Gaps at peak diastolic load (the sample of largest p_Ao - p_LV while closed) [mm^2].
  double peak_load_time_ms = 0, central_gap_area_mm2 = 0, commissural_gap_area_mm2 = 0;
  std::vector<double> commissural_gap_area_mm2_per;  // per commissure
  // Per cusp, in systole (forward flow) and diastole (closed): peak and p95 stress [kPa], where the peak is.
  struct CuspStress {
    double peak_kPa = 0, p95_kPa = 0, peak_height_mm = 0, peak_s = 0;
  };
  std::vector<CuspStress> cusp_systole, cusp_diastole;
  // Smallest leaflet-wall distance during forward flow [mm]: over all leaflets and per leaflet.
  double leaflet_wall_min_systole_mm = 0;
  std::vector<double> leaflet_wall_min_systole_mm_per;
  // Largest density error in the cycle [%]; noise of the LV pressure during forward flow [Pa]: the RMS about
  // its centred running mean over kNoiseWindow, NaN unless the samples are kNoiseMaxSpacing apart or closer.
  double max_density_error_pct = 0, lv_noise_Pa = 0;
  // Lowest and highest volume_ratio in the cycle (NaN without it): away from the lattice's value the
  // particles stand farther apart (lower) or closer (higher) than their densities say.
  double volume_ratio_min = 0, volume_ratio_max = 0;
  // Periodic state, against the previous cycle (NaN for the first).
  double sv_change_pct = 0, edp_change_pct = 0;
  bool periodic = false;
};

// Complete cycle windows [start + k T, start + (k+1) T] covered by samples up to t_last (k = 0, 1, ...).
std::vector<std::pair<double, double>> cycle_windows(double t_last, const CycleOptions& o);

// The metrics of the window [t0, t1] (signals interpolated linearly at the window's ends).
CycleMetrics cycle_metrics(const CycleSignals& s, double t0, double t1, const CycleOptions& o);

// All complete cycles, with the periodic-state test filled in (sv_change_pct, edp_change_pct, periodic).
std::vector<CycleMetrics> all_cycle_metrics(const CycleSignals& s, const CycleOptions& o);

// Fills the periodic-state fields of cur from prev: relative changes of stroke volume and end-diastolic
// aortic pressure [%]; periodic when both are below `tolerance_pct`.
void periodic_state(const CycleMetrics& prev, CycleMetrics& cur, double tolerance_pct = 2.0);

// The metrics as (column name with unit, value) in cycles.csv order.
std::vector<std::pair<std::string, double>> metric_table(const CycleMetrics& m);

// Piecewise-linear helpers (exposed for the tests). Integral of v over [a, b].
double integrate(const std::vector<double>& t, const std::vector<double>& v, double a, double b);
// RMS of v about its centred running mean (the mean of the samples within +- window / 2 of each) over the
// samples in [a, b] whose whole window lies within the signal; NaN where the samples within reach of [a, b]
// are more than max_dt apart, or fewer than 3 count.
double running_mean_rms(const std::vector<double>& t, const std::vector<double>& v, double a, double b,
                        double window, double max_dt);
// Value at time x (linear, held at the ends).
double sample(const std::vector<double>& t, const std::vector<double>& v, double x);

}  // namespace aortasph
