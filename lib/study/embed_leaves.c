/* lib/study/embed_leaves.c — the leaves of an embedding session's points,
 * kept: a slider or a walk evaluates "mean + t*pc:1" at every position, and
 * reading the store for each (every row for the mean, the whole PCA for a
 * component) took 15-45 ms of a frame's budget on face-study (87 rows,
 * 28K edges), more than the embedding's own iterations. A leaf read from
 * stored results is resolved once (es_study_resolve, which loads the PCA
 * once for every pc:K) and then copied, vector, scale and row weights,
 * while the store's generation (es_store_generation) is the one it was read
 * at: any write through the handle (a PCA replaced, a point saved) drops
 * them all. Files and single rows go to es_study_resolve every time. */
#include "study/study_pkg.h"

#include <string.h>

/* enough for a slider per component of a 20-PC explorer plus a few means,
 * differences and coefficients, within LEAF_CACHE_BYTES (at least 4 slots:
 * a 216K-vertex mesh's leaf is 5 MB); beyond, the oldest entry is reused */
#define LEAF_CACHE_SIZE 48
#define LEAF_CACHE_BYTES ((int64_t)64 << 20)

typedef struct leaf {
    es_point_leaf kind;
    char *arg;           /* NULL: the slot is empty */
    int64_t index;
    double scale;
    double *vec, *w;     /* E and N */
} leaf;

struct es__leaf_cache {
    es_ctx *ctx;
    es_store *store;
    es_study_resolver r;
    char *pca_name;      /* the PCA r resolves pc:K from (NULL: the default) */
    uint64_t generation;
    int64_t ne, n;
    int next;            /* the slot the next new leaf takes */
    int size;            /* slots in use, <= LEAF_CACHE_SIZE */
    leaf slot[LEAF_CACHE_SIZE];
};

static void drop_all(es__leaf_cache *c)
{
    for (int i = 0; i < LEAF_CACHE_SIZE; i++) {
        es__free(c->ctx, c->slot[i].arg);
        c->slot[i].arg = NULL;
    }
    es_study_resolver_clear(c->ctx, &c->r);
    c->next = 0;
}

es_status es__leaf_cache_new(es_ctx *ctx, es_store *store, const es_mesh *mesh,
                            es__leaf_cache **out)
{
    es__leaf_cache *c = es__calloc(ctx, 1, sizeof *c);
    *out = NULL;
    if (!c) return ES_ENOMEM;
    c->ctx = ctx;
    c->store = store;
    c->ne = es_store_nedges(store);
    c->n = es_store_nrows(store);
    c->generation = es_store_generation(store);
    c->r.store = store;
    c->r.mesh = mesh;   /* for file leaves */
    c->size = (int)(LEAF_CACHE_BYTES / ((c->ne + c->n + 1) * (int64_t)sizeof(double)));
    c->size = c->size < 4 ? 4 : c->size > LEAF_CACHE_SIZE ? LEAF_CACHE_SIZE : c->size;
    *out = c;
    return ES_OK;
}

void es__leaf_cache_free(es__leaf_cache *c)
{
    if (!c) return;
    drop_all(c);
    for (int i = 0; i < LEAF_CACHE_SIZE; i++) es__free(c->ctx, c->slot[i].vec);
    es__free(c->ctx, c->pca_name);
    es__free(c->ctx, c);
}

static int same_name(const char *a, const char *b)
{
    return (!a && !b) || (a && b && !strcmp(a, b));
}

es_status es__leaf_cache_ready(es__leaf_cache *c, const char *pca_name)
{
    if (es_store_generation(c->store) != c->generation || es_store_nrows(c->store) != c->n) {
        drop_all(c);
        c->generation = es_store_generation(c->store);
    }
    if (!same_name(pca_name, c->pca_name)) {
        /* components of another PCA: its pc:K leaves and loaded PCA go */
        for (int i = 0; i < LEAF_CACHE_SIZE; i++)
            if (c->slot[i].arg && c->slot[i].kind == ES_POINT_PC) {
                es__free(c->ctx, c->slot[i].arg);
                c->slot[i].arg = NULL;
            }
        es_study_resolver_clear(c->ctx, &c->r);
        es__free(c->ctx, c->pca_name);
        c->pca_name = NULL;
        if (pca_name && !(c->pca_name = es__strdup(c->ctx, pca_name))) return ES_ENOMEM;
    }
    c->r.pca_name = c->pca_name;
    return ES_OK;
}

static int kept_kind(es_point_leaf kind)
{
    return kind == ES_POINT_MEAN || kind == ES_POINT_PC || kind == ES_POINT_DIFF ||
           kind == ES_POINT_COEF;
}

es_status es__leaf_cache_resolve(es_ctx *ctx, void *ud, es_point_leaf kind, const char *arg,
                                 int64_t index, double *vec, double *scale, double *w)
{
    es__leaf_cache *c = ud;
    const char *a = arg ? arg : "";
    es_status rc;
    if (!kept_kind(kind) || !w || c->n != es_store_nrows(c->store))
        return es_study_resolve(ctx, &c->r, kind, arg, index, vec, scale, w);
    for (int i = 0; i < c->size; i++) {
        const leaf *l = &c->slot[i];
        if (l->arg && l->kind == kind && l->index == index && !strcmp(l->arg, a)) {
            memcpy(vec, l->vec, (size_t)c->ne * sizeof *vec);
            memcpy(w, l->w, (size_t)c->n * sizeof *w);
            *scale = l->scale;
            return ES_OK;
        }
    }
    /* w is zero on entry (es_point_eval_rows): after the call it holds this
     * leaf's weights alone */
    if ((rc = es_study_resolve(ctx, &c->r, kind, arg, index, vec, scale, w)) != ES_OK) return rc;
    leaf *l = &c->slot[c->next];
    c->next = (c->next + 1) % c->size;
    es__free(ctx, l->arg);
    l->arg = NULL;
    /* a leaf that cannot be kept (memory) is only read again next time */
    if (!l->vec && (l->vec = es__alloc_array(ctx, c->ne + c->n, sizeof(double))))
        l->w = l->vec + c->ne;
    if (!l->vec || !(l->arg = es__strdup(ctx, a))) {
        es_ctx_clear_error(ctx);
        return ES_OK;
    }
    l->kind = kind;
    l->index = index;
    l->scale = *scale;
    memcpy(l->vec, vec, (size_t)c->ne * sizeof *vec);
    memcpy(l->w, w, (size_t)c->n * sizeof *w);
    return ES_OK;
}
