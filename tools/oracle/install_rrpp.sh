#!/usr/bin/env bash
# tools/oracle/install_rrpp.sh — build RRPP (Collyer & Adams; not a Debian
# package) from a source tree into an R library, with Debian's R packages
# for its imports (r-cran-ape, r-cran-ggplot2, r-cran-matrix: tools/setup.sh),
# for the optional oracle of tests/tools/test_model_rrpp.c (tools/oracle/rrpp.R).
#
#   tools/oracle/install_rrpp.sh SOURCE_DIR LIBRARY_DIR
#   ES_RRPP_LIB=LIBRARY_DIR meson test -C build model_rrpp
#
# SOURCE_DIR is an unpacked RRPP source (its DESCRIPTION at the top), e.g.
# `git archive v2.0.2 | tar -x -C DIR` in a clone of RRPP's repository (mlcollyer/RRPP);
# the 2.0 series needs R >= 3.5 (Debian 12 has 4.2; RRPP 2.1 needs 4.4).
set -euo pipefail
if [ $# -ne 2 ] || [ ! -f "$1/DESCRIPTION" ]; then
  echo "usage: $0 SOURCE_DIR LIBRARY_DIR (SOURCE_DIR/DESCRIPTION must exist)" >&2
  exit 2
fi
mkdir -p "$2"
R CMD INSTALL --no-docs --no-html --no-help --library="$2" "$1"
Rscript -e ".libPaths(c('$2', .libPaths())); suppressMessages(library(RRPP)); cat('RRPP', format(packageVersion('RRPP')), 'in $2\n')"
