#!/usr/bin/env bash
# All tests: install, then an ASan+UBSan build runs the unit tests (validation-size physics runs left out: they
# take minutes under the sanitizers), then the Release build runs every test through CTest.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
if [ "${AORTASPH_SKIP_SANITIZE:-0}" != 1 ]; then
  echo "== sanitizer build (ASan + UBSan): unit tests"
  scripts/build.sh build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DAORTASPH_SANITIZE=ON
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ./build-asan/tests/aortasph_tests "~[validation]"
fi
echo "== release build: all tests"
scripts/build.sh build
(cd build && ctest --output-on-failure -j "$(nproc)" --timeout 900)
