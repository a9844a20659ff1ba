#!/usr/bin/env bash
# Fuzzes scene loading and validation (tests/fuzz/fuzz_scene.cpp) with libFuzzer + ASan + UBSan for SECONDS
# (default 60), starting from tests/fuzz/corpus/ (the project's scenes and every crash found so far).
# Usage: scripts/fuzz.sh [SECONDS]. Exits non-zero when the fuzzer finds a crash; the input is written to
# build-fuzz/crash-* (fix the bug, then add the input to tests/fuzz/corpus/ as a regression case).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
packages=(clang libclang-rt-14-dev libomp-14-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  echo "fuzz: installing ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
# -O1: the loader is not hot, and the sim library compiles in half the time of -O2.
cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=Fuzz -DCMAKE_CXX_FLAGS_FUZZ="-O1 -g" -DCMAKE_CXX_COMPILER=clang++ \
  -DAORTASPH_FUZZ=ON -DBUILD_TESTING=OFF > /dev/null
cmake --build build-fuzz --target fuzz_scene -j "$(nproc)"
mkdir -p build-fuzz/corpus
# New inputs go to build-fuzz/corpus; the committed corpus is only read.
OMP_NUM_THREADS=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 ASAN_OPTIONS=detect_leaks=1 \
  ./build-fuzz/tests/fuzz/fuzz_scene -max_total_time="$seconds" -max_len=8192 -timeout=60 -rss_limit_mb=2048 \
  -print_final_stats=1 -artifact_prefix=build-fuzz/ build-fuzz/corpus tests/fuzz/corpus
