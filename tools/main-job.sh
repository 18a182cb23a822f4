#!/usr/bin/env bash
# tools/main-job.sh BUILD_DIR — the README's main job, on data the project
# makes itself (synthetic) or on ../shared/data when it is there.
#
# For now: make a synthetic face-like family (edgespace synth), ingest it
# into an HDF5 store and describe the store; then the same for the
# face-study meshes of ../shared/data when present. Output under
# out/main-job/ (MAIN_JOB_DIR overrides).
set -euo pipefail
build_dir=${1:-build}
es="$build_dir/tools/edgespace"
work=${MAIN_JOB_DIR:-out/main-job}
"$es" --version
"$es" help
rm -rf "$work"
mkdir -p "$work"

if "$es" help synth >/dev/null 2>&1; then
  echo "== synthetic faces: synth -> ingest -> info"
  "$es" synth face -o "$work/synth-face"
  "$es" ingest "$work/synth-face.h5" --manifest "$work/synth-face/manifest.csv"
  "$es" info "$work/synth-face.h5"
else
  echo "== (edgespace synth is not built yet: skipping the synthetic set)"
fi

shared_data="$(dirname "$0")/../../shared/data"
if [ -f "$shared_data/face-study/manifest.csv" ]; then
  echo "== face-study (../shared/data): ingest -> info"
  "$es" ingest "$work/face-study.h5" --manifest "$shared_data/face-study/manifest.csv"
  "$es" info "$work/face-study.h5"
fi
