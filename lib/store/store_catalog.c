/* lib/store/store_catalog.c — what results a store has: tested for, listed
 * (inside the store, and beside it for format 3, merged in name order),
 * their attributes listed, and deleted (store_results.c writes and reads
 * them). */
#include "store/store_pkg.h"
#include "store/store_private.h"

#include <stdlib.h>
#include <string.h>

int es_store_has(es_store *s, const char *path)
{
    char full[700];
    int r = 0;
    if (!s || !path || !*path) return 0;
    es__result_full_path(full, sizeof full, path);
    es__h5_quiet q;
    bool e = false;
    es__h5_id f;
    const char *fp;
    es__h5_quiet_begin(&q);
    r = es__result_locate(s->ctx, s, path, ES__RESULT_READ, &f, &fp) == ES_OK &&
        es__result_find_link(s->ctx, f, fp, full, &e) == ES_OK && e;
    es__h5_quiet_end(&q);
    return r;
}

typedef struct name_list { es_ctx *ctx; char **names; int64_t n, cap; es_status rc; } name_list;

static int by_name(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

static int list_cb(void *data, const char *name)
{
    name_list *l = data;
    if (l->n == l->cap) {
        int64_t cap = l->cap ? 2 * l->cap : 16;
        char **p = es__realloc(l->ctx, l->names, (size_t)cap * sizeof *p);
        if (!p) { l->rc = ES_ENOMEM; return -1; }
        l->names = p;
        l->cap = cap;
    }
    if (!(l->names[l->n] = es__strdup(l->ctx, name))) { l->rc = ES_ENOMEM; return -1; }
    l->n++;
    return 0;
}

static es_status list_impl(es_ctx *ctx, es_store *s, const char *kind, char ***names,
                           int64_t *n)
{
    char full[600];
    name_list l = {ctx, NULL, 0, 0, ES_OK};
    es__h5_id g;
    if (kind && *kind && es__result_name_check(ctx, NULL, kind) != ES_OK) return ES_EINVAL;
    snprintf(full, sizeof full, "/analysis%s%s", kind && *kind ? "/" : "", kind ? kind : "");
    {
        bool e;
        es__h5_raw *raw = NULL;
        es_status rc;
        if ((rc = es__result_find_link(ctx, s->file, s->path, full, &e))) return rc;
        if (!e) goto beside;
        if ((g = es__h5_group_open(s->file, full)) < 0)
            return es__h5_fail(ctx, ES_EFORMAT, "store: %s is not a group", full);
        /* the group listed is searched by HDF5 too */
        if (kind && *kind && ((rc = es__h5_raw_open(ctx, g, s->path, &raw)) ||
                              (rc = es__h5_check_group(raw, g, full)))) {
            es__h5_raw_close(raw);
            es__h5_close(g);
            return rc;
        }
        es__h5_raw_close(raw);
    }
    if (es__h5_list(g, false, list_cb, &l) < 0) {
        es_status rc = l.rc ? l.rc : es__h5_fail(ctx, ES_EIO, "store: cannot list %s", full);
        es__h5_close(g);
        for (int64_t i = 0; i < l.n; i++) es__free(ctx, l.names[i]);
        es__free(ctx, l.names);
        return rc;
    }
    es__h5_close(g);
beside:
    /* and those beside the store (format 3), merged in name order */
    if (s->beside) {
        es_status rc = es__beside_names(s, kind, &l.names, &l.n, &l.cap);
        if (rc != ES_OK) {
            for (int64_t i = 0; i < l.n; i++) es__free(ctx, l.names[i]);
            es__free(ctx, l.names);
            return rc;
        }
        if (l.n > 1) qsort(l.names, (size_t)l.n, sizeof *l.names, by_name);
    }
    *names = l.names;
    *n = l.n;
    return ES_OK;
}

static es_status attrs_impl(es_ctx *ctx, es_store *s, const char *path, char ***keys, int64_t *n)
{
    char parts[8][128], full[700];
    es_status rc;
    name_list l = {ctx, NULL, 0, 0, ES_OK};
    es__h5_id f;
    const char *fp;
    (void)parts;
    bool e;
    if ((rc = es__result_find(ctx, s, path, ES__RESULT_READ, full, sizeof full, &f, &fp, &e))) return rc;
    if (!e) ES_FAIL(ctx, ES_ENOTFOUND, "store: no result object %s", full);
    es__h5_id obj = es__h5_object_open(f, full);
    if (obj < 0) return es__h5_fail(ctx, ES_EIO, "store: cannot open %s", full);
    /* the attribute messages checked before HDF5 decodes them */
    if ((rc = es__result_check_attrs(ctx, fp, obj, full))) {
        es__h5_close(obj);
        return rc;
    }
    if (es__h5_list(obj, true, list_cb, &l) < 0) {
        rc = l.rc ? l.rc : es__h5_fail(ctx, ES_EIO, "store: cannot list the attributes of %s",
                                       full);
        es__h5_close(obj);
        for (int64_t i = 0; i < l.n; i++) es__free(ctx, l.names[i]);
        es__free(ctx, l.names);
        return rc;
    }
    es__h5_close(obj);
    *keys = l.names;
    *n = l.n;
    return ES_OK;
}

es_status es_store_list_attrs(es_ctx *ctx, es_store *s, const char *path, char ***keys,
                              int64_t *n)
{
    es_status rc;
    if (!s || !keys || !n) ES_FAIL(ctx, ES_EINVAL, "store: NULL argument");
    *keys = NULL;
    *n = 0;
    ES__H5_QUIET(rc = attrs_impl(ctx, s, path, keys, n));
    return rc;
}

es_status es_store_list_results(es_ctx *ctx, es_store *s, const char *kind, char ***names,
                                int64_t *n)
{
    es_status rc;
    if (!s || !names || !n) ES_FAIL(ctx, ES_EINVAL, "store: NULL argument");
    *names = NULL;
    *n = 0;
    ES__H5_QUIET(rc = list_impl(ctx, s, kind, names, n));
    return rc;
}

static es_status delete_impl(es_ctx *ctx, es_store *s, const char *kind, const char *name)
{
    char full[600], group[300];
    es_status rc;
    if ((rc = es__result_name_check(ctx, kind, name)) != ES_OK) return rc;
    snprintf(group, sizeof group, "/analysis/%s", kind);
    snprintf(full, sizeof full, "%s/%s", group, name);
    bool e;
    es__h5_id f;
    const char *fp;
    if ((rc = es__result_locate(ctx, s, full + 10, ES__RESULT_READ, &f, &fp)) ||
        (rc = es__result_find_link(ctx, f, fp, full, &e)))
        return rc;
    if (!e) {
        char hint[400];
        es_store_result_hint(ctx, s, kind, name, hint, sizeof hint);
        ES_FAIL(ctx, ES_ENOTFOUND, "store: no result %s/%s in '%s'%s", kind, name, s->path, hint);
    }
    if (f != s->file) {
        if (s->mode == ES_STORE_READ)
            ES_FAIL(ctx, ES_EINVAL, "store: '%s' is open read-only", s->path);
        return es__beside_delete(s, kind, name);
    }
    if ((rc = es__store_begin_write(s))) return rc;
    if (es__h5_delete(s->file, full) < 0) {
        s->broken = true;
        return es__h5_fail(ctx, ES_EIO, "store: cannot delete %s", full);
    }
    /* the last result of its kind takes the kind's group with it */
    es__h5_id g = es__h5_group_open(s->file, group);
    int64_t nlinks = g < 0 ? -1 : es__h5_group_size(g);
    if (nlinks < 0) {
        es__h5_close(g);
        s->broken = true;
        return es__h5_fail(ctx, ES_EIO, "store: cannot read %s", group);
    }
    es__h5_close(g);
    if (nlinks == 0 && es__h5_delete(s->file, group) < 0) {
        s->broken = true;
        return es__h5_fail(ctx, ES_EIO, "store: cannot delete %s", group);
    }
    return ES_OK;
}

es_status es_store_delete_result(es_ctx *ctx, es_store *s, const char *kind, const char *name)
{
    es_status rc;
    if (!s) ES_FAIL(ctx, ES_EINVAL, "store: NULL store");
    ES__H5_QUIET(rc = delete_impl(ctx, s, kind, name));
    return rc;
}
