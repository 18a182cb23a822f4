/* tests/common/es_test_meshes.h — synthetic meshes for the store and ingest tests
 * that must not depend on ../shared: a torus grid (closed, genus 1, every
 * vertex interior) with a deterministic per-shape deformation, written as
 * OBJ with %.17g so that positions read back exactly. Also an independent
 * reader of OBJ `v` lines and an edge-length computation that does not go
 * through the library, for checking what ingest stored. */
#ifndef EDGESPACE_TESTS_ES_TEST_MESHES_H
#define EDGESPACE_TESTS_ES_TEST_MESHES_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Torus of nu x nv vertices; shape k deforms radii and adds a wobble. */
void es_test_torus(int nu, int nv, int k, double *xyz, int64_t *faces);

/* Write an OBJ; returns 0 on success. */
int es_test_write_obj(const char *path, int64_t nv, const double *xyz, int64_t nf,
                                    const int64_t *faces);

/* Torus shape k written to path; nu x nv grid. */
int es_test_write_torus(const char *path, int nu, int nv, int k);

/* The `v` lines of an OBJ file (strtod), 3 x V into a malloc'd array. */
double *es_test_obj_positions(const char *path, int64_t *nverts);

/* Raw edge lengths from positions and a 2 x E edge list. */
void es_test_lengths(int64_t E, const int64_t *edges, const double *xyz, double *len);

#endif
