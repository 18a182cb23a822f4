#!/usr/bin/env bash
# tools/main-job.sh BUILD_DIR — the README's main job, on data the project
# makes itself (synthetic) or on ../shared/data when it is there.
set -euo pipefail
build_dir=${1:-build}
es="$build_dir/tools/edgespace"
"$es" --version
"$es" help
