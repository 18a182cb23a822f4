#!/usr/bin/env bash
# tools/output_hashes.sh — what the commands and notebooks write, hashed, so
# that two builds can be compared file by file: a refactor that changes no
# behaviour leaves every hash as it was (issue 30: "outputs byte-identical
# before and after on the same inputs").
#
#   bash tools/output_hashes.sh BUILD_DIR OUT_FILE [WORK_DIR]
#
# Runs, on synthetic data the build makes itself: synth, ingest, info,
# export (lengths, meshes, result tables, statismo), mean, pca, diff,
# project, point, model, gpa, compare, plot-pca, embed (several points,
# --fast, a mesh file), interp, variation, render, plot; and every C
# notebook with --small (on ../shared's data where the checkout has it,
# else on their synthetic fallback: compare builds on one machine). Each output file's SHA-256 goes into
# OUT_FILE, one line per file, sorted by path relative to WORK_DIR.
#
# What a run legitimately changes is taken out before hashing, and only
# that: a moment, a duration, a random store id, the tool's version. HDF5
# files are hashed as `h5dump` prints them (their bytes hold object times
# and free-space layout) less the attributes so named; JSON less such keys;
# CSV less such columns; Markdown reports less their "## Run" section (the
# notebooks' step timings), their tables' timing columns and the "2.5 s" in
# their text; the work folder's path is WORK and the checkout's SRC wherever
# they are written, and a report's "libedgespace 0.1.0 (f2a79a0)" names no
# commit. Run it twice on one build: the two files must be
# equal (that is its own check). OH_HASH_ONLY=1 re-hashes WORK_DIR as it is.
set -euo pipefail
build=$(cd "$1" && pwd)
out=$2
work=${3:-$(mktemp -d)}
mkdir -p "$work"
work=$(cd "$work" && pwd)
es="$build/tools/edgespace"
# the checkout the build was made from (the notebooks name ../shared's files by it)
src=$(/usr/bin/python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["directories"]["source"])' \
      "$build/meson-info/meson-info.json")
cd "$work"
log="$work/commands.log"
# each command's standard output is an output too: stdout/NN_VERB.txt
# (its messages and progress lines, with their timings, go to the log)
n=0
run() {
    n=$((n + 1))
    echo "+ $*" >> "$log"
    "$@" > "$(printf 'stdout/%02d_%s.txt' "$n" "$2")" 2>> "$log"
}
if [ -z "${OH_HASH_ONLY:-}" ]; then
: > "$log"
mkdir -p stdout

# data: 6 subjects x 3 expressions of the synthetic face, and bent tubes
run "$es" synth face -o faces --count 6 --resolution 10
run "$es" synth tube -o tubes --count 5 --resolution 6
run "$es" ingest s.h5 --manifest faces/manifest.csv
run "$es" ingest t.h5 --manifest tubes/manifest.csv
run "$es" info s.h5
# statistics, each stored and exported as CSV
run "$es" mean s.h5 --by expression -o mean_by_expression.csv
run "$es" pca s.h5 --name p --components 6 -o pca.csv
run "$es" diff s.h5 --column expression --from neutral --to happy --pair-by subject --name d \
    -o diff.csv
run "$es" point s.h5 "mean + 2*pc:1" --pca p --name up
run "$es" model s.h5 "~ expression" --permutations 99 --seed 5 --name m
run "$es" gpa s.h5 --name g
run "$es" compare s.h5 --gpa g --by expression -o compare
run "$es" project s.h5 --pca p -o project.csv faces/face_s01_happy.obj
run "$es" export s.h5 --lengths lengths.csv
run "$es" export s.h5 --meshes meshes --where expression=angry --format ply-ascii
for r in pca/p model/m gpa/g; do
    run "$es" export s.h5 --result "$r" --output "result_${r/\//_}"
done
# shapes
run "$es" embed s.h5 --point mean -o embed_mean.obj
run "$es" embed s.h5 --pca p --point "mean + 2*pc:1" -o embed_pc1.ply
run "$es" embed s.h5 --pca p --point "mean - 2*pc:2" --fast -o embed_pc2_fast.obj
run "$es" embed s.h5 --point "file:faces/face_s03_angry.obj" -o embed_file.obj
run "$es" embed t.h5 --point mean -o embed_tube_mean.obj
run "$es" interp s.h5 --from row:face_s01_neutral --to row:face_s01_happy --steps 4 \
    -o interp_%02d.obj
run "$es" export s.h5 --statismo statismo.h5 --pca p --components 2
run "$es" render embed_mean.obj embed_pc1.ply -o render.png
run "$es" plot-pca s.h5 --pca p --color expression -o plot_pca.png
run "$es" plot scatter pca.csv_scores.csv --x PC1 --y PC2 --label expression -o plot.png
if "$es" help variation > /dev/null 2>&1; then   # (built with figures only)
    run "$es" variation s.h5 --pca p --pcs 1,2 -o variation.png
fi
# notebooks (built with figures)
for nb in "$build"/notebooks-c/[0-9][0-9]_*; do
    [ -x "$nb" ] && [ -f "$nb" ] || continue
    name=$(basename "$nb")
    mkdir -p "notebooks/$name"
    echo "+ $name --small" >> "$log"
    EDGESPACE_NOTEBOOK_OUT="$work/notebooks" OPENBLAS_NUM_THREADS=1 "$nb" --small >> "$log" 2>&1 ||
        echo "  ($name failed: its outputs are hashed as they are)" >> "$log"
done
fi

# a moment or a duration: attribute and key names whose values are not the
# program's output but the run's
volatile='^(created|modified|date|time[a-z_]*|[a-z_]*_time|t_[a-z_]*|seconds|[a-z_]*_seconds|[a-z_]*_s|wall|cpu|tool_version|edgespace_version|git|git_[a-z_]*|host|pid|store_id)$'
export volatile
h5text() {
    h5dump "$1" | /usr/bin/python3 -c '
import os, re, sys
vol = re.compile(os.environ["volatile"])
skip = 0
for line in sys.stdin:
    m = re.match(r"\s*(?:ATTRIBUTE|DATASET) \"([^\"]*)\"", line)
    if skip:
        skip += line.count("{") - line.count("}")
        continue
    # statismo writes build-time, buildTime: compared as build_time
    name = m and re.sub(r"(?<=[a-z])(?=[A-Z])", "_", m.group(1)).lower().replace("-", "_")
    if m and vol.match(name):
        skip = line.count("{") - line.count("}")
        continue
    sys.stdout.write(line)'
}
jsontext() {
    /usr/bin/python3 -c '
import json, os, re, sys
vol = re.compile(os.environ["volatile"])
def clean(v):
    if isinstance(v, dict):
        return {k: clean(x) for k, x in v.items() if not vol.match(k)}
    if isinstance(v, list):
        return [clean(x) for x in v]
    return v
print(json.dumps(clean(json.load(open(sys.argv[1]))), sort_keys=True, indent=1))' "$1"
}
csvtext() {
    /usr/bin/python3 -c '
import csv, os, re, sys
vol = re.compile(os.environ["volatile"])
rows = list(csv.reader(open(sys.argv[1], newline="")))
keep = [i for i, h in enumerate(rows[0] if rows else []) if not vol.match(h.strip().lower())]
w = csv.writer(sys.stdout, lineterminator="\n")
for r in rows:
    w.writerow([r[i] for i in keep if i < len(r)])' "$1"
}
mdtext() {
    /usr/bin/python3 -c '
import re, sys
timed = re.compile(r"second|\(s\)|^s$|^ms$|time", re.I)
out, drop, skip = [], None, False
for line in open(sys.argv[1]):
    line = line.rstrip("\n")
    if line.startswith("## "):
        skip = line.strip() == "## Run"
    if skip:
        continue
    if line.startswith("|"):
        cells = line.strip().strip("|").split("|")
        if drop is None:   # a table header: its timing columns
            drop = {i for i, c in enumerate(cells) if timed.search(c.strip())}
        line = "|".join(c for i, c in enumerate(cells) if i not in drop)
    else:
        drop = None
    line = re.sub(r"\b\d+(\.\d+)? (s|ms)\b", "<t> \\2", line)
    out.append(line)
print("\n".join(out))' "$1"
}
# the work folder's and the checkout's paths, wherever an output names a
# file, and the commit a notebook names in its report
unwork() {
    LC_ALL=C sed -e "s|$work|WORK|g" -e "s|$src|SRC|g" \
        -e 's/libedgespace \([0-9.]*\) ([0-9a-f]*\(-dirty\)\{0,1\})/libedgespace \1 (COMMIT)/g'
}
{
    find . -type f ! -name commands.log ! -name '*.es-cache' -print | LC_ALL=C sort |
    while read -r f; do
        case "$f" in
            *.h5) h=$(h5text "$f" | unwork | sha256sum) ;;
            *.json) h=$(jsontext "$f" | unwork | sha256sum) ;;
            *.csv) h=$(csvtext "$f" | unwork | sha256sum) ;;
            *.md) h=$(mdtext "$f" | unwork | sha256sum) ;;
            *.png|*.glb|*.pdf) h=$(sha256sum < "$f") ;;
            ./stdout/*) h=$(unwork < "$f" | sed -E 's/\b[0-9]+(\.[0-9]+)? (s|ms)\b/<t> \2/g' |
                          sha256sum) ;;
            *) h=$(unwork < "$f" | sha256sum) ;;
        esac
        echo "${h%% *}  ${f#./}"
    done
} > "$out"
echo "$(wc -l < "$out") files hashed into $out (work: $work; commands: $log)"
