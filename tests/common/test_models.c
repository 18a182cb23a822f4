/* tests/common/test_models.c — es_test_models.h. */
#include "es_test_models.h"
#include "es_test_run.h"
#include "core/core_private.h"
#include "core/csv_table.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int es_test_write_permutations(es_ctx *ctx, const char *rows_csv, const char *block,
                               uint64_t seed, int64_t count, const char *path)
{
    es__csv_table t = {0};
    if (es__csv_read(ctx, "rows", rows_csv, 0, &t) != ES_OK) return 0;
    const int64_t n = t.nrecords - 1;
    int64_t *perm = calloc((size_t)(n * count), sizeof *perm), *blocks = NULL, ng = 0, c = -1;
    const char **lab = calloc((size_t)n, sizeof *lab), **names = NULL;
    int ok = perm && lab;
    for (int64_t k = 0; block && k < es__csv_nfields(&t, 0); k++)
        if (!strcmp(es__csv_field(&t, 0, k), block)) c = k;
    if (block) {
        ok = ok && c >= 0;
        for (int64_t i = 0; ok && i < n; i++) lab[i] = es__csv_field(&t, i + 1, c);
        ok = ok && es_groups_from_labels(ctx, lab, n, &blocks, &names, &ng) == ES_OK;
    }
    ok = ok && es_model_permutations(ctx, n, blocks, seed, count, perm) == ES_OK;
    FILE *f = ok ? fopen(path, "w") : NULL;
    for (int64_t b = 0; f && b < count; b++)
        for (int64_t i = 0; i < n; i++)
            fprintf(f, "%lld%c", (long long)(perm[i + b * n] + 1), i + 1 < n ? ',' : '\n');
    ok = f && fclose(f) == 0;
    es_free(ctx, blocks);
    es_free(ctx, (void *)names);
    free(perm);
    free(lab);
    es__csv_table_clear(ctx, &t);
    return ok;
}

int es_test_landmark_gpa(const char *dir, const char *set, const char *specimens, char *store,
                         char *aligned, char *spec, size_t n)
{
    static es_test_out r;
    char lm[600], sp[600];
    snprintf(lm, sizeof lm, "%s/data/landmarks_rshapes/%s_landmarks.csv", ES_SHARED_DIR, set);
    snprintf(sp, sizeof sp, "%s/data/landmarks_rshapes/%s_specimens.csv", ES_SHARED_DIR, set);
    snprintf(store, n, "%s/%s.h5", dir, set);
    snprintf(aligned, n, "%s/%s.aligned.csv", dir, set);
    snprintf(spec, n, "%s/%s.specimens.csv", dir, set);
    unlink(store);
    ES_RUN(&r, dir, "ingest-landmarks", store, "--csv", lm, "--specimens", specimens ? specimens : sp,
           "-q");
    if (r.status) return 0;
    ES_RUN(&r, dir, "gpa", store, "--name", "g");
    if (r.status) return 0;
    ES_RUN(&r, dir, "export", store, "--result", "gpa/g", "--table", "aligned", "--output", aligned);
    if (r.status) return 0;
    ES_RUN(&r, dir, "export", store, "--result", "gpa/g", "--output", spec);
    return r.status == 0;
}
