#!/usr/bin/env bash
# tools/bench/bench_commands.sh — the embedding commands as a user runs them,
# each a fresh process, timed side by side for two builds of edgespace (this
# one and an earlier commit's), in one run on the same store: CPU (user +
# system) and wall seconds of
#   - embed of the points a study looks at (mean, mean -/+ 2 sd on PCs 1-3,
#     a held-out mesh file), each once to make the per-store cache and then
#     timed (a build without the cache just runs it again);
#   - a 20-frame walk along PC 1 (interp mean-1.5 sd -> mean+1.5 sd);
#   - variation --pcs 1,2,3 and export --statismo --pca.
# Prints a table with the ratio old / new. Run it with nothing else on the
# machine (check the load average first).
#
#   bash tools/bench/bench_commands.sh NEW_BUILD OLD_BUILD [DATASET_DIR]
#     DATASET_DIR: ../shared/data/face-study by default; its last subject is
#     held out of the store and embedded from its file.
set -euo pipefail
new=$(cd "$1" && pwd)/tools/edgespace
old=$(cd "$2" && pwd)/tools/edgespace
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
data=${3:-$here/../shared/data/face-study}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# the store: every mesh but the last subject's three
mapfile -t files < <(ls "$data"/*.obj | sort)
held=${files[-1]}
{
    echo "file"
    for f in "${files[@]:0:${#files[@]}-3}"; do echo "$f"; done
} > "$work/manifest.csv"
# each build makes its own store (a build reads the store formats of its own
# release and before: format 3 keeps results in files beside the store)
for b in new old; do
    "${!b}" ingest "$work/$b.h5" --manifest "$work/manifest.csv" > /dev/null
    "${!b}" pca "$work/$b.h5" --name default --components 5 > /dev/null
done
echo "# $(basename "$data"): $(( ${#files[@]} - 3 )) rows; load average $(cut -d' ' -f1-3 /proc/loadavg)"
printf "%-44s %18s %18s %8s %8s\n" "command" "new cpu / wall" "old cpu / wall" "cpu old/new" "wall"

# seconds of user+system CPU and wall of one command (output discarded)
timed() {
    if ! /usr/bin/time -f "%U %S %e" -o "$work/t" "$@" > /dev/null 2> "$work/err"; then
        echo "failed: $* ($(tail -1 "$work/err"))" >&2
        echo "nan nan"
        return
    fi
    awk '{printf "%.3f %.3f\n", $1 + $2, $3}' "$work/t"
}

compare() {
    local what=$1 store_new=$2 store_old=$3; shift 3
    local -a args=("$@")
    "$new" "${args[0]}" "$store_new" "${args[@]:1}" > /dev/null 2>&1 || true   # makes the cache
    read -r nc nw < <(timed "$new" "${args[0]}" "$store_new" "${args[@]:1}")
    read -r oc ow < <(timed "$old" "${args[0]}" "$store_old" "${args[@]:1}")
    printf "%-44s %8s / %-8s %8s / %-8s %8s %8s\n" "$what" "$nc" "$nw" "$oc" "$ow" \
        "$(awk -v a="$oc" -v b="$nc" 'BEGIN{printf "%.2f", a / b}')" \
        "$(awk -v a="$ow" -v b="$nw" 'BEGIN{printf "%.2f", a / b}')"
}

for p in "mean" "mean - 2*pc:1" "mean + 2*pc:1" "mean - 2*pc:2" "mean + 2*pc:2" \
         "mean - 2*pc:3" "mean + 2*pc:3" "file:$held"; do
    label=$p
    [ "${p#file:}" != "$p" ] && label="file:$(basename "$held")"
    compare "embed $label" "$work/new.h5" "$work/old.h5" embed --point "$p" -o "$work/x.obj" \
        --no-store
done
compare "interp 20 frames along PC 1" "$work/new.h5" "$work/old.h5" interp \
    --from "mean - 1.5*pc:1" --to "mean + 1.5*pc:1" --steps 20 -o "$work/f_%02d.obj" --no-store
compare "variation --pcs 1,2,3" "$work/new.h5" "$work/old.h5" variation --pcs 1,2,3 \
    -o "$work/v.png"
compare "export --statismo --pca default" "$work/new.h5" "$work/old.h5" export \
    --statismo "$work/m.h5" --pca default
