#!/usr/bin/env bash
# The closed valve under a diastolic load, in 0.1 s instead of a cycle's 0.5 s (docs/validation.md, "Stop 53:
# a diastole in 0.1 s"): the physio scene (scenes/aortic_valve_cycle_physio.json) with its LV inlet held at the
# waveform's end-diastolic 8 mmHg (3067 Pa absolute) from t = 0, so that the valve stays closed while the
# Windkessel outlet starts at 80 mmHg; cfl 0.5, probes every 1 ms, VTK every 10 ms; then scripts/diastole.py
# (particle growth, flows through the annulus and the aortic outlet, the aorta's pressure against the
# Windkessel's, blood inside the walls). About 9 min on the quiet 2-core machine. Further arguments go to
# `aortasph run` (e.g. --set materials.blood.shifting=0) to compare a variant with the shipped scene; stop 54's
# steady diastole: --set materials.blood.mask_density=true --set materials.blood.shifting_ale=true --end-time 0.2.
# Usage: scripts/validate_diastole.sh [BUILD_DIR] [OUT_DIR] [run arguments...]
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${1:-build}/aortasph
out=${2:-out/validate_diastole}
shift $(($# < 2 ? $# : 2))
py=${AORTASPH_PYTHON:-/usr/bin/python3}
"$bin" run scenes/aortic_valve_cycle_physio.json --out "$out" --no-render --quiet --threads 2 --end-time 0.1 \
  --vtk --vtk-every 10 --set time.cfl=0.5 --set time.output_interval=0.001 \
  --set open_boundaries.0.pressure=3067 "$@" > /dev/null
"$py" scripts/diastole.py "$out"
