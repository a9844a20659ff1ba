#!/usr/bin/env bash
# Lobovsky et al. (2014) dam break, H = 300 mm (issue 20 item 5; docs/validation.md, "Dam break against
# Lobovsky et al. 2014"): scenes/dam_break_lobovsky.json at H/20, H/30 and H/40 (the shipped spacing), quasi-2-D
# (periodic across a slab 8 spacings wide), then the first impact at the four wall sensors against the measured
# one by scripts/lobovsky.py, raw and as the 1 ms running mean, with a plot.
# Usage: scripts/validate_lobovsky.sh [BUILD_DIR] [OUT_DIR] [DIVISIONS...]
#   (H/20 ~2 min, H/30 ~5 min, H/40 ~12 min on 2 cores; extra run options in $LOBOVSKY_ARGS)
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${1:-build}/aortasph
out=${2:-out/validate_lobovsky}
shift $(($# > 2 ? 2 : $#))
divs=("$@")
[ ${#divs[@]} -gt 0 ] || divs=(20 30 40)
py=${AORTASPH_PYTHON:-/usr/bin/python3}
mkdir -p "$out"
runs=()
for n in "${divs[@]}"; do
  # The scene's domain holds the tank's 3 wall layers down to H/15 (layers of 20 mm within its 60 mm margin).
  if ! [[ "$n" =~ ^[0-9]+$ ]] || [ "$n" -lt 15 ]; then
    echo "validate_lobovsky.sh: $n: give divisions of H of at least 15 (H/15 = 20 mm spacing)" >&2
    exit 2
  fi
  dx=$("$py" -c "print(0.3 / $n)")
  width=$("$py" -c "print(8 * 0.3 / $n)")  # the periodic slab: 8 spacings (at least 7.15 are needed)
  sets=(--set "resolution.spacing=$dx" --set "domain.max.2=$width" --set "bodies.0.shape.box.max.2=$width"
    --set "bodies.1.shape.container.max.2=$width")
  for k in 0 1 2 3; do sets+=(--set "probes.$k.point.2=$("$py" -c "print($width / 2)")"); done
  # shellcheck disable=SC2086
  "$bin" run scenes/dam_break_lobovsky.json --no-render --quiet --threads 2 --out "$out/h$n" "${sets[@]}" \
    ${LOBOVSKY_ARGS:-}
  runs+=("$out/h$n:H/$n")
done
"$py" scripts/lobovsky.py "${runs[@]}" --png "$out/lobovsky_raw.png" --json "$out/lobovsky_raw.json" |
  tee "$out/lobovsky_raw.txt"
"$py" scripts/lobovsky.py "${runs[@]}" --smooth 1 --png "$out/lobovsky_1ms.png" --json "$out/lobovsky_1ms.json" |
  tee "$out/lobovsky_1ms.txt"
