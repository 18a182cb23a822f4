/* lib/sparse/sparse_pkg.h — what the files of lib/sparse share: CHOLMOD's
 * header and the one way they start a CHOLMOD workspace. Never installed;
 * no other module may include it (the only place cholmod.h is read).
 */
#ifndef EDGESPACE_SPARSE_PKG_H
#define EDGESPACE_SPARSE_PKG_H

#ifndef ES_MODULE_SPARSE
#error "sparse/sparse_pkg.h is private to lib/sparse/ (see lib/README.md)"
#endif

#include "sparse/sparse_private.h"

#include <cholmod.h>

/* cholmod_l_start, then quiet: CHOLMOD prints nothing and calls no error
 * handler (the library never prints; failures come back as statuses). */
static inline void es__sparse_start(cholmod_common *cm)
{
    cholmod_l_start(cm);
    cm->print = 0;
    cm->error_handler = NULL;
}

#endif
