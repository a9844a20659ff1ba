#!/usr/bin/env bash
# Fuzzes scene loading and validation (tests/fuzz/fuzz_scene.cpp) with libFuzzer + ASan + UBSan for SECONDS
# (default 60), starting from tests/fuzz/corpus/ (the project's scenes and every crash found so far).
# Usage: scripts/fuzz.sh [SECONDS] [BUILD_DIR]. Without BUILD_DIR it configures and builds build-fuzz (clang,
# -DAORTASPH_FUZZ=ON, the fuzz target only); with one it builds fuzz_scene in that tree as configured (scripts/test.sh
# passes its clang sanitizer tree, which is configured with -DAORTASPH_FUZZ=ON too).
# Exits non-zero when the fuzzer finds a crash; the input is written to BUILD_DIR/crash-* (fix the bug, then add the
# input to tests/fuzz/corpus/ as a regression case).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
dir=${2:-}
scripts/install-deps.sh --clang
if [ -z "$dir" ]; then
  dir=build-fuzz
  # -O1: the loader is not hot, and the sim library compiles in half the time of -O2.
  cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=Fuzz -DCMAKE_CXX_FLAGS_FUZZ="-O1 -g" -DCMAKE_CXX_COMPILER=clang++ \
    -DAORTASPH_FUZZ=ON -DBUILD_TESTING=OFF > /dev/null
fi
cmake --build "$dir" --target fuzz_scene -j "$(nproc)"
mkdir -p "$dir/corpus"
# New inputs go to $dir/corpus; the committed corpus is only read.
OMP_NUM_THREADS=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 ASAN_OPTIONS=detect_leaks=1 \
  "$dir/tests/fuzz/fuzz_scene" -max_total_time="$seconds" -max_len=8192 -timeout=60 -rss_limit_mb=2048 \
  -print_final_stats=1 -artifact_prefix="$dir/" "$dir/corpus" tests/fuzz/corpus
