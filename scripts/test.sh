#!/usr/bin/env bash
# All tests: install, build (Release), run every test; then an ASan+UBSan build runs the unit tests again.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh build
(cd build && ctest --output-on-failure -j "$(nproc)" --timeout 600)
if [ "${AORTASPH_SKIP_SANITIZE:-0}" != 1 ]; then
  echo "== sanitizer build (ASan + UBSan)"
  scripts/build.sh build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DAORTASPH_SANITIZE=ON
  # Validation-size physics runs are left to the Release pass; everything else runs under the sanitizers.
  (cd build-asan && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
     ctest --output-on-failure -j "$(nproc)" --timeout 900 -E '\[validation\]|Martin|hydrostatic')
fi
