/* lib/embed/embed_memory.c — what an embedder and its solves will need, told
 * before any of it is allocated, so that a mesh too large for the machine is
 * refused in one line instead of growing until the kernel kills the process
 * (a 5-million-vertex mesh passed 14 GB and was killed).
 *
 * The need is dominated by the sparse factors (the 3V x 3V refinement and
 * frame matrix, the V x V position Laplacian, the closure matrix over the
 * interior dihedrals), whose fill under nested dissection grows as n log n,
 * and by the work buffers of the four stages (linear in E). Model: bytes =
 * E (4000 + 85 log2 E). Measured peak RSS of es_embedder_new plus one
 * es_embed_solve (this tree, getrusage, OPENBLAS_NUM_THREADS=1): closed tori
 * of V = 2,500 to 160,000 vertices used 4,730-4,930 bytes per edge (160K
 * vertices: 2.31 GB; the model 2.69 GB), open synthetic faces of 780 to
 * 47,449 vertices 3,430-3,910 (the model 1.1-1.4 times that). The model is
 * kept above what it measures by tests/embed/test_embed_memory.c, which
 * fails when the solver outgrows it.
 */
#include "core/core_private.h"
#include "edgespace/es_embed.h"
#include "edgespace/es_mesh.h"

#include <math.h>
#include <stdio.h>

uint64_t es_embed_memory_estimate(const es_mesh *mesh)
{
    double e = mesh ? (double)es_mesh_nedges(mesh) : 0;
    if (e < 1) return 0;
    return (uint64_t)(e * (4000.0 + 85.0 * log2(e)));
}

/* "1.2 GB", "350 MB": a size as a reader wants it */
static void human(char *buf, size_t n, uint64_t bytes)
{
    double v = (double)bytes;
    if (v >= 1e9) snprintf(buf, n, "%.3g GB", v / 1e9);
    else snprintf(buf, n, "%.3g MB", v / 1e6);
}

es_status es_embed_check_memory(es_ctx *ctx, const es_mesh *mesh, uint64_t extra,
                                const char *extra_what)
{
    uint64_t need = es_embed_memory_estimate(mesh), limit = es_ctx_memory_limit(ctx);
    char a[32], b[32], c[32], part[128] = "";
    if (__builtin_add_overflow(need, extra, &need)) need = UINT64_MAX;
    if (need <= limit) return ES_OK;
    human(a, sizeof a, need);
    human(b, sizeof b, limit);
    human(c, sizeof c, extra);
    if (extra) snprintf(part, sizeof part, " (%s of it%s)", c, extra_what ? extra_what : "");
    ES_FAIL(ctx, ES_ERANGE, "embed: a mesh of %lld vertices and %lld edges needs about %s%s, "
            "more than the memory limit of %s (--max-memory, EDGESPACE_MAX_MEMORY or "
            "es_ctx_set_memory_limit; by default the machine's memory)",
            (long long)es_mesh_nverts(mesh), (long long)es_mesh_nedges(mesh), a, part, b);
}
