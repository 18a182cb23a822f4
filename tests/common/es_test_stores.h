/* tests/common/es_test_stores.h — stores the tests make from the project's
 * own synthetic shapes (lib/synth), so that they run without ../shared. */
#ifndef ES_TEST_STORES_H
#define ES_TEST_STORES_H

#include "edgespace/edgespace.h"

/* n synthetic faces (ES_SYNTH_FACE, ctx's seed set to `seed`) written to
 * dir with their manifest and ingested into a new store at `store` (labels
 * subject and expression). Failures are counted as failed checks. */
void es_test_face_store(es_ctx *ctx, const char *dir, const char *store, int64_t n,
                        uint64_t seed);

#endif
