#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ with clang (ASan + UBSan) in build-fuzz/ and runs each
# for SECONDS (default 12) from a copy of its seed corpus in fuzz/corpus/. Fails on any finding
# (crash, sanitizer report, leak, a single allocation over 200 MB, an input taking over 5 s);
# the input is kept in build-fuzz/artifacts/. Longer runs: bash scripts/fuzz.sh 3600 (see
# fuzz/README.md). FUZZ_TARGETS="obj ply" runs only those targets (for parallel long runs).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-12}
cmake -S . -B build-fuzz -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DMESHQUILT_FUZZ=ON > build-fuzz.log 2>&1 || { cat build-fuzz.log; exit 1; }
cmake --build build-fuzz -j"$(nproc)" >> build-fuzz.log 2>&1 || { tail -50 build-fuzz.log; exit 1; }
rm -f build-fuzz.log
mkdir -p build-fuzz/artifacts
# One target per core at a time (each libFuzzer run is one process).
run_target() {
  local target=$1 work=build-fuzz/corpus-$1
  mkdir -p "$work"
  cp -n fuzz/corpus/$target/* "$work"/ 2>/dev/null || true
  if UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 ASAN_OPTIONS=detect_leaks=1 \
    build-fuzz/fuzz_$target "$work" -max_total_time="$seconds" -timeout=5 -malloc_limit_mb=200 \
    -rss_limit_mb=1024 -max_len=65536 -artifact_prefix=build-fuzz/artifacts/$target- \
    -print_final_stats=1 2> build-fuzz/$target.log; then
    echo "fuzz: $target for ${seconds} s: $(grep -E "stat::number_of_executed_units" \
      build-fuzz/$target.log | tail -1)"
  else
    tail -40 build-fuzz/$target.log; echo "fuzz: $target: FINDING (see build-fuzz/artifacts/)"
    return 1
  fi
}
pids=()
failed=0
for target in ${FUZZ_TARGETS:-obj ply off keys field mask size quilt}; do
  run_target "$target" &
  pids+=($!)
  if [ "${#pids[@]}" -ge "$(nproc)" ]; then
    wait "${pids[0]}" || failed=1
    pids=("${pids[@]:1}")
  fi
done
for pid in "${pids[@]}"; do wait "$pid" || failed=1; done
[ "$failed" = 0 ] || exit 1
echo "fuzz: no findings"
