#!/bin/sh
# tools/bench/ingest_memory_sweep.sh — peak memory of `edgespace ingest`
# against the number of meshes: memory must not grow with N.
#
#   tools/bench/ingest_memory_sweep.sh EDGESPACE [N...]
#
# Replicates ../shared/data/face-study (90 meshes of 9,409 vertices, 27,871
# edges) to N rows (the files cycled, each row its own id, so that every row
# is ingested), then runs one ingest into a new store per N under
# /usr/bin/time -v, twice: streamed in blocks (the default) and with
# --block-rows N (every row held in memory before the first write, as ingest
# did before it streamed). Prints N, mode, peak RSS (MB), wall (s), store
# size (MB). Needs ~0.5 MB of disk per row in $TMPDIR. Figures, not tests.
set -eu
exe=${1:?usage: ingest_memory_sweep.sh EDGESPACE [N...]}
shift
[ $# -gt 0 ] || set -- 500 1000 2000 4000 6000
src=$(cd "$(dirname "$0")/../../.." && pwd)/shared/data/face-study
[ -f "$src/manifest.csv" ] || { echo "no $src/manifest.csv" >&2; exit 1; }
[ -x /usr/bin/time ] || { echo "needs /usr/bin/time (Debian package time)" >&2; exit 1; }
tmp=$(mktemp -d "${TMPDIR:-/tmp}/ingest_sweep.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
files=$(tail -n +2 "$src/manifest.csv" | cut -d, -f1)
printf '%6s %-9s %10s %8s %10s\n' N mode peak_MB wall_s store_MB
for n in "$@"; do
    {
        echo "file,id"
        i=0
        while [ "$i" -lt "$n" ]; do
            for f in $files; do
                [ "$i" -lt "$n" ] || break
                echo "$src/$f,r$i"
                i=$((i + 1))
            done
        done
    } > "$tmp/m.csv"
    for mode in streamed one-block; do
        extra=""
        [ "$mode" = one-block ] && extra="--block-rows $n"
        rm -f "$tmp/s.h5"
        # shellcheck disable=SC2086
        /usr/bin/time -v -o "$tmp/time" "$exe" ingest "$tmp/s.h5" --manifest "$tmp/m.csv" \
            -q $extra 2> "$tmp/err" || { echo "ingest failed:" >&2; tail -3 "$tmp/err" >&2; exit 1; }
        kb=$(sed -n 's/.*Maximum resident set size (kbytes): //p' "$tmp/time")
        wall=$(sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): //p' "$tmp/time")
        size=$(stat -c %s "$tmp/s.h5")
        awk -v n="$n" -v m="$mode" -v kb="$kb" -v w="$wall" -v sz="$size" \
            'BEGIN { printf "%6d %-9s %10.1f %8s %10.1f\n", n, m, kb / 1024, w, sz / 1048576 }'
    done
done
