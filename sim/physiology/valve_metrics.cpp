#include "physiology/valve_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace aortasph {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
using Vec = std::vector<double>;

// The samples of v inside [a, b] with v interpolated at a and b: times in T, values in V.
void clip(const Vec& t, const Vec& v, double a, double b, Vec& T, Vec& V) {
  T.clear();
  V.clear();
  if (t.empty() || !(b > a)) return;
  T.push_back(a);
  V.push_back(sample(t, v, a));
  for (std::size_t i = 0; i < t.size(); ++i)
    if (t[i] > a && t[i] < b) {
      T.push_back(t[i]);
      V.push_back(v[i]);
    }
  T.push_back(b);
  V.push_back(sample(t, v, b));
}

double max_in(const Vec& t, const Vec& v, double a, double b) {
  Vec T, V;
  clip(t, v, a, b, T, V);
  double m = -std::numeric_limits<double>::infinity();
  for (double x : V)
    if (!std::isnan(x)) m = std::max(m, x);
  return std::isfinite(m) ? m : kNaN;
}

double min_in(const Vec& t, const Vec& v, double a, double b) {
  Vec T, V;
  clip(t, v, a, b, T, V);
  double m = std::numeric_limits<double>::infinity();
  for (double x : V)
    if (!std::isnan(x)) m = std::min(m, x);
  return std::isfinite(m) ? m : kNaN;
}

// The first time in [a, b] where v reaches its largest value there.
double argmax_in(const Vec& t, const Vec& v, double a, double b) {
  Vec T, V;
  clip(t, v, a, b, T, V);
  std::size_t best = 0;
  for (std::size_t i = 1; i < V.size(); ++i)
    if (V[i] > V[best]) best = i;
  return T.empty() ? kNaN : T[best];
}

// Integral over {t in [a, b] : g(t) > level} of f (power 1) or f^2 (power 2), f and g piecewise linear on the
// same samples; `measure` receives the length of that set.
double integral_where(const Vec& t, const Vec& f, const Vec& g, double level, double a, double b, int power,
                      double& measure) {
  Vec T, F, G;
  clip(t, f, a, b, T, F);
  clip(t, g, a, b, T, G);
  double sum = 0.0;
  measure = 0.0;
  for (std::size_t i = 0; i + 1 < T.size(); ++i) {
    const double g0 = G[i] - level, g1 = G[i + 1] - level;
    if (g0 <= 0 && g1 <= 0) continue;
    double ta = T[i], tb = T[i + 1];
    if (g0 <= 0) ta = T[i] + (T[i + 1] - T[i]) * (-g0) / (g1 - g0);
    if (g1 <= 0) tb = T[i] + (T[i + 1] - T[i]) * g0 / (g0 - g1);
    const double fa = F[i] + (F[i + 1] - F[i]) * (ta - T[i]) / (T[i + 1] - T[i]);
    const double fb = F[i] + (F[i + 1] - F[i]) * (tb - T[i]) / (T[i + 1] - T[i]);
    const double h = tb - ta;
    measure += h;
    sum += power == 1 ? 0.5 * h * (fa + fb) : h / 3.0 * (fa * fa + fa * fb + fb * fb);  // exact for linear f
  }
  return sum;
}

// Times in [a, b] where v crosses `level` upwards (below -> at or above) or downwards (above -> at or below).
Vec crossings(const Vec& t, const Vec& v, double level, double a, double b, bool up) {
  Vec T, V, out;
  clip(t, v, a, b, T, V);
  for (std::size_t i = 0; i + 1 < T.size(); ++i) {
    const double v0 = V[i] - level, v1 = V[i + 1] - level;
    const bool hit = up ? (v0 < 0 && v1 >= 0) : (v0 > 0 && v1 <= 0);
    if (hit) out.push_back(T[i] + (T[i + 1] - T[i]) * v0 / (v0 - v1));
  }
  return out;
}

// Mean of the samples of v (NaN skipped) with t in [a, b].
double sample_mean(const Vec& t, const Vec& v, double a, double b) {
  double sum = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < t.size(); ++i)
    if (t[i] >= a && t[i] <= b && !std::isnan(v[i])) {
      sum += v[i];
      ++n;
    }
  return n ? sum / n : kNaN;
}

Vec difference(const Vec& a, const Vec& b) {
  Vec d(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) d[i] = a[i] - b[i];
  return d;
}

bool has(const Vec& v) {
  return !v.empty();
}

}  // namespace

double running_mean_rms(const Vec& t, const Vec& v, double a, double b, double window, double max_dt) {
  if (t.size() < 3 || !(b > a)) return kNaN;
  const double half = 0.5 * window, eps = 1e-9 * std::max(window, max_dt);
  // The samples must be max_dt apart or closer wherever a window reaches.
  for (std::size_t i = 0; i + 1 < t.size(); ++i)
    if (t[i + 1] > a - half - eps && t[i] < b + half + eps && t[i + 1] - t[i] > max_dt * (1 + 1e-6) + eps)
      return kNaN;
  double sum2 = 0.0;
  int n = 0;
  std::size_t lo = 0, hi = 0;  // the window [lo, hi) of sample i
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (t[i] < a - eps || t[i] > b + eps || std::isnan(v[i])) continue;
    if (t[i] - half < t.front() - eps || t[i] + half > t.back() + eps) continue;  // a whole window only
    while (t[lo] < t[i] - half - eps) ++lo;
    hi = std::max(hi, lo);
    while (hi < t.size() && t[hi] <= t[i] + half + eps) ++hi;
    double mean = 0.0;
    for (std::size_t k = lo; k < hi; ++k) mean += v[k];
    mean /= static_cast<double>(hi - lo);
    sum2 += (v[i] - mean) * (v[i] - mean);
    ++n;
  }
  return n >= 3 ? std::sqrt(sum2 / n) : kNaN;
}

double sample(const Vec& t, const Vec& v, double x) {
  if (t.empty()) return kNaN;
  if (x <= t.front()) return v.front();
  if (x >= t.back()) return v.back();
  const std::size_t k = static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), x) - t.begin());
  const double w = (x - t[k - 1]) / (t[k] - t[k - 1]);
  return v[k - 1] + w * (v[k] - v[k - 1]);
}

double integrate(const Vec& t, const Vec& v, double a, double b) {
  Vec T, V;
  clip(t, v, a, b, T, V);
  double sum = 0.0;
  for (std::size_t i = 0; i + 1 < T.size(); ++i) sum += 0.5 * (T[i + 1] - T[i]) * (V[i] + V[i + 1]);
  return sum;
}

std::vector<std::pair<double, double>> cycle_windows(double t_last, const CycleOptions& o) {
  std::vector<std::pair<double, double>> w;
  const double eps = 1e-9 * o.period;
  for (int k = 0;; ++k) {
    const double a = o.start + k * o.period, b = o.start + (k + 1) * o.period;
    if (b > t_last + eps || k > 100000) break;
    w.emplace_back(a, b);
  }
  return w;
}

CycleMetrics cycle_metrics(const CycleSignals& s, double t0, double t1, const CycleOptions& o) {
  CycleMetrics m;
  m.t_start = t0;
  m.t_end = t1;
  const Vec& t = s.t;
  const double T = t1 - t0;
  const double ml = 1e6, cm2 = 1e4, mmHg = 1.0 / kPaPerMmHg;

  // Forward flow [tf0, tf1] around the peak of the valve flow (docs/valve-metrics.md, "Phases"): it ends at
  // the first downward zero crossing after the peak; it starts at the flow's rise through 5 % of its peak,
  // taken back to zero along the chord through its 5 % and 10 % crossings, but not before the last upward
  // zero crossing. Not the last zero crossing alone: before the valve opens, the closed leaflets bulge
  // towards the aorta under the rising LV pressure, which a flow probe at the annulus reads as a small
  // forward flow (physio55n's cycle 2: 2-13 ml/s over the 70 ms before opening, against -50 mmHg), and
  // counted as ejection it put isovolumic contraction into the mean gradient (1.3 mmHg for 6.9).
  const Vec& q = s.valve_flow;
  const double q_peak = max_in(t, q, t0, t1);
  m.peak_forward_flow_ml_s = q_peak * ml;
  bool ejection = q_peak > 0;
  double tf0 = t0, tf1 = t1;
  if (ejection) {
    const double t_pk = argmax_in(t, q, t0, t1);
    double t5 = t0;
    for (double c : crossings(t, q, 0.05 * q_peak, t0, t_pk, true)) t5 = c;
    for (double c : crossings(t, q, 0.0, t0, t5, true)) tf0 = c;
    const Vec up10 = crossings(t, q, 0.10 * q_peak, t5, t_pk, true);
    if (t5 > t0 && !up10.empty()) tf0 = std::max(tf0, 2.0 * t5 - up10.front());
    const Vec down = crossings(t, q, 0.0, t_pk, t1, false);
    if (!down.empty()) tf1 = down.front();
    m.stroke_volume_ml = integrate(t, q, tf0, tf1) * ml;
    m.ejection_time_ms = (tf1 - tf0) * 1e3;
  } else {
    m.peak_forward_flow_ml_s = std::max(m.peak_forward_flow_ml_s, 0.0);
    m.stroke_volume_ml = 0.0;
    m.ejection_time_ms = 0.0;
  }
  m.cardiac_output_l_min = m.stroke_volume_ml / T * 60.0 / 1e3;

  // Transvalvular gradient during forward flow; Gorlin EOA over its positive part (ISO 5840).
  const bool pressures = has(s.lv_pressure) && has(s.aortic_pressure);
  const Vec dp = pressures ? difference(s.lv_pressure, s.aortic_pressure) : Vec{};
  m.peak_gradient_mmHg = m.mean_gradient_mmHg = m.eoa_gorlin_cm2 = kNaN;
  if (pressures && ejection) {
    m.peak_gradient_mmHg = max_in(t, dp, tf0, tf1) * mmHg;
    m.mean_gradient_mmHg = integrate(t, dp, tf0, tf1) / (tf1 - tf0) * mmHg;
    double period_pos = 0.0, unused = 0.0;
    const double q2 = integral_where(t, q, dp, 0.0, tf0, tf1, 2, period_pos);
    const double dp_int = integral_where(t, dp, dp, 0.0, tf0, tf1, 1, unused);
    if (period_pos > 0) {
      const double q_rms_ml_s = std::sqrt(q2 / period_pos) * ml;
      const double dp_mean_mmHg = dp_int / period_pos * mmHg;
      m.eoa_gorlin_cm2 = q_rms_ml_s / (51.6 * std::sqrt(dp_mean_mmHg / (o.density / 1000.0)));
    }
  }

  // Jet: peak velocity and the continuity EOA = A_LVOT VTI_LVOT / VTI_jet over the forward flow.
  m.peak_jet_velocity_m_s = m.eoa_continuity_cm2 = kNaN;
  if (has(s.jet_speed) && ejection) {
    m.peak_jet_velocity_m_s = max_in(t, s.jet_speed, tf0, tf1);
    const double vti_jet = integrate(t, s.jet_speed, tf0, tf1);
    if (o.lvot_area > 0 && vti_jet > 0) {
      const Vec& ql = has(s.lvot_flow) ? s.lvot_flow : q;
      const double vti_lvot = integrate(t, ql, tf0, tf1) / o.lvot_area;
      m.eoa_continuity_cm2 = o.lvot_area * vti_lvot / vti_jet * cm2;
    }
  }

  // Orifice: opening and closing between 10 % and 90 % of the area's swing in the cycle.
  m.peak_goa_cm2 = m.opening_time_ms = m.closing_time_ms = kNaN;
  m.closing_volume_ml = m.leakage_volume_ml = m.regurgitant_fraction_pct = kNaN;
  double t_closed = kNaN, t_reopen = t1;
  double t_lead = t0;  // the window starts closed until here: the previous diastole's tail
  if (has(s.orifice_area)) {
    const Vec& A = s.orifice_area;
    const double a_pk = max_in(t, A, t0, t1), a_min = min_in(t, A, t0, t1);
    m.peak_goa_cm2 = a_pk * cm2;
    const double swing = a_pk - a_min;
    if (swing > 0) {
      const double l10 = a_min + 0.1 * swing, l90 = a_min + 0.9 * swing;
      const double t_apk = argmax_in(t, A, t0, t1);
      if (sample(t, A, t0) < l10) {
        const Vec up = crossings(t, A, l10, t0, t_apk, true);
        if (!up.empty()) t_lead = up.front();
      }
      const Vec up90 = crossings(t, A, l90, t0, t_apk, true);
      if (!up90.empty()) {
        const Vec up10 = crossings(t, A, l10, t0, up90.front(), true);
        if (!up10.empty()) m.opening_time_ms = (up90.front() - up10.back()) * 1e3;
      }
      const Vec down10 = crossings(t, A, l10, t_apk, t1, false);
      if (!down10.empty()) {
        t_closed = down10.front();
        const Vec down90 = crossings(t, A, l90, t_apk, t_closed, false);
        const double t_c90 = down90.empty() ? t_apk : down90.back();
        m.closing_time_ms = (t_closed - t_c90) * 1e3;
        const Vec reopen = crossings(t, A, l10, t_closed, t1, true);
        if (!reopen.empty()) t_reopen = reopen.front();
      }
    }
  }
  const bool closed = !std::isnan(t_closed);
  if (closed && ejection) {
    // Backflow at the valve plane: during closure (end of forward flow -> closed) and once closed.
    const double from = std::max(t_closed, tf1);
    m.closing_volume_ml = t_closed > tf1 ? -integrate(t, q, tf1, t_closed) * ml : 0.0;
    m.leakage_volume_ml = t_reopen > from ? -integrate(t, q, from, t_reopen) * ml : 0.0;
    if (m.stroke_volume_ml > 0)
      m.regurgitant_fraction_pct = 100.0 * (m.closing_volume_ml + m.leakage_volume_ml) / m.stroke_volume_ml;
  }

  // Pressures, and the difference held across the closed valve [t_closed, t_reopen].
  m.diastolic_dp_mean_mmHg = m.diastolic_dp_peak_mmHg = m.diastolic_dp_held_s = kNaN;
  m.lv_peak_mmHg = m.lv_end_diastolic_mmHg = kNaN;
  m.aortic_systolic_mmHg = m.aortic_diastolic_mmHg = m.aortic_end_diastolic_mmHg = kNaN;
  const double zero = o.pressure_zero;
  if (has(s.lv_pressure)) {
    m.lv_peak_mmHg = (max_in(t, s.lv_pressure, t0, t1) - zero) * mmHg;
    m.lv_end_diastolic_mmHg = (sample(t, s.lv_pressure, t1) - zero) * mmHg;
  }
  if (has(s.aortic_pressure)) {
    m.aortic_systolic_mmHg = (max_in(t, s.aortic_pressure, t0, t1) - zero) * mmHg;
    m.aortic_diastolic_mmHg = (min_in(t, s.aortic_pressure, t0, t1) - zero) * mmHg;
    m.aortic_end_diastolic_mmHg = (sample(t, s.aortic_pressure, t1) - zero) * mmHg;
  }
  if (pressures && closed && t_reopen > t_closed) {
    const Vec back = difference(s.aortic_pressure, s.lv_pressure);
    m.diastolic_dp_mean_mmHg = integrate(t, back, t_closed, t_reopen) / (t_reopen - t_closed) * mmHg;
    m.diastolic_dp_peak_mmHg = max_in(t, back, t_closed, t_reopen) * mmHg;
    // Held: the closed valve's time at or above the hold level, in the window's diastole and in the tail of
    // the previous one the window starts with (a diastole spans the window's end: with a waveform whose
    // valve closes at 0.43-0.46 s of 0.8 s, [t_closed, t1] alone is under 0.4 s; in a periodic state the sum
    // is the whole diastole's).
    double held = 0.0, lead = 0.0;
    integral_where(t, back, back, o.hold_level, t_closed, t_reopen, 1, held);
    if (t_lead > t0) integral_where(t, back, back, o.hold_level, t0, t_lead, 1, lead);
    m.diastolic_dp_held_s = held + lead;
  }

  // Leaflet stress and strain in systole (forward flow) and diastole (closed).
  auto phase_stats = [&](const Vec& v, double a, double b, bool mean) {
    if (!has(v) || !(b > a)) return kNaN;
    return mean ? integrate(t, v, a, b) / (b - a) : max_in(t, v, a, b);
  };
  const double sa = ejection ? tf0 : kNaN, sb = ejection ? tf1 : kNaN;
  const double da = closed ? t_closed : kNaN, db = closed ? t_reopen : kNaN;
  m.stress_systole_peak_kPa = phase_stats(s.stress_max, sa, sb, false) / 1e3;
  m.stress_systole_p95_kPa = phase_stats(s.stress_p95, sa, sb, false) / 1e3;
  m.stress_systole_mean_kPa = phase_stats(s.stress_mean, sa, sb, true) / 1e3;
  m.stress_diastole_peak_kPa = phase_stats(s.stress_max, da, db, false) / 1e3;
  m.stress_diastole_p95_kPa = phase_stats(s.stress_p95, da, db, false) / 1e3;
  m.stress_diastole_mean_kPa = phase_stats(s.stress_mean, da, db, true) / 1e3;
  m.strain_systole_peak = phase_stats(s.strain_max, sa, sb, false);
  m.strain_diastole_peak = phase_stats(s.strain_max, da, db, false);

  // Coaptation while closed: sample means over [t_closed, t_reopen].
  m.pair_names = s.pair_names;
  for (std::size_t p = 0; p < s.pair_names.size(); ++p) {
    m.coaptation_height_mm.push_back(closed ? sample_mean(t, s.coaptation_height[p], da, db) * 1e3 : kNaN);
    m.coaptation_length_mm.push_back(closed ? sample_mean(t, s.coaptation_length[p], da, db) * 1e3 : kNaN);
  }
  m.central_coaptation_height_mm =
      closed && has(s.central_height) ? sample_mean(t, s.central_height, da, db) * 1e3 : kNaN;
  m.effective_height_mm =
      closed && has(s.effective_height) ? sample_mean(t, s.effective_height, da, db) * 1e3 : kNaN;
  for (const Vec& e : s.effective_height_cusp)
    m.effective_height_mm_per.push_back(closed ? sample_mean(t, e, da, db) * 1e3 : kNaN);

  // Gap areas at peak diastolic load: at the sample in the closed phase where p_Ao - p_LV is largest (the
  // first such sample), the central and commissural open areas of the gap_area probe.
  m.peak_load_time_ms = m.central_gap_area_mm2 = m.commissural_gap_area_mm2 = kNaN;
  double t_load = kNaN;
  if (pressures && closed) {
    double best = -std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < t.size(); ++i)
      if (t[i] >= da && t[i] <= db && s.aortic_pressure[i] - s.lv_pressure[i] > best) {
        best = s.aortic_pressure[i] - s.lv_pressure[i];
        t_load = t[i];
      }
    if (!std::isnan(t_load)) m.peak_load_time_ms = (t_load - t0) * 1e3;
  }
  const bool load = !std::isnan(t_load);
  if (has(s.gap_central) && load) {
    m.central_gap_area_mm2 = sample(t, s.gap_central, t_load) * 1e6;
    m.commissural_gap_area_mm2 = 0.0;
  }
  for (const Vec& g : s.gap_commissural) {
    const double a = load ? sample(t, g, t_load) * 1e6 : kNaN;
    m.commissural_gap_area_mm2_per.push_back(a);
    if (has(s.gap_central) && load) m.commissural_gap_area_mm2 += a;
  }

  // Per cusp: the largest max and p95 over the samples of a phase, and the peak's place at that sample.
  auto cusp_phase = [&](std::size_t c, double a, double b) {
    CycleMetrics::CuspStress r{kNaN, kNaN, kNaN, kNaN};
    if (!(b >= a)) return r;
    double best = -1.0, best95 = -1.0;
    for (std::size_t i = 0; i < t.size(); ++i) {
      if (t[i] < a || t[i] > b) continue;
      const double v = s.cusp_stress_max[c][i], v95 = s.cusp_stress_p95[c][i];
      if (!std::isnan(v) && v > best) {
        best = v;
        r.peak_kPa = v / 1e3;
        r.peak_height_mm = s.cusp_peak_height[c][i] * 1e3;
        r.peak_s = s.cusp_peak_s[c][i];
      }
      if (!std::isnan(v95) && v95 > best95) {
        best95 = v95;
        r.p95_kPa = v95 / 1e3;
      }
    }
    return r;
  };
  for (std::size_t c = 0; c < s.cusp_stress_max.size(); ++c) {
    m.cusp_systole.push_back(cusp_phase(c, sa, sb));
    m.cusp_diastole.push_back(cusp_phase(c, da, db));
  }

  // Leaflet-wall distance: the smallest during forward flow (systole).
  m.leaflet_wall_min_systole_mm = has(s.wall_min) && ejection ? min_in(t, s.wall_min, sa, sb) * 1e3 : kNaN;
  for (const Vec& w : s.wall_min_cusp)
    m.leaflet_wall_min_systole_mm_per.push_back(ejection ? min_in(t, w, sa, sb) * 1e3 : kNaN);

  // The fluid's honesty (issue 17 item 3): the largest density error of the cycle, and the acoustic noise of
  // the LV pressure during forward flow (RMS about its 10 ms centred running mean, from samples <= 1 ms
  // apart).
  m.max_density_error_pct = has(s.density_error) ? 100.0 * max_in(t, s.density_error, t0, t1) : kNaN;
  m.volume_ratio_min = has(s.volume_ratio) ? min_in(t, s.volume_ratio, t0, t1) : kNaN;
  m.volume_ratio_max = has(s.volume_ratio) ? max_in(t, s.volume_ratio, t0, t1) : kNaN;
  m.lv_noise_Pa = has(s.lv_pressure) && ejection
                      ? running_mean_rms(t, s.lv_pressure, tf0, tf1, kNoiseWindow, kNoiseMaxSpacing)
                      : kNaN;

  m.sv_change_pct = m.edp_change_pct = kNaN;
  m.periodic = false;
  return m;
}

void periodic_state(const CycleMetrics& prev, CycleMetrics& cur, double tolerance_pct) {
  auto change = [](double a, double b) {
    if (std::isnan(a) || std::isnan(b)) return kNaN;
    const double ref = std::max(std::abs(a), 1e-300);
    return 100.0 * std::abs(b - a) / ref;
  };
  cur.sv_change_pct = change(prev.stroke_volume_ml, cur.stroke_volume_ml);
  cur.edp_change_pct = change(prev.aortic_end_diastolic_mmHg, cur.aortic_end_diastolic_mmHg);
  cur.periodic = cur.sv_change_pct < tolerance_pct && cur.edp_change_pct < tolerance_pct;
}

std::vector<CycleMetrics> all_cycle_metrics(const CycleSignals& s, const CycleOptions& o) {
  std::vector<CycleMetrics> out;
  if (s.t.empty()) return out;
  const auto windows = cycle_windows(s.t.back(), o);
  for (std::size_t k = 0; k < windows.size(); ++k) {
    out.push_back(cycle_metrics(s, windows[k].first, windows[k].second, o));
    out.back().cycle = static_cast<int>(k);
    if (k > 0) periodic_state(out[k - 1], out[k]);
  }
  return out;
}

std::vector<std::pair<std::string, double>> metric_table(const CycleMetrics& m) {
  std::vector<std::pair<std::string, double>> r = {
      {"cycle", m.cycle},
      {"t_start_s", m.t_start},
      {"t_end_s", m.t_end},
      {"stroke_volume_ml", m.stroke_volume_ml},
      {"cardiac_output_l_min", m.cardiac_output_l_min},
      {"peak_forward_flow_ml_s", m.peak_forward_flow_ml_s},
      {"ejection_time_ms", m.ejection_time_ms},
      {"peak_jet_velocity_m_s", m.peak_jet_velocity_m_s},
      {"peak_gradient_mmHg", m.peak_gradient_mmHg},
      {"mean_gradient_mmHg", m.mean_gradient_mmHg},
      {"peak_goa_cm2", m.peak_goa_cm2},
      {"eoa_gorlin_cm2", m.eoa_gorlin_cm2},
      {"eoa_continuity_cm2", m.eoa_continuity_cm2},
      {"opening_time_ms", m.opening_time_ms},
      {"closing_time_ms", m.closing_time_ms},
      {"closing_volume_ml", m.closing_volume_ml},
      {"leakage_volume_ml", m.leakage_volume_ml},
      {"regurgitant_fraction_pct", m.regurgitant_fraction_pct},
      {"diastolic_dp_mean_mmHg", m.diastolic_dp_mean_mmHg},
      {"diastolic_dp_peak_mmHg", m.diastolic_dp_peak_mmHg},
      {"diastolic_dp_held_s", m.diastolic_dp_held_s},
      {"lv_peak_mmHg", m.lv_peak_mmHg},
      {"lv_end_diastolic_mmHg", m.lv_end_diastolic_mmHg},
      {"aortic_systolic_mmHg", m.aortic_systolic_mmHg},
      {"aortic_diastolic_mmHg", m.aortic_diastolic_mmHg},
      {"aortic_end_diastolic_mmHg", m.aortic_end_diastolic_mmHg},
      {"stress_systole_peak_kPa", m.stress_systole_peak_kPa},
      {"stress_systole_p95_kPa", m.stress_systole_p95_kPa},
      {"stress_systole_mean_kPa", m.stress_systole_mean_kPa},
      {"stress_diastole_peak_kPa", m.stress_diastole_peak_kPa},
      {"stress_diastole_p95_kPa", m.stress_diastole_p95_kPa},
      {"stress_diastole_mean_kPa", m.stress_diastole_mean_kPa},
      {"strain_systole_peak", m.strain_systole_peak},
      {"strain_diastole_peak", m.strain_diastole_peak},
  };
  for (std::size_t p = 0; p < m.pair_names.size(); ++p) {
    r.emplace_back("coaptation_height_" + m.pair_names[p] + "_mm", m.coaptation_height_mm[p]);
    r.emplace_back("coaptation_length_" + m.pair_names[p] + "_mm", m.coaptation_length_mm[p]);
  }
  r.emplace_back("central_coaptation_height_mm", m.central_coaptation_height_mm);
  r.emplace_back("effective_height_mm", m.effective_height_mm);
  for (std::size_t c = 0; c < m.effective_height_mm_per.size(); ++c)
    r.emplace_back("effective_height_c" + std::to_string(c) + "_mm", m.effective_height_mm_per[c]);
  r.emplace_back("peak_load_time_ms", m.peak_load_time_ms);
  r.emplace_back("central_gap_area_mm2", m.central_gap_area_mm2);
  r.emplace_back("commissural_gap_area_mm2", m.commissural_gap_area_mm2);
  for (std::size_t c = 0; c < m.commissural_gap_area_mm2_per.size(); ++c)
    r.emplace_back("commissural_gap_area_c" + std::to_string(c) + "_mm2", m.commissural_gap_area_mm2_per[c]);
  for (const char* phase : {"systole", "diastole"}) {
    const auto& cusps = std::string(phase) == "systole" ? m.cusp_systole : m.cusp_diastole;
    for (std::size_t c = 0; c < cusps.size(); ++c) {
      const std::string p = std::string("stress_") + phase + "_", k = "_c" + std::to_string(c);
      r.emplace_back(p + "peak" + k + "_kPa", cusps[c].peak_kPa);
      r.emplace_back(p + "p95" + k + "_kPa", cusps[c].p95_kPa);
      r.emplace_back(p + "peak" + k + "_height_mm", cusps[c].peak_height_mm);
      r.emplace_back(p + "peak" + k + "_s", cusps[c].peak_s);
    }
  }
  r.emplace_back("leaflet_wall_min_systole_mm", m.leaflet_wall_min_systole_mm);
  for (std::size_t c = 0; c < m.leaflet_wall_min_systole_mm_per.size(); ++c)
    r.emplace_back("leaflet_wall_min_systole_c" + std::to_string(c) + "_mm",
                   m.leaflet_wall_min_systole_mm_per[c]);
  r.emplace_back("max_density_error_pct", m.max_density_error_pct);
  r.emplace_back("volume_ratio_min", m.volume_ratio_min);
  r.emplace_back("volume_ratio_max", m.volume_ratio_max);
  r.emplace_back("lv_noise_Pa", m.lv_noise_Pa);
  r.emplace_back("sv_change_pct", m.sv_change_pct);
  r.emplace_back("edp_change_pct", m.edp_change_pct);
  r.emplace_back("periodic", m.cycle == 0 ? kNaN : (m.periodic ? 1.0 : 0.0));
  return r;
}

}  // namespace aortasph
