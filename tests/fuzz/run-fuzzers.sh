#!/usr/bin/env bash
# tests/fuzz/run-fuzzers.sh BUILD_DIR [SECONDS] — build the fuzz targets with
# clang (libFuzzer + AddressSanitizer, the library instrumented for coverage)
# in BUILD_DIR and run each for a short time as the meson tests of suite
# 'fuzz', so that the results land in BUILD_DIR/meson-logs/testlog.json.
# SECONDS (or FUZZ_TIME) is the time per target; without it each target
# runs the time tests/fuzz/meson.build gives it (20 s, the store opener
# 240 s: what CI runs). The long run is
#     bash tests/fuzz/run-fuzzers.sh build-fuzz 600
# (10 minutes per target, 2 at a time: about an hour). Each target prints
# its executions, coverage (cov:, ft:) and corpus at the end
# (BUILD_DIR/meson-logs/testlog.txt); a crash fails its test and leaves the
# input in BUILD_DIR/tests/fuzz/artifacts-<target>/.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build_dir=${1:?usage: run-fuzzers.sh BUILD_DIR [SECONDS]}
FUZZ_TIME=${2:-${FUZZ_TIME:-}}
cd "$here"
command -v clang >/dev/null || { echo "run-fuzzers: clang not found" >&2; exit 1; }
if [ ! -f "$build_dir/build.ninja" ]; then
  CC=clang meson setup "$build_dir" -Dfuzz=true -Db_sanitize=address -Db_lundef=false \
    -Dbuildtype=debugoptimized -Dc_args=-fsanitize=fuzzer-no-link >/dev/null
else
  meson configure "$build_dir" -Dfuzz=true >/dev/null
fi
targets=(obj ply off num manifest tps lmcsv point formula store crafted)
ninja -C "$build_dir" -j2 "${targets[@]/#/tests/fuzz/fuzz_}" >&2
# only the fuzz targets are built: the rest of the tree needs no clang build
# a loaded machine stretches the wall clock: the meson timeout (180 s for
# 20 s of fuzzing) grows with FUZZ_TIME
args=()
if [ -n "${FUZZ_TIME:-}" ]; then
  args+=("--test-args=-max_total_time=$FUZZ_TIME" "--timeout-multiplier=$(( FUZZ_TIME / 20 + 1 ))")
fi
meson test -C "$build_dir" --suite fuzz --no-rebuild --num-processes 2 --print-errorlogs "${args[@]}"
