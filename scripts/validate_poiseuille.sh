#!/usr/bin/env bash
# Poiseuille's law in a pipe of radius R = 4 mm (docs/validation.md, "Stop 51: Poiseuille"): the pipe periodic
# along its axis and driven by a body force (scenes/poiseuille_pipe.json, to 0.12 s) and the open tube driven
# by a pressure inlet against an outflow (scenes/poiseuille_tube.json), each at R = 4, 8 and 12 spacings (the
# tube to 0.4 s, at 12 spacings to 0.16 s); then scripts/poiseuille.py. About 12 min on the quiet 2-core
# machine: the R = 4 and 8 runs two at a time on one thread each (3 min), the R = 12 ones on two threads (5 and
# 4 min). Usage: scripts/validate_poiseuille.sh [BUILD_DIR] [OUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${1:-build}/aortasph
out=${2:-out/validate_poiseuille}
py=${AORTASPH_PYTHON:-/usr/bin/python3}
mkdir -p "$out"
pipe() {  # spacing, threads
  "$bin" run scenes/poiseuille_pipe.json --no-render --quiet --threads "$2" --out "$out/pipe_$1" \
    --set resolution.spacing="$1" > /dev/null
}
tube() {  # spacing, threads, end time; the fluid reaches the outflow buffer's far face: 16 mm + 4 spacings
  local length
  length=$("$py" -c "print(0.016 + 4 * $1)")
  "$bin" run scenes/poiseuille_tube.json --no-render --quiet --threads "$2" --end-time "$3" \
    --out "$out/tube_$1" --set resolution.spacing="$1" --set bodies.0.shape.cylinder.length="$length" > /dev/null
}
pipe 0.001 1 &
tube 0.001 1 0.4
wait
pipe 0.0005 1 &
tube 0.0005 1 0.4
wait
pipe 0.000333333 2
tube 0.000333333 2 0.16
"$py" scripts/poiseuille.py "$out"/pipe_0.001 "$out"/pipe_0.0005 "$out"/pipe_0.000333333 \
  "$out"/tube_0.001 "$out"/tube_0.0005 "$out"/tube_0.000333333
