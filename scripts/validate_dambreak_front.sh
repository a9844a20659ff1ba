#!/usr/bin/env bash
# Why the Martin & Moyce dam-break front leads (issue 20 item 1; docs/validation.md, "Why the front leads"):
# the runs behind the tables there, one change at a time, each printed by scripts/dambreak_front.py.
# Usage: scripts/validate_dambreak_front.sh [BUILD_DIR] [OUT_DIR]   (about 10 min on 2 loaded cores)
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${1:-build}/aortasph
out=${2:-out/validate_dambreak_front}
mkdir -p "$out"
run() {  # name, options
  local name=$1
  shift
  scripts/dambreak_front.py "$bin" "$out/$name" "$@" --threads 2 | tee "$out/$name.txt"
}
run a10 --div 10
run a20 --div 20
run a30 --div 30
run a10_free_slip --div 10 --slip free_slip
run a20_free_slip --div 20 --slip free_slip
run a30_free_slip --div 30 --slip free_slip
run a10_delta0 --div 10 --delta 0
run a20_delta0 --div 20 --delta 0
run a10_depth8 --div 10 --depth 8
run a10_c0x2 --div 10 --c0-factor 20
run a10_h16 --div 10 --smoothing 1.6
run a10_gate1 --div 10 --gate 1
run a10_gate2 --div 10 --gate 2
