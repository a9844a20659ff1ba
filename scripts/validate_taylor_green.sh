#!/usr/bin/env bash
# Taylor-Green vortex at Re = 100 over one decay time (issue 20, docs/validation.md): the transport velocity
# (Adami et al. 2013) with p_b = 2 rho0 c0^2 on a lattice jittered by 0.2 dx (the set-up that meets the
# target) at lambda/10, 20 and 40, then at lambda/20 the exact lattice and Adami et al.'s p_b = rho0 c0^2,
# and Re = 50 and 200 (NU; numerical against physical dissipation). Long (lambda/40 is 12,800 particles over
# ~870 steps): not in CTest. Usage: scripts/validate_taylor_green.sh [BUILD_DIR] (default build).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${1:-build}/tests/aortasph_tests
run() {
  echo "== $*"
  env "$@" "$bin" "[taylor-green-validate]" | grep -E '^(t=|N=)'
}
for n in 10 20 40; do run N=$n; done
run N=20 JITTER=0
run N=20 PB=1e5
run N=20 PB=0
run N=20 NU=0.02
run N=20 NU=0.005
