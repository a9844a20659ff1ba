#!/usr/bin/env bash
# All tests: install, then a clang ASan+UBSan build runs the unit tests (left out: validation-size physics runs,
# the aortic root in flow, [long] cases, runs of thousands of steps whose code paths shorter cases cover under
# the sanitizers, and [heavy] cases: nine that took 10-30 s each there at stop 23 (136 s of the step's 298 s),
# and nine more at stop 24 (the RCR outlet's ODE run, the parabolic tube, the SIGKILL resume, the shell-contact
# thread comparison, then the commissure posts 40 s, the fluid-and-block checkpoint 25 s, the mirror-leaflet
# geometry 15 s and two shell-contact rests 14 and 13 s, measured on the quiet machine; at stop 27 the shell
# leaflets' half-spacing case 49 s, the rotated-commissure geometry 32 s and `aortasph check` of the aortic
# scenes 33 s, on a loaded machine; at stop 34 six 1-vs-2-thread comparisons, 48 s of shard time, which
# ThreadSanitizer and the Release step check, and the light-sheet barrier case, 16 s; at stop 45 the
# deep-buffer list audit, 30 s, the pressure inlet beside an off-lattice wall, 26 s, the soft blocks' contact,
# 15 s, and the barrier beside a free edge's plane, 13 s, CI having taken 936 s; at stop 55 the resume to a
# later end, 13 s; at stop 60 the mask_density sluice, 55 s, whose 28 ms start covers the code, CI having taken
# 976 s),
# each while other cases cover its code under the sanitizers; they all run in the Release step), a
# ThreadSanitizer build runs the simulation-render pipeline test, a bounded libFuzzer run
# fuzzes the scene loader (scripts/fuzz.sh, built in the same clang sanitizer tree), then the Release build (GCC)
# runs every test through CTest. The validation-size
# cases (tag [.validation], hidden from CTest: rigid blocks sinking and floating, the TL-SPH cantilever's energy
# and period, its large deformation, the flexible pole) run in scripts/validate.sh instead.
# AORTASPH_SKIP_SANITIZE=1, AORTASPH_SKIP_TSAN=1, AORTASPH_SKIP_FUZZ=1 leave a step out.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh --clang
# One clang tree for the sanitizers and the fuzz target (-DAORTASPH_FUZZ=ON with AORTASPH_SANITIZE: the fuzz
# target's own sources carry libFuzzer's coverage hooks): one build instead of two (2 min 55 s on 2 cores, stop
# 14), and clang compiles faster than GCC here (solid_tlsph.cpp under ASan: 31 s of CPU against 44 s).
# -g0: the sanitizers' reports name functions from the symbol table but give no file:line (rebuild with -g1 to
# get them); line tables cost 17 % of the tree's compile time (test_aortic.cpp: 34.7 s of CPU with -g1, 28.8 s
# without, stop 24). At -O0 the test files compile 2.5x faster but the cases ran 5-20x slower: tried, not used.
sanitize_tree() {
  scripts/build.sh build-san -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=ASan -DCMAKE_CXX_FLAGS_ASAN="-O1 -g0" \
    -DAORTASPH_SANITIZE=ON -DAORTASPH_FUZZ=ON
}
fuzz_run() { scripts/fuzz.sh "${AORTASPH_FUZZ_SECONDS:-40}" build-san; }
fuzzed=0
if [ "${AORTASPH_SKIP_SANITIZE:-0}" != 1 ]; then
  echo "== sanitizer build (clang, ASan + UBSan): unit tests"
  sanitize_tree
  # The unit cases run as two single-threaded shards side by side (alternate cases in declaration order), and the
  # fuzzer (one process, one thread, a fixed wall time) beside them: three single-threaded processes keep both
  # cores busy, where one two-thread process left them partly idle. Two-thread OpenMP teams beside other work
  # would spin against it (see the CTest step below). Cases that compare thread counts set their own.
  filter="~[validation]~[flow]~[long]~[heavy]~[.]"
  # (--list-test-names-only exits with the number of cases it listed: hence the `|| true`s; the count check
  # below catches a listing that went wrong.)
  { ./build-san/tests/aortasph_tests --list-test-names-only "$filter" || true; } | awk 'NF' > build-san/asan-cases.txt
  pids=()
  if [ "${AORTASPH_SKIP_FUZZ:-0}" != 1 ]; then
    echo "== fuzzing the scene loader for ${AORTASPH_FUZZ_SECONDS:-40} s beside the unit tests (build-san/fuzz.log)"
    fuzz_run > build-san/fuzz.log 2>&1 &
    fuzz_pid=$!
    fuzzed=1
  fi
  # The two shards get equal shares of the cases' ASan times in tests/asan-durations.txt (seconds, a tab, the
  # case's name, from the shards' --durations logs of a quiet run; a case not listed counts 2 s), the longest
  # first, each to the shard with less so far (stop 45: alternating cases gave 155 and 117 s; this split 136
  # and 136 s of the same times). Regenerate after adding or moving long cases:
  #   cat build-san/asan-shard[01].log | grep -E '^[0-9.]+ s: ' | sed -E 's/^([0-9.]+) s: /\1\t/' \
  #     > tests/asan-durations.txt
  rm -f build-san/asan-names0.txt build-san/asan-names1.txt
  touch build-san/asan-names0.txt build-san/asan-names1.txt
  durations=tests/asan-durations.txt
  [ -f "$durations" ] || durations=/dev/null  # then every case counts 2 s: an even split by count
  awk -F'\t' 'FILENAME == ARGV[1] { d[$2] = $1; next } { printf "%s\t%s\n", ($0 in d) ? d[$0] : 2, $0 }' \
    "$durations" build-san/asan-cases.txt | sort -t"$(printf '\t')" -k1,1 -g -r |
    awk -F'\t' '{ if (s0 <= s1) { s0 += $1; print $2 > "build-san/asan-names0.txt" }
                  else { s1 += $1; print $2 > "build-san/asan-names1.txt" } }'
  for k in 0 1; do
    # Catch2 reads one test name per line; its spec syntax needs , [ ] * \ " escaped.
    # --durations: each case's time goes into the shard's log (build-san/asan-shard0.log, ...), to find what to
    # keep out of the shards when the step grows.
    sed 's/[][,\\*"]/\\&/g' build-san/asan-names$k.txt > build-san/asan-shard$k.txt
    OMP_NUM_THREADS=1 ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
      ./build-san/tests/aortasph_tests --durations yes -f build-san/asan-shard$k.txt > build-san/asan-shard$k.log 2>&1 &
    pids+=($!)
  done
  listed=$(cat build-san/asan-shard0.txt build-san/asan-shard1.txt |
    { ./build-san/tests/aortasph_tests --list-test-names-only -f /dev/stdin || true; } | awk 'NF' | wc -l)
  failed=0
  for k in 0 1; do
    if wait "${pids[$k]}"; then
      echo "shard $k: $(grep -E '^(All tests passed|test cases)' build-san/asan-shard$k.log | tail -n 1)"
    else
      cat build-san/asan-shard$k.log
      failed=1
    fi
  done
  if [ "$fuzzed" = 1 ]; then
    if wait "$fuzz_pid"; then grep -E '^(Done|stat::)' build-san/fuzz.log; else cat build-san/fuzz.log; failed=1; fi
  fi
  if [ "$listed" != "$(wc -l < build-san/asan-cases.txt)" ]; then
    echo "the ASan shards hold $listed cases, the filter $(wc -l < build-san/asan-cases.txt)"
    failed=1
  fi
  [ "$failed" = 0 ] || exit 1
fi
if [ "${AORTASPH_SKIP_TSAN:-0}" != 1 ]; then
  # Only the simulation-render pipeline test, built alone (sim + render + one test file): a few minutes. -g0 as
  # in the ASan tree (stop 45): reports name functions, not lines; rebuild with -g1 for file:line.
  echo "== ThreadSanitizer build: simulation-render pipeline test (${SECONDS} s so far)"
  cmake -S . -B build-tsan -DCMAKE_BUILD_TYPE=TSan -DCMAKE_CXX_FLAGS_TSAN="-O1 -g0" -DAORTASPH_TSAN=ON > /dev/null
  cmake --build build-tsan --target aortasph_tsan_tests -j "$(nproc)"
  # LP_NUM_THREADS=0: llvmpipe draws on the render thread itself. Its own worker threads synchronise in ways
  # ThreadSanitizer cannot see (reports inside libOSMesa only); frames are identical either way (DESIGN.md).
  LP_NUM_THREADS=0 TSAN_OPTIONS=halt_on_error=1 ./build-tsan/tests/aortasph_tsan_tests
fi
if [ "${AORTASPH_SKIP_FUZZ:-0}" != 1 ] && [ "$fuzzed" = 0 ]; then
  echo "== fuzzing the scene loader for ${AORTASPH_FUZZ_SECONDS:-40} s (libFuzzer, clang; ${SECONDS} s so far)"
  [ -x build-san/tests/aortasph_tests ] || sanitize_tree
  fuzz_run
fi
echo "== release build: all tests (${SECONDS} s so far)"
scripts/build.sh build
# One OpenMP thread per test, as many tests at once as there are cores: OpenMP teams that share cores spin
# against each other (a 32 s test took 152 s beside another two-thread test). Tests that compare thread counts
# set their own.
(cd build && OMP_NUM_THREADS=1 ctest --output-on-failure -j "$(nproc)" --timeout 900)
echo "== all tests passed in ${SECONDS} s"
