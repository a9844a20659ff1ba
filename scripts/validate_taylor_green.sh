#!/usr/bin/env bash
# Taylor-Green vortex at Re = 100 over one decay time (issue 20, docs/validation.md), with the transport
# velocity (Adami et al. 2013) on and off, at lambda/20 and lambda/40. Long (lambda/40 is 12,800 particles
# over ~850 steps): not in CTest. Usage: scripts/validate_taylor_green.sh [BUILD_DIR] (default build).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${1:-build}/tests/aortasph_tests
for n in 20 40; do
  for pb in 1e5 0; do
    echo "== lambda/$n, p_b = $pb"
    N=$n PB=$pb "$bin" "[taylor-green-validate]" | grep -E '^(t=|N=)'
  done
done
