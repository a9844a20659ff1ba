#!/usr/bin/env python3
"""Generates scenes/waveforms/lv_pressure.csv: a normal human left-ventricular pressure waveform, 75 bpm.

Model (a lumped, time-varying elastance model of the left heart; no data are fitted):
  - LV: P_lv = E(t) (V_lv - V0), E(t) = (Emax - Emin) En(t / Tmax) + Emin, with the normalised elastance
    "double Hill" curve of Stergiopulos, Meister & Westerhof 1996, "Determinants of stroke volume and systolic
    and diastolic aortic pressure", Am. J. Physiol. 270:H2050-H2059:
        En(tn) = 1.55 [(tn / 0.7)^1.9 / (1 + (tn / 0.7)^1.9)] [1 / (1 + (tn / 1.17)^21.9)],
    Tmax = 0.41 s: chosen so that the ejection lasts the normal left-ventricular ejection time at 75 bpm,
    0.29 s (Weissler, Harris & Schoenfeld 1968, Circulation 37:149, LVET = 0.413 s - 0.0017 s x HR for men);
    with the often used Tmax = 0.2 + 0.15 T = 0.32 s the ejection lasts only 0.23 s.
  - Emax = 1.8 mmHg/ml (a normal end-systolic elastance, 1-3 mmHg/ml), Emin = 0.06 mmHg/ml, V0 = 10 ml, the
    left atrium at 8.5 mmHg: chosen (not fitted) so that the LV peaks near 120 mmHg and fills to 8 mmHg.
  - Mitral and aortic valves: ideal diodes with small resistances; the left atrium a constant filling pressure.
  - Arterial load: the three-element Windkessel (Westerhof, Lankhaar & Westerhof 2009, "The arterial
    Windkessel", Med. Biol. Eng. Comput. 47:131-141) with the normal systemic values that docs/scenes.md
    ships (R_p 0.05, C 1.6 ml/mmHg, R_d 1.05 mmHg s/ml, venous pressure 0).
The ODEs (dV_lv/dt = Q_mv - Q_ao, C dP_c/dt = Q_ao - P_c / R_d) are integrated with the classical Runge-Kutta
scheme at 20 us for 12 beats (periodic to < 0.01 mmHg); the last beat, sampled every 5 ms from the onset of
contraction (end diastole, t = 0), is written in mmHg. The resulting numbers (peak and end-diastolic LV
pressure, aortic pressures, stroke volume, ejection time) are printed and written into the file's header;
compare them with the normal values of the Wiggers diagram (Guyton & Hall, Textbook of Medical Physiology,
13th ed. 2016, fig. 9-6: LV 120/0-8 mmHg, aorta 120/80, stroke volume about 70 ml, ejection about 0.3 s at
75 bpm).

Usage: scripts/lv_waveform.py [OUT.csv]   (default: scenes/waveforms/lv_pressure.csv)
"""
import os
import sys

# Heart: 75 bpm.
T = 0.8  # s
TMAX = 0.41  # s, time of peak elastance (see above)
EMAX = 1.8  # mmHg/ml, end-systolic elastance
EMIN = 0.06  # mmHg/ml, diastolic elastance
V0 = 10.0  # ml, unstressed volume
P_LA = 8.5  # mmHg, left-atrial (filling) pressure
R_MV = 0.005  # mmHg s/ml, open mitral valve
R_AV = 0.003  # mmHg s/ml, open aortic valve
# Arterial load, RCR (docs/scenes.md).
R_P, C, R_D, P_V = 0.05, 1.6, 1.05, 0.0

DT = 2e-5
BEATS = 12
SAMPLE = 0.005


def elastance(t):
    tn = (t % T) / TMAX
    a = (tn / 0.7) ** 1.9
    en = 1.55 * (a / (1.0 + a)) * (1.0 / (1.0 + (tn / 1.17) ** 21.9))
    return (EMAX - EMIN) * en + EMIN


def flows(t, v, pc):
    p_lv = elastance(t) * (v - V0)
    q_ao = max(p_lv - pc, 0.0) / (R_AV + R_P)
    q_mv = max(P_LA - p_lv, 0.0) / R_MV
    return p_lv, q_ao, q_mv


def rhs(t, v, pc):
    _, q_ao, q_mv = flows(t, v, pc)
    return q_mv - q_ao, (q_ao - (pc - P_V) / R_D) / C


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "scenes", "waveforms", "lv_pressure.csv")
    v, pc, t = 120.0, 80.0, 0.0
    steps = int(round(T / DT))
    every = int(round(SAMPLE / DT))
    for beat in range(BEATS):
        rows = []
        p_ao_max, p_ao_min, sv, ejecting = -1e9, 1e9, 0.0, 0.0
        p_lv_max, p_lv_min = -1e9, 1e9
        edp = None
        for k in range(steps):
            p_lv, q_ao, _ = flows(t, v, pc)
            p_ao = pc + R_P * q_ao
            if k % every == 0:
                rows.append((k * DT, p_lv))
            if k == 0:
                edp = p_lv
            p_lv_max, p_lv_min = max(p_lv_max, p_lv), min(p_lv_min, p_lv)
            p_ao_max, p_ao_min = max(p_ao_max, p_ao), min(p_ao_min, p_ao)
            sv += q_ao * DT
            if q_ao > 0.0:
                ejecting += DT
            k1 = rhs(t, v, pc)
            k2 = rhs(t + DT / 2, v + DT / 2 * k1[0], pc + DT / 2 * k1[1])
            k3 = rhs(t + DT / 2, v + DT / 2 * k2[0], pc + DT / 2 * k2[1])
            k4 = rhs(t + DT, v + DT * k3[0], pc + DT * k3[1])
            v += DT / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
            pc += DT / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
            t = (beat * steps + k + 1) * DT
    summary = ("LV %.1f / %.1f mmHg (peak / end-diastolic; minimum %.1f), aorta %.1f / %.1f mmHg, stroke volume "
               "%.1f ml, ejection %.3f s" % (p_lv_max, edp, p_lv_min, p_ao_max, p_ao_min, sv, ejecting))
    print(summary)
    with open(out, "w") as f:
        f.write("# source: time-varying elastance model of the left ventricle (Stergiopulos, Meister & Westerhof "
                "1996, Am. J. Physiol. 270:H2050, double-Hill elastance) loaded by an RCR Windkessel (Westerhof "
                "et al. 2009), generated by scripts/lv_waveform.py\n")
        f.write("# parameters: T %g s (75 bpm), Tmax %g s, Emax %g mmHg/ml, Emin %g mmHg/ml, V0 %g ml, left atrium "
                "%g mmHg, R_mv %g, R_av %g, R_p %g mmHg s/ml, C %g ml/mmHg, R_d %g mmHg s/ml\n"
                % (T, TMAX, EMAX, EMIN, V0, P_LA, R_MV, R_AV, R_P, C, R_D))
        f.write("# result: %s; t = 0 is the onset of contraction (end diastole); repeat with period %g s\n"
                % (summary, T))
        f.write("time_s,lv_pressure_mmHg\n")
        for tt, p in rows:
            f.write("%.3f,%.3f\n" % (tt, p))


if __name__ == "__main__":
    main()
