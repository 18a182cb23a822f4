/* tools/stats_cli.h — glue shared by the commands that work on a store's
 * statistics (mean, pca, diff, project, point, plot, and embed and interp for
 * their points): CSV output, edge tables, a point given on the command line. */
#ifndef EDGESPACE_TOOLS_STATS_CLI_H
#define EDGESPACE_TOOLS_STATS_CLI_H

#include <edgespace/edgespace.h>
#include <edgespace/es_study.h>
#include <edgespace/es_store.h>

#include <stdio.h>


/* Open a CSV file for writing ("-": stdout); prints the error and returns
 * NULL on failure. Close with stats_csv_close (0 ok, -1 write error printed). */
FILE *stats_csv_open(const char *verb, const char *path);
int stats_csv_close(const char *verb, FILE *f, const char *path);
/* One field, quoted when it holds a comma, quote or line break (RFC 4180),
 * preceded by a comma unless first. */
void stats_csv_field(FILE *f, const char *s, int first);
void stats_csv_number(FILE *f, double v);

/* Edge end points of the store's topology (2 x E; free()). NULL on failure
 * (printed). */
int64_t *stats_edges(const char *verb, es_ctx *ctx, es_store *store);

/* Write the per-edge CSV "edge,v0,v1,<name_0>,...": ncol columns of E
 * values (column c = values + c * E). 0 ok, 1 failure (printed). */
int stats_write_edge_csv(const char *verb, es_ctx *ctx, es_store *store, const char *path,
                         int64_t ncol, const char *const *names, const double *values);

/* The E scale-normalized lengths of a point given on the command line:
 * row:ID, the name of a stored point (/analysis/point/NAME), or an
 * expression (datasets-spec/point-syntax.md; pca: the PCA that pc:K means,
 * NULL for the only or the 'default' one); *scale gets the point's own
 * scale, else the mean scale of the store's rows. Non-positive lengths
 * (extrapolated too far) are an error naming the edge. 0 ok, else the
 * status, with the message printed. */
es_status stats_point_lengths(const char *verb, es_ctx *ctx, es_store *store, const char *spec,
                              const char *pca, int64_t ne, double *lengths, double *scale);

#endif
