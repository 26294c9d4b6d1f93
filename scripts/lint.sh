#!/usr/bin/env bash
# Lint (issue 24), run by scripts/test.sh after the Release build:
#  1. clang-format-14 (.clang-format) on every tracked C++ file: a few seconds.
#  2. clang-tidy-14 (.clang-tidy) on the C++ sources changed since a base: about 30 s per source
#     on one core (Eigen), so only the changed ones. The base is $MESHQUILT_LINT_BASE if set,
#     else the merge base with origin/main, else (no origin/main, or the merge base is HEAD, as
#     in a fresh clone of main) HEAD~1; with no parent commit nothing is tidied. The diff is to
#     the work tree, so uncommitted changes are tidied too. A changed header is tidied through
#     its .cpp (or, with none, the first source that includes it); sources not in the
#     compilation database (the fuzz targets, tests/data) are skipped. A test file built as
#     part of a unity source (scripts/test.sh's build) is tidied through that source, its
#     findings in any test file reported.
# Needs $MESHQUILT_LINT_BUILD (default build)/compile_commands.json and the generated kernel
# headers, i.e. a configured and built build directory. Exits non-zero on any finding.
# MESHQUILT_LINT_ALL=1 tidies every source (core/ cli/ host/ tests/ bench/), not the changed ones.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${MESHQUILT_LINT_BUILD:-build}
jobs=${MESHQUILT_LINT_JOBS:-$(nproc)}
status=0

start=$SECONDS
if ! git ls-files -z '*.cpp' '*.h' | xargs -0 clang-format-14 --dry-run --Werror; then
  echo "lint: clang-format: the files above are not formatted (clang-format-14 -i FILE)" >&2
  status=1
fi
echo "lint: clang-format: $(git ls-files '*.cpp' '*.h' | wc -l) files, $((SECONDS - start)) s"

database="$build/compile_commands.json"
if [ ! -f "$database" ]; then
  echo "lint: $database missing: configure and build $build first" >&2
  exit 1
fi
in_database() { grep -qF "\"file\": \"$PWD/$1\"" "$database"; }
# The unity source of the build that includes test file $1, if any.
unity_of() {
  grep -lF "#include \"$PWD/$1\"" "$build"/CMakeFiles/test_*.dir/Unity/*.cxx 2>/dev/null |
    head -1 || true
}

changed=()
if [ "${MESHQUILT_LINT_ALL:-0}" = 1 ]; then
  mapfile -t changed < <(git ls-files 'core/*.cpp' 'cli/*.cpp' 'host/*.cpp' 'tests/*.cpp' \
    'bench/*.cpp')
  echo "lint: clang-tidy: every source of core/ cli/ host/ tests/ bench/"
else
  base=""
  if [ -n "${MESHQUILT_LINT_BASE:-}" ]; then
    base=$(git rev-parse --verify "${MESHQUILT_LINT_BASE}^{commit}")
  elif git rev-parse --verify -q origin/main >/dev/null &&
    merge_base=$(git merge-base HEAD origin/main) &&
    [ "$merge_base" != "$(git rev-parse HEAD)" ]; then
    base=$merge_base
  elif git rev-parse --verify -q 'HEAD~1^{commit}' >/dev/null; then
    base=$(git rev-parse HEAD~1)
  fi
  if [ -z "$base" ]; then
    echo "lint: clang-tidy: no base commit, nothing to tidy"
  else
    echo "lint: clang-tidy: sources changed since $(git log -1 --format='%h %s' "$base" | cut -c1-80)"
    mapfile -t changed < <(git diff --name-only --diff-filter=d "$base" -- '*.cpp' '*.h')
  fi
fi

sources=()
for f in "${changed[@]}"; do
  source=""
  case "$f" in
    *.cpp) source=$f ;;
    *.h)
      if [ -f "${f%.h}.cpp" ]; then
        source=${f%.h}.cpp
      else
        # A header without a .cpp: the first source in the database that includes it.
        while IFS= read -r includer; do
          if in_database "$includer" || [ -n "$(unity_of "$includer")" ]; then
            source=$includer
            break
          fi
        done < <(git grep -l -F "#include \"$f\"" -- '*.cpp' || true)
      fi
      ;;
  esac
  case "$source" in
    tests/*)
      if ! in_database "$source"; then
        source=$(unity_of "$source")
        source=${source#"$PWD/"}
      fi
      ;;
  esac
  if [ -z "$source" ] || ! in_database "$source"; then
    echo "lint: clang-tidy: skipping $f (no source of it in $database)"
    continue
  fi
  case "$source" in
    core/* | cli/* | host/* | tests/* | bench/* | */Unity/*) ;;
    *)
      echo "lint: clang-tidy: skipping $f (not in core/ cli/ host/ tests/ bench/)"
      continue
      ;;
  esac
  sources+=("$source")
done

if [ ${#sources[@]} -gt 0 ]; then
  mapfile -t sources < <(printf '%s\n' "${sources[@]}" | sort -u)
  start=$SECONDS
  # One clang-tidy per source, $jobs at a time; each prints its findings at once when done
  # (so parallel outputs do not interleave) and fails on any (WarningsAsErrors in .clang-tidy).
  # Tests and benchmarks: findings in their own files (a unity source's included .cpp files are
  # not suspicious), without two checks that cost their readability for nothing (building a
  # command line with +, reserving a fixture's few elements).
  # shellcheck disable=SC2016
  if ! printf '%s\0' "${sources[@]}" | xargs -0 -n 1 -P "$jobs" bash -c '
      extra=()
      loose=-performance-inefficient-string-concatenation,-performance-inefficient-vector-operation
      case "$1" in
        tests/* | */Unity/*)
          extra=(--header-filter=tests/ "--checks=-bugprone-suspicious-include,$loose") ;;
        bench/*)
          # Google Benchmark idioms: BM_ names, and the unused _ of "for (auto _ : state)".
          extra=(--header-filter=bench/ "--checks=-clang-analyzer-deadcode.DeadStores,$loose"
            "--config={InheritParentConfig: true, CheckOptions: [{key: readability-identifier-naming.FunctionIgnoredRegexp, value: \"BM_.*\"}]}") ;;
      esac
      if out=$(clang-tidy-14 -p "$0" --quiet "${extra[@]}" "$1" 2>&1); then
        exit 0
      fi
      printf "%s\n%s\n" "lint: clang-tidy: $1:" "$out" | grep -v " warnings\? generated\.$"
      exit 1' "$build"; then
    echo "lint: clang-tidy: findings above (.clang-tidy lists the checks)" >&2
    status=1
  fi
  echo "lint: clang-tidy: ${#sources[@]} sources, $((SECONDS - start)) s"
fi
exit $status
