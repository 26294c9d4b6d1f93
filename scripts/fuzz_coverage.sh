#!/usr/bin/env bash
# Source-based line coverage of each reader by the corpus its fuzz target has grown
# (build-fuzz/corpus-TARGET, from scripts/fuzz.sh): builds build-fuzz-coverage/ with clang's
# -fprofile-instr-generate, replays the corpus once (-runs=0), and prints, per target, the line
# coverage of the functions that parse its format. Needs llvm-profdata-14 and llvm-cov-14 (Debian
# llvm-14, which clang depends on).
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-fuzz-coverage -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DMESHQUILT_FUZZ=ON -DMESHQUILT_FUZZ_COVERAGE=ON > build-fuzz-coverage.log 2>&1 ||
  { cat build-fuzz-coverage.log; exit 1; }
cmake --build build-fuzz-coverage -j"$(nproc)" >> build-fuzz-coverage.log 2>&1 ||
  { tail -50 build-fuzz-coverage.log; exit 1; }
rm -f build-fuzz-coverage.log
# The functions that parse each format (core/mesh/mesh_io.cpp, core/surface/tangent_field.cpp),
# matched against demangled names: each reader's own code, its lambdas and (PLY) its helper types;
# the text cursor the text formats share is not counted (each format uses only part of it).
declare -A parsers=(
  [obj]='::read_obj\('
  [ply]='::read_ply\(|::Ply|::parse_ply|::ply_'
  [off]='::read_off\('
  [keys]='read_key_vectors'
  [field]='read_vertex_vector_field'
  [mask]='parse_surface_mask'
  [size]='parse_size_map')
for target in ${FUZZ_TARGETS:-obj ply off keys field mask size}; do
  corpus=build-fuzz/corpus-$target
  [ -d "$corpus" ] || corpus=fuzz/corpus/$target
  out=build-fuzz-coverage/$target
  mkdir -p "$out"
  LLVM_PROFILE_FILE="$out/%p.profraw" ASAN_OPTIONS=detect_leaks=0 \
    build-fuzz-coverage/fuzz_$target "$corpus" -runs=0 > "$out/replay.log" 2>&1
  llvm-profdata-14 merge -sparse "$out"/*.profraw -o "$out/merged.profdata"
  files=$(find "$corpus" -type f | wc -l)
  # One row per function: name, regions..., lines, missed lines, cover.
  llvm-cov-14 report build-fuzz-coverage/fuzz_$target -instr-profile="$out/merged.profdata" \
    -show-functions core/mesh/mesh_io.cpp core/surface/tangent_field.cpp 2>/dev/null | c++filt -n |
    awk -v re="${parsers[$target]}" -v t="$target" -v n="$files" '
      $0 ~ re && NF >= 10 { lines += $(NF-5); missed += $(NF-4); fns++ }
      END { if (lines > 0) printf "fuzz coverage: %s: %d corpus files, %d parser functions, %d of %d lines (%.1f%%)\n", t, n, fns, lines - missed, lines, 100 * (lines - missed) / lines;
            else printf "fuzz coverage: %s: no parser functions matched\n", t }'
done
