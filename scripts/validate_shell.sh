#!/usr/bin/env bash
# Shell validations too slow for the test suite (issue 16; results in docs/validation.md, "Shells"):
#   - the classic clamped circular plate (scenes/shell_plate.json: a = 40 in, t = 1 in, p = 6 psi) at dx = 4t, 2t,
#     t: centre deflection against p a^4 / (64 D) = 2.2189 mm;
#   - the roll-up of a cantilever strip under an end moment 2 pi E I / L, and the Scordelis-Lo roof
#     (tests/test_shell.cpp, hidden tag [.shell-validation]);
#   - a water column on a clamped square plate (one side) and a plate window between two columns (both
#     sides) against the clamped-plate formula (tests/test_shell_fluid.cpp), and the three shell aortic leaflets
#     under 80 mmHg without fluid (tests/test_shell_leaflet.cpp), the same hidden tag.
# Usage: scripts/validate_shell.sh   (BUILD_DIR=build, THREADS=1, OUT=out/validate_shell)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD_DIR:-build}
threads=${THREADS:-1}
out=${OUT:-out/validate_shell}
mkdir -p "$out"
for dx in 0.1016 0.0508 0.0254; do
  start=$(date +%s)
  "$build/aortasph" run scenes/shell_plate.json --set resolution.spacing=$dx --out "$out/plate_$dx" --no-render \
    --quiet --threads "$threads"
  tail -1 "$out/plate_$dx/probes.csv" | awk -F, -v dx=$dx -v s=$(( $(date +%s) - start )) \
    '{printf "clamped plate dx = %s m (%.0f t): centre uz = %.5g m, ratio to p a^4/(64 D) = 2.2189e-3 m: %.4f (%d s)\n", dx, dx / 0.0254, $4, $4 / 2.2189e-3, s}'
done
OMP_NUM_THREADS=$threads "$build/tests/aortasph_tests" "[.shell-validation]" 2>&1 | grep -A3 "warning:\|FAILED\|passed\|failed" || true
