/* tests/common/es_test_files.h — file helpers for the store, manifest and ingest
 * tests: a scratch directory under the build tree, whole-file reads and
 * byte-for-byte comparison. */
#ifndef EDGESPACE_TESTS_ES_TEST_FILES_H
#define EDGESPACE_TESTS_ES_TEST_FILES_H

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* A fresh directory ES_BUILD_ROOT/test-tmp/<name>-XXXXXX (static buffer). */
const char *es_test_tmpdir(const char *name);

/* Whole file into a malloc'd buffer (*n bytes); NULL if unreadable. */
char *es_test_slurp(const char *path, size_t *n);

/* 1 if the file's bytes equal buf[0..n). */
int es_test_same_bytes(const char *path, const char *buf, size_t n);

void es_test_write_file(const char *path, const char *text);

/* Number of directory entries whose name contains `needle`. */
int es_test_count_entries(const char *dir, const char *needle);

#endif
