#!/usr/bin/env bash
# Shell validations too slow for the test suite (issue 16; results in docs/validation.md, "Shells"):
#   - the classic clamped circular plate (scenes/shell_plate.json: a = 40 in, t = 1 in, p = 6 psi) at dx = 4t, 2t,
#     t: centre deflection against p a^4 / (64 D) = 2.2189 mm;
#   - the roll-up of a cantilever strip under an end moment 2 pi E I / L (free, and periodic across its width),
#     the cantilever strip's energy over ten periods, and the Scordelis-Lo roof
#     (tests/test_shell.cpp, hidden tag [.shell-validation]);
#   - the hydrostatic water column on an aluminium plate of O'Connor & Rogers 2021 / Fourey et al. 2017
#     (scenes/shell_hydrostatic_fsi.json, quasi-2-D, periodic in z): mid-span deflection, mean over 0.2-1 s,
#     against q L^4 / (384 D) = 7.059e-5 m, and the same plate under the same load as a pressure, no water;
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
# O'Connor & Rogers: the wet run at the scene's dx = t = L/20 (about 4 min on one thread), and the plate alone
# under the same load as a pressure at L/20, L/40 and L/80 (its rows on x = 0 and L: size 1 + dx).
start=$(date +%s)
"$build/aortasph" run scenes/shell_hydrostatic_fsi.json --out "$out/hydrostatic_fsi" --no-render --quiet \
  --threads "$threads"
awk -F, -v s=$(( $(date +%s) - start )) 'NR > 1 && $1 >= 0.2 {u += $3; n++} END {printf "hydrostatic FSI (O'"'"'Connor & Rogers) dx = 0.05 m: mid-span uy = %.5g m (mean 0.2-1 s), ratio to 7.059e-5 m: %.4f (%d s)\n", u / n, -u / n / 7.059022e-5, s}' \
  "$out/hydrostatic_fsi/probes.csv"
grep -o '"fluid_crossings": [0-9]*' "$out/hydrostatic_fsi/run.json"
for dx in 0.05 0.025 0.0125; do
  "$build/aortasph" run scenes/shell_hydrostatic_fsi.json --out "$out/hydrostatic_dry_$dx" --no-render --quiet \
    --threads "$threads" --end-time 0.03 --set resolution.spacing=$dx \
    --set "bodies=[$(python3 -c "import json; b = json.load(open('scenes/shell_hydrostatic_fsi.json'))['bodies'][2]; b['shape']['rectangle']['size'] = [1 + $dx, 0.4]; b['pressure_load'] = -19620; print(json.dumps(b))")]" \
    --set 'probes=[{"name": "mid", "type": "displacement", "body": "plate", "point": [0.5, 0, 0.2]}]'
  tail -1 "$out/hydrostatic_dry_$dx/probes.csv" | awk -F, -v dx=$dx \
    '{printf "the same plate, no water, the load as a pressure, dx = %s m: mid-span uy = %.5g m, ratio %.4f\n", dx, $3, -$3 / 7.059022e-5}'
done
OMP_NUM_THREADS=$threads "$build/tests/aortasph_tests" "[.shell-validation]" 2>&1 | grep -A3 "warning:\|FAILED\|passed\|failed" || true
