#!/usr/bin/env bash
# tools/setup.sh — install what edgespace needs on Debian 12, configure, build,
# and then run the main job or the test suite.
#
#   bash tools/setup.sh demo    # install, build, run the main job (README step 1)
#   bash tools/setup.sh test    # install, build, run every test  (README step 2)
#   bash tools/setup.sh build   # install and build only
#
# Every mode also makes the Python package (python/edgespace) importable by
# Debian's interpreter: a path file edgespace.pth in its site-packages names
# python/ of this checkout, and the package loads build/lib/libedgespace.so
# (python/README.md); `/usr/bin/python3 -c "import edgespace"` then works.
#
# Installs exactly the missing Debian packages (apt-get, non-interactive,
# idempotent: a second run installs nothing). Environment:
#   BUILD_DIR   build directory (default: build)
#   MESON_ARGS  extra arguments for 'meson setup' (e.g. -Dwerror=true; -Dmpi=enabled
#               also installs Open MPI and parallel HDF5 and builds for mpirun)
#   TEST_ARGS   extra arguments for 'meson test' (e.g. --no-suite slow)
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$here"
mode=${1:-build}
build_dir=${BUILD_DIR:-build}

packages=(
  build-essential meson ninja-build pkg-config python3
  libopenblas-dev liblapacke-dev libsuitesparse-dev libhdf5-dev hdf5-tools libcsv-dev
  libcairo2-dev libcjson-dev
  r-base-core r-cran-shapes   # R oracles: the shapes package's landmark data sets
  clang libclang-rt-14-dev   # libFuzzer targets for the parsers
  # the Python package, its tests and notebooks (Debian's /usr/bin/python3;
  # python/tests/run.py --check verifies them below)
  python3-cffi python3-numpy python3-pytest python3-h5py python3-tqdm python3-pandas
  jupyter-nbconvert python3-ipykernel
  python3-scipy              # the published pipeline's oracle (fmin_l_bfgs_b)
  python3-matplotlib         # edgespace.mpl: the figures as matplotlib Axes for notebooks
  # R, for the tests that run datasets-spec/store-format.md's R snippets
  r-cran-hdf5r r-bioc-rhdf5
  r-cran-vegan               # the oracle of edgespace model (tools/oracle/adonis2.R)
  r-cran-ape r-cran-ggplot2  # RRPP's imports (with r-cran-matrix), for the optional RRPP
                             # oracle built from source by tools/oracle/install_rrpp.sh
  # edgespace explore's server and the Jupyter widget (python/edgespace/explore,
  # edgespace/widgets.py; python3-ipywidgets brings the widgets' nbextension), and
  # headless Chromium driving the page, and the widget in the classic notebook, in tests
  python3-aiohttp python3-ipywidgets chromium chromium-driver python3-selenium
  jupyter-notebook
)
# Debian packages installed only when their command is missing: npm fetches
# three.js for the explorer's page (an npm from another source, such as the
# one bundled with NodeSource's nodejs, does as well and is left alone)
commands=(npm:npm)

# The MPI build (MESON_ARGS with -Dmpi=enabled): Open MPI and Debian's
# openmpi build of HDF5 (parallel I/O), beside the serial one, which the
# default build keeps using (meson.build asks for hdf5-serial by name).
case " ${MESON_ARGS:-} " in
  *" -Dmpi=enabled "*) packages+=(libopenmpi-dev openmpi-bin libhdf5-openmpi-dev) ;;
esac

install_missing() {
  local missing=()
  for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  for c in "${commands[@]}"; do
    command -v "${c%%:*}" >/dev/null 2>&1 || missing+=("${c#*:}")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "setup: installing ${missing[*]}" >&2
  local sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends \
    "${missing[@]}" >&2
}

configure_and_build() {
  # shellcheck disable=SC2086
  if [ -f "$build_dir/build.ninja" ]; then
    meson configure "$build_dir" ${MESON_ARGS:-} >/dev/null
  else
    meson setup "$build_dir" ${MESON_ARGS:-} >/dev/null
  fi
  ninja -C "$build_dir" >&2
}

# JavaScript from the npm registry at the versions and checksums each
# folder's package-lock.json pins, into its node_modules (not committed):
# three.js for edgespace explore's page (python/edgespace/explore/web, which
# the server serves: the page loads nothing from elsewhere) and Khronos'
# glTF validator, the reader the tests check GLB files with (tests/js).
# A folder whose pinned versions are there already is skipped.
install_npm_folder() {
  local dir=$1 pkg=$2 want have
  want=$(node -p "require('$dir/package-lock.json').packages['node_modules/$pkg'].version")
  have=$(node -p "try { require('$dir/node_modules/$pkg/package.json').version } catch (e) { '' }")
  if [ "$want" != "$have" ]; then
    echo "setup: $pkg $want (npm ci in ${dir#"$here"/})" >&2
    (cd "$dir" && npm ci --ignore-scripts --no-audit --no-fund --loglevel=error >&2)
  fi
}

install_web() {
  install_npm_folder "$here/python/edgespace/explore/web" three
  install_npm_folder "$here/tests/js" gltf-validator
}

# python/ on Debian's interpreter's path (idempotent; rewritten when the
# checkout moves). The package finds the library that `build` holds.
install_python() {
  local py=/usr/bin/python3 site pth sudo=""
  [ -x "$py" ] || return 0
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  site=$("$py" -c 'import site; print(site.getsitepackages()[0])')
  pth="$site/edgespace.pth"
  if [ "$(cat "$pth" 2>/dev/null)" != "$here/python" ]; then
    $sudo mkdir -p "$site"
    echo "$here/python" | $sudo tee "$pth" >/dev/null
    echo "setup: $pth -> $here/python" >&2
  fi
  # every module the Python tests need, or fail: CI runs them, never skips them
  "$py" "$here/python/tests/run.py" --check
  if [ -f "$here/build/lib/libedgespace.so" ]; then
    (cd / && "$py" -c "import edgespace") || { echo "setup: import edgespace failed" >&2; return 1; }
  fi
}

install_missing
install_web
case "$mode" in
  build) configure_and_build; install_python ;;
  demo)  configure_and_build; install_python; bash tools/main-job.sh "$build_dir" ;;
  # shellcheck disable=SC2086
  test)  configure_and_build; install_python
         meson test -C "$build_dir" --print-errorlogs --num-processes 2 ${TEST_ARGS:-} ;;
  *) echo "usage: $0 [build|demo|test]" >&2; exit 2 ;;
esac
