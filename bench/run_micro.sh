#!/bin/sh
# Runs every Google Benchmark program (*_bench) of a build directory, five repetitions each,
# keeping only the aggregates (mean, median, stddev, cv), one JSON file per program:
#
#   bench/run_micro.sh [-b BUILD_DIR] OUT_DIR [extra benchmark flags, e.g. --benchmark_filter=X]
#
# Compare two such directories with: bench/compare.py OLD_DIR NEW_DIR
# The build must have MESHQUILT_BUILD_BENCH=ON (and CMAKE_BUILD_TYPE=Release for meaningful times).
set -eu

build=build
if [ "${1:-}" = "-b" ]; then
  [ $# -ge 2 ] || { echo "run_micro.sh: -b needs a directory" >&2; exit 2; }
  build=$2
  shift 2
fi
if [ $# -lt 1 ] || [ "$1" = "-h" ] || [ "$1" = "--help" ]; then
  sed -n '2,8p' "$0" | sed 's/^# \{0,1\}//'
  [ $# -ge 1 ] && exit 0 || exit 2
fi
out=$1
shift

if [ ! -d "$build" ]; then
  echo "run_micro.sh: build directory '$build' not found" >&2
  exit 2
fi
mkdir -p "$out"

found=0
status=0
for program in "$build"/*_bench; do
  [ -f "$program" ] && [ -x "$program" ] || continue
  found=1
  name=$(basename "$program")
  echo "run_micro.sh: $name" >&2
  # JSON goes to a file of its own (--benchmark_out) so nothing the program prints can corrupt it;
  # the console shows the usual table.
  if ! "$program" --benchmark_repetitions=5 --benchmark_report_aggregates_only=true \
      --benchmark_out="$out/$name.json" --benchmark_out_format=json "$@" >&2; then
    echo "run_micro.sh: $name failed" >&2
    status=1
  fi
done
if [ "$found" = 0 ]; then
  echo "run_micro.sh: no *_bench program in '$build' (configure with -DMESHQUILT_BUILD_BENCH=ON)" >&2
  exit 2
fi
echo "run_micro.sh: results in $out" >&2
exit $status
