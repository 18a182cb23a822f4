#!/usr/bin/env bash
# tests/fuzz/run-fuzzers.sh BUILD_DIR — build the parser fuzzers with clang
# (libFuzzer + AddressSanitizer, the library instrumented for coverage) in
# BUILD_DIR and run each for a short time as the meson tests of suite
# 'fuzz', so that the results land in BUILD_DIR/meson-logs/testlog.json.
# FUZZ_TIME (seconds per target, default 20) overrides the run time.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build_dir=${1:?usage: run-fuzzers.sh BUILD_DIR}
cd "$here"
command -v clang >/dev/null || { echo "run-fuzzers: clang not found" >&2; exit 1; }
if [ ! -f "$build_dir/build.ninja" ]; then
  CC=clang meson setup "$build_dir" -Dfuzz=true -Db_sanitize=address -Db_lundef=false \
    -Dbuildtype=debugoptimized -Dc_args=-fsanitize=fuzzer-no-link >/dev/null
else
  meson configure "$build_dir" -Dfuzz=true >/dev/null
fi
ninja -C "$build_dir" -j2 tests/fuzz/fuzz_obj tests/fuzz/fuzz_ply tests/fuzz/fuzz_off \
  tests/fuzz/fuzz_num >&2
# only the fuzz targets are built: the rest of the tree needs no clang build
# a loaded machine stretches the wall clock: the meson timeout (180 s for
# 20 s of fuzzing) grows with FUZZ_TIME
args=()
if [ -n "${FUZZ_TIME:-}" ]; then
  args+=("--test-args=-max_total_time=$FUZZ_TIME" "--timeout-multiplier=$(( FUZZ_TIME / 20 + 1 ))")
fi
meson test -C "$build_dir" --suite fuzz --no-rebuild --num-processes 2 --print-errorlogs "${args[@]}"
