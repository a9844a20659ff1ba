#!/usr/bin/env bash
# Particle shifting with open boundaries (docs/validation.md, "Stop 44: the shift counted in the density"):
# scenes/tube_shift_packing.json three times, unshifted, shifted with the density ignoring the shift (the
# default, shifting_ale false) and shifted with the shift counted in the density, then the counts in the tube's
# core at each 25 ms frame (scripts/shift_packing.py). About 3 min per run on one core; the runs go side by
# side on $JOBS cores (default 2).
# Usage: scripts/validate_shift_packing.sh [BUILD_DIR] [OUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${1:-build}/aortasph
out=${2:-out/validate_shift_packing}
py=${AORTASPH_PYTHON:-/usr/bin/python3}
jobs=${JOBS:-2}
mkdir -p "$out"
run() {
  local name=$1
  shift
  "$bin" run scenes/tube_shift_packing.json --no-render --vtk --quiet --threads 1 --out "$out/$name" "$@"
}
run unshifted --set materials.blood.shifting=0 &
[ "$jobs" -gt 1 ] || wait
run density_ignores_shift &
wait
run shift_in_density --set materials.blood.shifting_ale=true
"$py" scripts/shift_packing.py "$out/unshifted" "$out/density_ignores_shift" "$out/shift_in_density"
