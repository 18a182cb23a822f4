/* lib/figure/color_files.c — a mesh file coloured by scalars from a CSV
 * file (es_figure_color_file, behind `edgespace render MESH --scalars CSV
 * -o OUT.ply|.glb|.vtp`): the colours es_render would draw, as per-vertex
 * colours a viewer shows without this project (MeshLab, Blender, ParaView,
 * a web page), with the values themselves in VTK's PolyData for ParaView.
 *
 * PLY and GLB colour vertices only, so face and edge values are carried to
 * the vertices as the mean of the finite values around each vertex; the
 * VTP file keeps face values as cell data besides.
 */
#include "figure/figure_pkg.h"
#include "core/files.h"
#include "edgespace/es_figure.h"
#include "edgespace/es_mesh.h"
#include "meshio/meshio_private.h"

#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <strings.h>

/* Per-vertex values of the scalars `it` carries (vertex: themselves; face
 * or edge: the mean of the finite ones touching the vertex, NaN if none). */
static es_status vertex_values(es_ctx *ctx, const es_render_mesh *it, double *out)
{
    const int64_t V = it->nverts;
    if (it->scalar_kind == ES_SCALARS_VERTEX) {
        memcpy(out, it->scalars, (size_t)V * sizeof *out);
        return ES_OK;
    }
    int64_t *count = es__calloc(ctx, (size_t)V, sizeof *count);
    if (!count) return ES_ENOMEM;
    memset(out, 0, (size_t)V * sizeof *out);
    bool faces = it->scalar_kind == ES_SCALARS_FACE;
    int64_t n = faces ? it->nfaces : it->nedges, per = faces ? 3 : 2;
    const int64_t *idx = faces ? it->faces : it->edges;
    for (int64_t e = 0; e < n; e++) {
        if (!isfinite(it->scalars[e])) continue;
        for (int64_t k = 0; k < per; k++) {
            out[idx[per * e + k]] += it->scalars[e];
            count[idx[per * e + k]]++;
        }
    }
    for (int64_t v = 0; v < V; v++) out[v] = count[v] ? out[v] / (double)count[v] : NAN;
    es__free(ctx, count);
    return ES_OK;
}

/* s as XML attribute text (a column header may hold <, &, "). */
static void xml_escape(FILE *f, const char *s)
{
    for (; *s; s++) {
        switch (*s) {
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '&': fputs("&amp;", f); break;
        case '"': fputs("&quot;", f); break;
        default: fputc(*s, f);
        }
    }
}

/* VTK XML PolyData, ASCII (VTK's "VTK File Formats"): positions, triangles,
 * the values per point (and per cell for face values) and the colours. */
static void write_vtp(FILE *f, const es_render_mesh *it, const double *vv, const uint8_t *rgb,
                      const char *name)
{
    const int64_t V = it->nverts, F = it->nfaces;
    fprintf(f, "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" "
            "byte_order=\"LittleEndian\">\n<PolyData>\n<Piece NumberOfPoints=\"%" PRId64 "\" "
            "NumberOfPolys=\"%" PRId64 "\">\n<Points><DataArray type=\"Float64\" "
            "NumberOfComponents=\"3\" format=\"ascii\">\n", V, F);
    for (int64_t v = 0; v < 3 * V; v++) fprintf(f, "%.17g%c", it->xyz[v], v % 3 == 2 ? '\n' : ' ');
    fputs("</DataArray></Points>\n<Polys><DataArray type=\"Int64\" Name=\"connectivity\" "
          "format=\"ascii\">\n", f);
    for (int64_t t = 0; t < 3 * F; t++) fprintf(f, "%" PRId64 "%c", it->faces[t], t % 3 == 2 ? '\n' : ' ');
    fputs("</DataArray><DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n", f);
    for (int64_t t = 0; t < F; t++) fprintf(f, "%" PRId64 "\n", 3 * (t + 1));
    fputs("</DataArray></Polys>\n<PointData Scalars=\"", f);
    xml_escape(f, name);
    fputs("\"><DataArray type=\"Float64\" Name=\"", f);
    xml_escape(f, name);
    fputs("\" format=\"ascii\">\n", f);
    /* VTK's ASCII reader takes nan */
    for (int64_t v = 0; v < V; v++) fprintf(f, isfinite(vv[v]) ? "%.17g\n" : "nan\n", vv[v]);
    fputs("</DataArray><DataArray type=\"UInt8\" Name=\"colors\" NumberOfComponents=\"3\" "
          "format=\"ascii\">\n", f);
    for (int64_t v = 0; v < V; v++)
        fprintf(f, "%u %u %u\n", rgb[3 * v], rgb[3 * v + 1], rgb[3 * v + 2]);
    fputs("</DataArray></PointData>\n", f);
    if (it->scalar_kind == ES_SCALARS_FACE) {
        fputs("<CellData><DataArray type=\"Float64\" Name=\"", f);
        xml_escape(f, name);
        fputs("\" format=\"ascii\">\n", f);
        for (int64_t t = 0; t < F; t++)
            fprintf(f, isfinite(it->scalars[t]) ? "%.17g\n" : "nan\n", it->scalars[t]);
        fputs("</DataArray></CellData>\n", f);
    }
    fputs("</Piece>\n</PolyData>\n</VTKFile>\n", f);
}

es_status es_figure_color_file(es_ctx *ctx, const es_render_spec *spec, const char *mesh_path,
                               const char *scalar_path, const char *out_path,
                               es_render_report *rep)
{
    if (!spec || !mesh_path || !scalar_path || !out_path)
        ES_FAIL(ctx, ES_EINVAL, "color: no spec, mesh, scalar file or output path");
    const char *dot = strrchr(out_path, '.');
    bool vtp = dot && !strcasecmp(dot, ".vtp");
    es_mesh_format fmt = vtp ? ES_FORMAT_AUTO : es_meshio_format_from_path(out_path);
    if (!vtp && fmt != ES_FORMAT_PLY && fmt != ES_FORMAT_GLB)
        ES_FAIL(ctx, ES_EINVAL, "color: '%s': a coloured mesh is written as .ply, .glb or .vtp",
                out_path);
    es_meshdata md;
    es_mesh *mesh = NULL;
    es_render_mesh it;
    char head[200] = "";
    double *vals = NULL, *vv = NULL;
    uint8_t *rgb = NULL;
    int64_t nvals = 0;
    memset(&it, 0, sizeof it);
    es_status rc = es_meshdata_read(ctx, mesh_path, ES_FORMAT_AUTO, &md);
    if (rc != ES_OK) return rc;
    it.nverts = md.nverts;
    it.nfaces = md.nfaces;
    it.xyz = md.xyz;
    it.faces = md.faces;
    if ((rc = es__read_scalars(ctx, scalar_path, spec->scalar_column, &vals, &nvals, head,
                               sizeof head)) == ES_OK) {
        it.scalars = vals;
        rc = es__match_scalars(ctx, mesh_path, &md, scalar_path, nvals, &mesh, &it);
    }
    es_render_spec sp = *spec;
    sp.meshes = &it;
    sp.nmeshes = 1;
    es_render_report r;
    memset(&r, 0, sizeof r);
    if (rc == ES_OK) rc = es__render_range(ctx, &sp, &r);
    vv = es__alloc_array(ctx, md.nverts, sizeof *vv);
    rgb = es__alloc_array(ctx, 3 * md.nverts, sizeof *rgb);
    if (rc == ES_OK && (!vv || !rgb)) rc = ES_ENOMEM;
    if (rc == ES_OK) rc = vertex_values(ctx, &it, vv);
    for (int64_t v = 0; rc == ES_OK && v < md.nverts; v++) {
        double c[3];
        es_colormap_rgb(sp.cmap, isfinite(vv[v]) ? (vv[v] - r.vmin) / (r.vmax - r.vmin) : NAN,
                        c);
        for (int k = 0; k < 3; k++) rgb[3 * v + k] = (uint8_t)lrint(255 * c[k]);
    }
    if (rc == ES_OK && vtp) {
        es__file_replace w;
        if ((rc = es__replace_begin(ctx, out_path, &w)) == ES_OK) {
            write_vtp(w.f, &it, vv, rgb, *head ? head : "scalars");
            rc = es__replace_end(ctx, &w, ES_OK);
        }
    } else if (rc == ES_OK) {
        rc = es__meshdata_write(ctx, out_path, fmt, md.nverts, md.nfaces, md.faces, md.xyz, rgb);
    }
    if (rep) *rep = r;
    es_meshdata_clear(ctx, &md);
    es_mesh_free(mesh);
    es__free(ctx, vals);
    es__free(ctx, vv);
    es__free(ctx, rgb);
    return rc;
}
