#!/usr/bin/env bash
# tools/main-job.sh BUILD_DIR — the README's main job: notebook 1, the face
# study (notebooks-c/01_faces.c), built and run, then where its report is.
#
# Data: ../shared/data/face-study when it is there (all 30 subjects); else
# the project's own synthetic face family (es_synth "face"), and the report
# says in its first lines that the data are synthetic. Environment:
#   NOTEBOOK_ARGS  extra arguments for the notebook (e.g. --small, --synthetic)
#   OUT_DIR        output folder (default: out/01_faces in the repository)
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$here"
build_dir=${1:-build}
nb="$build_dir/notebooks-c/01_faces"
out=${OUT_DIR:-out/01_faces}

"$build_dir/tools/edgespace" --version
if [ ! -x "$nb" ]; then
  echo "main-job: $nb was not built: the statistics and embedding modules it needs" \
       "(es_stats.h, es_embed.h) are not in this tree yet" >&2
  exit 1
fi
shared=${EDGESPACE_SHARED:-../shared}
if [ -d "$shared/data/face-study" ]; then
  echo "main-job: face study on $shared/data/face-study" >&2
else
  echo "main-job: ../shared/data is absent: running on synthetic faces the project makes itself" >&2
fi
# One BLAS thread: the work is sparse and the machine is shared.
# shellcheck disable=SC2086
OPENBLAS_NUM_THREADS=${OPENBLAS_NUM_THREADS:-1} "$nb" --out "$out" ${NOTEBOOK_ARGS:-}
echo
case "$out" in /*) report="$out/report.md" ;; *) report="$here/$out/report.md" ;; esac
echo "Report: $report (figures and CSV files beside it, run.json for the run)"
