/* lib/ingest/landmarks_tps.c — the tpsDig TPS landmark reader.
 *
 * TPS is the format of F. J. Rohlf's tpsDig/tpsUtil (Rohlf 2015, "The tps
 * series of software", Hystrix 26:9-12), which most morphometric data are
 * exchanged in; the keys and their meaning follow geomorph's readland.tps
 * (SCALE multiplies, CURVES/POINTS blocks are outlines, not landmarks).
 * Numbers go through core/text.h, so they read to the same bits as the
 * mesh readers' (strtod's correctly rounded value).
 */
#include "ingest/ingest_pkg.h"
#include "core/files.h"
#include "core/text.h"

#include <ctype.h>
#include <math.h>
#include <strings.h>

/* "KEY=value" (case-insensitive key); returns the value or NULL. */
static const char *tps_key(const char *line, const char *key)
{
    size_t n = strlen(key);
    if (strncasecmp(line, key, n) || line[n] != '=') return NULL;
    const char *v = line + n + 1;
    while (*v == ' ' || *v == '\t') v++;
    return v;
}

/* Separators between the coordinates of a line. */
#define COORD_SEPS " \t,"

/* Up to 4 coordinates of line s into v (the first 3 kept); *got counts
 * them. -1 if a token is not a finite number. */
static int parse_coords(const char *s, double v[3], int *got)
{
    const char *p = s;
    *got = 0;
    while (*got < 4) {
        p += strspn(p, COORD_SEPS);
        if (!*p) break;
        const char *e = p + strcspn(p, COORD_SEPS);
        double x;
        if (es__parse_double(p, e, &x) != e || !isfinite(x)) return -1;
        if (*got < 3) v[*got] = x;
        (*got)++;
        p = e;
    }
    return 0;
}

es_status es_landmarks_read_tps(es_ctx *ctx, const char *path, int apply_scale,
                                es_landmarks **out)
{
    char *buf = NULL;
    size_t len;
    es_status rc;
    es__lm_builder b = {0};
    const char *file = es__path_base(path);
    *out = NULL;
    b.ctx = ctx;
    if ((rc = es__lm_read_text(ctx, path, &buf, &len)) != ES_OK) return rc;

    /* a count from the file is bounded by the lines left to hold it */
    int64_t nlines = 1;
    for (const char *q = buf; (q = strchr(q, '\n')); q++) nlines++;
    int64_t line = 0, pending = 0;   /* coordinate lines still expected */
    int64_t skip = 0;                /* POINTS= lines of a curve still to skip */
    int d = 2, warned_curves = 0;
    char *cur = buf;
    while (cur && *cur) {
        char *nl = strchr(cur, '\n');
        if (nl) *nl = 0;
        char *s = cur;
        cur = nl ? nl + 1 : NULL;
        line++;
        size_t l = strlen(s);
        while (l && (s[l - 1] == '\r' || isspace((unsigned char)s[l - 1]))) s[--l] = 0;
        while (isspace((unsigned char)*s)) s++;
        if (!*s) continue;
        if (skip > 0) { skip--; continue; }
        if (pending > 0) {
            double v[3];
            int got;
            if (parse_coords(s, v, &got) != 0) {
                rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: expected %d coordinates, "
                              "found '%s'", file, (long long)line, d, s);
                goto fail;
            }
            if (got != d) {
                rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: expected %d coordinates, "
                              "found %d", file, (long long)line, d, got);
                goto fail;
            }
            int64_t lmk = b.k - pending;
            double *col = b.xyz + (b.n - 1) * b.kd;
            for (int q = 0; q < d; q++) col[lmk + q * b.k] = v[q];
            pending--;
            continue;
        }
        const char *val;
        int64_t iv;
        if ((val = tps_key(s, "LM")) || (val = tps_key(s, "LM3"))) {
            int dim = tps_key(s, "LM3") ? 3 : 2;
            if (es__parse_int64_field(val, &iv) || iv < 1) {
                rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: bad landmark count '%s'",
                              file, (long long)line, val);
                goto fail;
            }
            if (iv > nlines - line) {
                rc = es__fail(ctx, ES_ERANGE, "landmarks: %s:%lld: %lld landmarks (LM= count) "
                              "are too many for the %lld lines that follow", file,
                              (long long)line, (long long)iv, (long long)(nlines - line));
                goto fail;
            }
            d = dim;
            if (b.n == 0) b.limit = nlines / (iv + 1) + 1;   /* LM= line + iv lines each */
            if ((rc = es__lm_builder_add(&b, iv, d, file, line)) != ES_OK) goto fail;
            pending = iv;
        } else if ((val = tps_key(s, "ID"))) {
            if (b.n == 0) goto before_lm;
            es__free(ctx, b.ids[b.n - 1]);
            if (!(b.ids[b.n - 1] = es__strdup(ctx, val))) { rc = ES_ENOMEM; goto fail; }
        } else if ((val = tps_key(s, "IMAGE"))) {
            if (b.n == 0) goto before_lm;
            es__free(ctx, b.images[b.n - 1]);
            if (!(b.images[b.n - 1] = es__strdup(ctx, val))) { rc = ES_ENOMEM; goto fail; }
        } else if ((val = tps_key(s, "SCALE"))) {
            double sc;
            if (b.n == 0) goto before_lm;
            if (es__parse_finite(val, &sc) || !(sc > 0)) {
                rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: bad SCALE '%s'", file,
                              (long long)line, val);
                goto fail;
            }
            b.scale[b.n - 1] = sc;
        } else if ((val = tps_key(s, "CURVES"))) {
            if (!warned_curves++)
                es__warn(ctx, "landmarks: %s:%lld: CURVES (outlines) are ignored", file,
                         (long long)line);
        } else if ((val = tps_key(s, "POINTS"))) {
            if (es__parse_int64_field(val, &iv) || iv < 0) {
                rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: bad POINTS count '%s'", file,
                              (long long)line, val);
                goto fail;
            }
            skip = iv;
        } else if (tps_key(s, "COMMENT") || tps_key(s, "VARIABLES")) {
            /* free text, ignored */
        } else if (strchr(s, '=')) {
            es__warn(ctx, "landmarks: %s:%lld: unknown key '%s' ignored", file, (long long)line, s);
        } else {
            rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: unexpected line '%s' (coordinates "
                          "must follow an LM= line)", file, (long long)line, s);
            goto fail;
        }
        continue;
    before_lm:
        rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: '%s' before the first LM= line", file,
                      (long long)line, s);
        goto fail;
    }
    if (pending > 0) {
        rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: end of file with %lld of %lld "
                      "coordinate lines of specimen %lld missing", file, (long long)line,
                      (long long)pending, (long long)b.k, (long long)b.n);
        goto fail;
    }
    if (skip > 0) {
        rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: end of file inside a POINTS= block",
                      file, (long long)line);
        goto fail;
    }
    if (b.n == 0) {
        rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s: no LM= or LM3= specimen", file);
        goto fail;
    }
    for (int64_t j = 0; j < b.n; j++) {
        if (apply_scale && isfinite(b.scale[j]))
            for (int64_t v = 0; v < b.kd; v++)
                if (!isfinite(b.xyz[j * b.kd + v] *= b.scale[j])) {
                    rc = es__fail(ctx, ES_ERANGE, "landmarks: %s: specimen %lld%s%s%s: SCALE=%g "
                                  "makes its coordinates overflow", file, (long long)j + 1,
                                  b.ids[j] ? " ('" : "", b.ids[j] ? b.ids[j] : "",
                                  b.ids[j] ? "')" : "", b.scale[j]);
                    goto fail;
                }
        if (!b.ids[j]) {
            char name[32];
            snprintf(name, sizeof name, "%lld", (long long)j + 1);
            if (!(b.ids[j] = es__strdup(ctx, name))) { rc = ES_ENOMEM; goto fail; }
        }
    }
    es__free(ctx, buf);
    return es__lm_builder_finish(&b, 1, out);
fail:
    es__free(ctx, buf);
    es__lm_builder_clear(&b);
    return rc;
}
