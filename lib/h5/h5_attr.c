/* lib/h5/h5_attr.c — attributes: scalars and strings written (replacing),
 * an integer read checked to be one, and any string or number read as text
 * (strings through the checked decoder of h5_vlen.c). */
#include "h5/h5_pkg.h"

#include <stdio.h>
#include <string.h>

int es__h5_attr_exists(es__h5_id obj, const char *key)
{
    return H5Aexists(obj, key);
}

/* A scalar attribute (replacing one of that name) of file type ftype from
 * *v of memory type mtype. */
static es_status write_scalar(es_ctx *ctx, es__h5_id obj, const char *key, hid_t ftype,
                              hid_t mtype, const void *v)
{
    hid_t sp = -1, a = -1;
    es_status rc = ES_OK;
    if (H5Aexists(obj, key) > 0) H5Adelete(obj, key);
    if ((sp = H5Screate(H5S_SCALAR)) < 0 ||
        (a = H5Acreate2(obj, key, ftype, sp, H5P_DEFAULT, H5P_DEFAULT)) < 0 ||
        H5Awrite(a, mtype, v) < 0)
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot write attribute '%s'", key);
    es__h5_close(a);
    es__h5_close(sp);
    return rc;
}

es_status es__h5_write_attr_i64(es_ctx *ctx, es__h5_id obj, const char *key, int64_t v)
{
    return write_scalar(ctx, obj, key, H5T_STD_I64LE, H5T_NATIVE_INT64, &v);
}

es_status es__h5_write_attr_f64(es_ctx *ctx, es__h5_id obj, const char *key, double v)
{
    return write_scalar(ctx, obj, key, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &v);
}

es_status es__h5_write_attr_str(es_ctx *ctx, es__h5_id obj, const char *key, const char *v)
{
    hid_t sp = -1, a = -1, t = -1;
    es_status rc = ES_OK;
    if (H5Aexists(obj, key) > 0) H5Adelete(obj, key);
    if ((t = es__h5_str_type()) < 0 || (sp = H5Screate(H5S_SCALAR)) < 0 ||
        (a = H5Acreate2(obj, key, t, sp, H5P_DEFAULT, H5P_DEFAULT)) < 0 ||
        H5Awrite(a, t, &v) < 0)
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot write attribute '%s'", key);
    es__h5_close(a);
    es__h5_close(sp);
    es__h5_close(t);
    return rc;
}

es_status es__h5_write_attr_strs(es_ctx *ctx, es__h5_id obj, const char *key,
                                 const char *const *v, int64_t n)
{
    hsize_t d = (hsize_t)n;
    hid_t sp = -1, a = -1, t = -1;
    es_status rc = ES_OK;
    if (H5Aexists(obj, key) > 0) H5Adelete(obj, key);
    if ((t = es__h5_str_type()) < 0 || (sp = n ? H5Screate_simple(1, &d, NULL)
                                        : H5Screate(H5S_NULL)) < 0 ||
        (a = H5Acreate2(obj, key, t, sp, H5P_DEFAULT, H5P_DEFAULT)) < 0 ||
        (n && H5Awrite(a, t, v) < 0))
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot write attribute '%s'", key);
    es__h5_close(a);
    es__h5_close(sp);
    es__h5_close(t);
    return rc;
}

es_status es__h5_read_attr_i64(es_ctx *ctx, es__h5_id obj, const char *objname, const char *key,
                               int64_t *v)
{
    hid_t a = H5Aopen(obj, key, H5P_DEFAULT), t = -1, sp = -1;
    es_status rc = ES_OK;
    if (a < 0) return es__h5_fail(ctx, ES_EFORMAT, "store: %s has no attribute '%s'", objname, key);
    /* one integer: H5Aread writes every element, so a crafted array would
     * overrun v */
    if ((t = H5Aget_type(a)) < 0 || (sp = H5Aget_space(a)) < 0 ||
        H5Tget_class(t) != H5T_INTEGER || H5Sget_simple_extent_type(sp) == H5S_NULL ||
        H5Sget_simple_extent_npoints(sp) != 1)
        rc = es__fail(ctx, ES_EFORMAT, "store: attribute '%s' of %s is not one integer", key,
                      objname);
    else if (H5Aread(a, H5T_NATIVE_INT64, v) < 0)
        rc = es__h5_fail(ctx, ES_EFORMAT, "store: cannot read attribute '%s' of %s", key, objname);
    es__h5_close(sp);
    es__h5_close(t);
    H5Aclose(a);
    return rc;
}

/* A string attribute through the store's own decoder (h5_vlen.c); one
 * integer or real as text. */
es_status es__h5_read_attr_text(es_ctx *ctx, es__h5_raw *raw, es__h5_id obj, const char *key,
                                char *buf, size_t n)
{
    hid_t a = -1, t = -1, sp = -1;
    es_status rc = ES_OK;
    H5T_class_t cls;
    if (n) buf[0] = '\0';
    if ((a = H5Aopen(obj, key, H5P_DEFAULT)) < 0 || (t = H5Aget_type(a)) < 0 ||
        (sp = H5Aget_space(a)) < 0) {
        rc = es__h5_fail(ctx, ES_ENOTFOUND, "store: no attribute '%s'", key);
        goto done;
    }
    cls = H5Tget_class(t);
    if (cls == H5T_STRING) {
        char **s = NULL;
        int64_t ns = 0;
        if ((rc = es__h5_read_attr_strings(ctx, raw, obj, key, &s, &ns))) goto done;
        if (ns != 1)
            rc = es__fail(ctx, ES_EFORMAT, "store: attribute '%s' holds %lld strings, not one",
                          key, (long long)ns);
        else if (n)
            snprintf(buf, n, "%s", s[0]);
        for (int64_t i = 0; i < ns; i++) es__free(ctx, s[i]);
        es__free(ctx, s);
    } else if ((cls == H5T_INTEGER || cls == H5T_FLOAT) &&
               H5Sget_simple_extent_type(sp) != H5S_NULL &&
               H5Sget_simple_extent_npoints(sp) == 1) {
        long long iv;
        double dv;
        if (H5Aread(a, cls == H5T_INTEGER ? H5T_NATIVE_LLONG : H5T_NATIVE_DOUBLE,
                    cls == H5T_INTEGER ? (void *)&iv : (void *)&dv) < 0) {
            rc = es__h5_fail(ctx, ES_EFORMAT, "store: cannot read attribute '%s'", key);
            goto done;
        }
        if (n && cls == H5T_INTEGER) snprintf(buf, n, "%lld", iv);
        else if (n) snprintf(buf, n, "%.17g", dv);
    } else {
        rc = es__fail(ctx, ES_EFORMAT, "store: attribute '%s' is not a string or scalar", key);
    }
done:
    es__h5_close(sp);
    es__h5_close(t);
    es__h5_close(a);
    return rc;
}

/* A fixed-length C string type of strlen(s) + 1 bytes (close it). */
static hid_t fixed_str(const char *s)
{
    hid_t t = H5Tcopy(H5T_C_S1);
    if (t >= 0 && H5Tset_size(t, strlen(s) + 1) < 0) {
        H5Tclose(t);
        return -1;
    }
    return t;
}

int es__h5_put_attr_cstr(es__h5_id obj, const char *key, const char *v)
{
    hid_t t = fixed_str(v), sp = H5Screate(H5S_SCALAR), a = -1;
    int r = 0;
    if (t < 0 || sp < 0 || (a = H5Acreate2(obj, key, t, sp, H5P_DEFAULT, H5P_DEFAULT)) < 0 ||
        H5Awrite(a, t, v) < 0)
        r = -1;
    es__h5_close_kept((const hid_t[]){a, sp, t}, 3);
    return r;
}

int es__h5_put_cstr(es__h5_id loc, const char *name, const char *v)
{
    hid_t t = fixed_str(v), sp = H5Screate(H5S_SCALAR), d = -1;
    int r = 0;
    if (t < 0 || sp < 0 ||
        (d = H5Dcreate2(loc, name, t, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)) < 0 ||
        H5Dwrite(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, v) < 0)
        r = -1;
    es__h5_close_kept((const hid_t[]){d, sp, t}, 3);
    return r;
}
