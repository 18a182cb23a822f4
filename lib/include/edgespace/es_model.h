/* lib/include/edgespace/es_model.h — linear models on shape with permutation
 * tests: formulas over label columns, design matrices, sums of squares of
 * type I, II and III, R^2 and F with permutation p-values by residual
 * randomization (RRPP), blocks for repeated measures, coefficients as
 * combinations of rows, pairwise comparisons of least-squares means,
 * per-variable (per-edge) tests with Benjamini-Hochberg FDR, and the common
 * allometric component.
 *
 * datasets-spec/analysis-results.md ("model/<name>") describes the formula
 * syntax and the statistics as the command offers them. The method is
 * geomorph's procD.lm / RRPP's lm.rrpp (Collyer, Sekora & Adams 2015;
 * Adams & Collyer 2018): the response is a matrix Y of N rows (shapes) by
 * p variables (scale-normalized edge lengths, or Procrustes-aligned
 * coordinates), the statistics are traces of projections
 * of Y (Goodall's F, Anderson's PERMANOVA on Euclidean distances), and for
 * each term the residuals of its reduced model are permuted among the rows
 * (Freedman & Lane 1983) and added back to the reduced model's fitted
 * values. vegan's adonis2 permutes the rows themselves (ES_PERM_RAW); both
 * are offered, and agree with R to rounding (tools/oracle/adonis2.R,
 * tests/tools/test_model_oracle.c).
 *
 * Everything works on the N x N geometry of the rows: the response enters
 * once, through an es_source, as its principal coordinates Z (N x r, Z Z^T =
 * the Gram matrix of the centred rows, by es_pca_fit), so a permutation
 * costs O(q N r) whatever p is.
 */
#ifndef EDGESPACE_ES_MODEL_H
#define EDGESPACE_ES_MODEL_H

#include "es_core.h"
#include "es_stats.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- formulas ----------------------------------------------------------------
 *
 *   "~ expression + subject", "~ log(size) + species * sex", "~ a + b + a:b"
 * Variables are label columns: NAME (numeric when every value is a number,
 * else categorical), factor(NAME) (categorical), log(NAME) (the natural log
 * of a positive numeric column); a:b is an interaction, a*b means a + b +
 * a:b, parentheses group sums ((a + b)*c). Terms are ordered by degree
 * (main effects, then two-way interactions, ...), keeping the written order
 * within a degree, as R's terms() does. Every model has an intercept. */
typedef struct es_formula es_formula;

typedef enum es_var_kind {
    ES_VAR_AUTO = 0,   /* NAME: numeric if every value is a finite number */
    ES_VAR_FACTOR,     /* factor(NAME) */
    ES_VAR_LOG         /* log(NAME) */
} es_var_kind;

/* Parse text. Errors are ES_EFORMAT naming the 1-based column:
 * "formula: column 9: expected a column name, found '+'". A formula that
 * expands to more than ES_FORMULA_MAX_TERMS terms is refused before it is
 * expanded (a*b*...*r, 18 names, would be 262,143 terms). */
#define ES_FORMULA_MAX_TERMS 1024
ES_API es_status es_formula_parse(es_ctx *ctx, const char *text, es_formula **out);
/* Whether a variable's column exists: 1 if it does; 0 if not, with the
 * reason in why[n] ("no label column 'mood' in 's.h5' (did you mean
 * 'mode'?)"). */
typedef int (*es_formula_column_fn)(void *userdata, const char *name, char *why, size_t n);
/* es_formula_parse with each variable's column checked by known as it is
 * read, before any product is expanded: ES_ENOTFOUND "formula: column 4:
 * " and known's reason. */
ES_API es_status es_formula_parse_checked(es_ctx *ctx, const char *text,
                                          es_formula_column_fn known, void *userdata,
                                          es_formula **out);
ES_API void es_formula_free(es_formula *f);
/* Variables (distinct NAME / factor(NAME) / log(NAME), in order of first
 * appearance): the label column each reads and how. Borrowed strings. */
ES_API int64_t es_formula_nvars(const es_formula *f);
ES_API const char *es_formula_var(const es_formula *f, int64_t v, es_var_kind *kind);
/* Terms in model order; the label joins the variables' labels with ':'
 * ("species:sex", "log(size)"). */
ES_API int64_t es_formula_nterms(const es_formula *f);
ES_API const char *es_formula_term(const es_formula *f, int64_t j);

/* ---- designs -------------------------------------------------------------- */

/* The values of one variable for the N rows: labels (N strings) or numbers
 * (N doubles, numeric only). name is the column the formula names. */
typedef struct es_model_column {
    const char *name;
    const char *const *labels;  /* or NULL */
    const double *values;       /* or NULL */
} es_model_column;

typedef enum es_contrasts {
    ES_CONTRASTS_TREATMENT = 0, /* R's contr.treatment: the first level is the reference */
    ES_CONTRASTS_SUM            /* R's contr.sum: levels against the last, sum to zero */
} es_contrasts;

/* The model matrix X (N x q, intercept first) as R's model.matrix makes it:
 * factor levels sorted in byte order (R's sort in the C locale), a factor
 * coded by its contrasts in a term whose margin (the term without it) is in
 * the model, by indicators otherwise; interaction columns are products with
 * the first variable varying fastest. Column names: "intercept", "age",
 * "log(size)", "expression=happy", "expression=happy:age". */
typedef struct es_design {
    es_ctx *ctx;
    int64_t n, ncols;       /* N rows, q columns */
    double *x;              /* N x q, column-major, ld N */
    char **colnames;        /* q */
    int64_t *assign;        /* q: the term of each column (-1: the intercept) */
    int64_t nterms;
    char **terms;           /* nterms labels */
    int64_t *term_vars;     /* nterms x nvars: 1 if term j holds variable v */
    int64_t nvars;
    char **vars;            /* nvars labels ("expression", "log(size)") */
    int *var_factor;        /* 1 for a categorical variable */
    int64_t *nlevels;       /* factor levels (0 for numeric variables) */
    char ***levels;         /* levels[v][l], sorted */
    int64_t *codes;         /* N x nvars: level of row i of factor v (-1 numeric) */
    double *values;         /* N x nvars: the numeric column (log applied) */
    int *term_coding;       /* nterms x nvars: how term j codes factor v: 0 treatment
                               contrasts, 1 sum contrasts, 2 indicators; -1 when v is
                               numeric or not in the term */
    int64_t *col_level;     /* col_level[v + c nvars]: the level of factor v that column
                               c's code flags (+1 in it), -1 where v is not a factor of
                               c's term */
    es_contrasts contrasts;
} es_design;

/* Build the design of formula f for N rows from columns (every variable of
 * f must be among them, by name). Errors: ES_ENOTFOUND naming a variable
 * without a column; ES_EINVAL for a log of a value <= 0, a number where
 * none parses (log(NAME) of text: naming the row), a factor with one
 * level. Caller owns *out. */
ES_API es_status es_design_build(es_ctx *ctx, const es_formula *f, int64_t n,
                                 const es_model_column *columns, int64_t ncolumns,
                                 es_contrasts contrasts, es_design **out);
ES_API void es_design_free(es_design *d);

/* ---- fitting and testing --------------------------------------------------- */

typedef enum es_ss_type {
    ES_SS_TYPE_I = 1,   /* sequential: each term after those before it */
    ES_SS_TYPE_II = 2,  /* each term after every term that does not contain it */
    ES_SS_TYPE_III = 3  /* each term after all others (depends on the contrasts) */
} es_ss_type;

typedef enum es_perm_scheme {
    ES_PERM_RRPP = 0,   /* residuals of each term's reduced model (geomorph, RRPP) */
    ES_PERM_RAW         /* the rows themselves (vegan's adonis2) */
} es_perm_scheme;

typedef struct es_model_opts {
    es_ss_type ss_type;        /* ES_SS_TYPE_I */
    es_perm_scheme scheme;     /* ES_PERM_RRPP */
    int64_t permutations;      /* 999; 0: no p-values */
    const int64_t *blocks;     /* N block ids (>= 0): permute within blocks; or NULL */
    uint64_t seed;             /* 0: es_ctx_seed */
} es_model_opts;

/* Defaults as marked. */
ES_API void es_model_opts_init(es_model_opts *opts);

/* A fitted model. Arrays are owned by it (es_model_free). */
typedef struct es_model {
    es_ctx *ctx;
    int64_t n;              /* N rows */
    int64_t p;              /* variables of the response (E or k*d) */
    int64_t rank;           /* rank of the design */
    int64_t nterms;
    es_ss_type ss_type;
    es_perm_scheme scheme;
    int64_t permutations;
    uint64_t seed;          /* the seed the permutations came from */
    int64_t *df;            /* nterms: rank added by each term (0: aliased) */
    double *ss, *ms, *r2, *f, *pval;  /* nterms; pval NaN without permutations or
                                         when the term cannot be tested */
    int *testable;          /* nterms: 0 when blocks leave the term's SS unchanged
                               (a term constant within every block, e.g. the block) */
    int64_t df_resid;       /* N - rank */
    double rss, tss;        /* residual and total sums of squares */
    double *fperm;          /* permutations x nterms: F of each permutation */
    int64_t ncoef;          /* q */
    double *coef;           /* q x p (ld q): row c = coefficient of column c, NaN
                               for a column aliased by earlier ones */
    double *coef_weights;   /* N x q: column c = the row weights w with
                               coef_c = sum_i w_i y_i (0 for aliased columns) */
    double *mean;           /* p: the mean row */
    const es_design *design;   /* borrowed: must outlive the model */
    struct es_model_priv *priv;   /* the fit's bases and coordinates */
} es_model;

/* Fit the design d to the response src (p = src->nedges variables, N =
 * src->nrows = d->n rows) and test each term. Memory: the principal
 * coordinates (N x r, r <= min(N - 1, p)) and es_pca_fit's (its
 * components, p x r), the design's bases (N x q per term); time: one PCA
 * plus O(permutations x terms x (q + df) x N x r). Progress is reported
 * per batch of permutations.
 * Errors: ES_EINVAL (N != d->n, N <= rank: no residual degrees of freedom,
 * a block id < 0, permutations < 0, all rows equal), those of es_pca_fit. */
ES_API es_status es_model_fit(es_ctx *ctx, const es_design *d, const es_source *src,
                              const es_model_opts *opts, es_model **out);
ES_API void es_model_free(es_model *m);

/* The permutations a fit with this seed and these blocks uses, in order:
 * out (N x count, ld N), column b = permutation b + 1 (the observed order,
 * permutation 0, is not included): row i of the permuted data takes the
 * residual of row out[i + b N]. Fisher-Yates within each block, from
 * es_rng seeded with seed. */
ES_API es_status es_model_permutations(es_ctx *ctx, int64_t n, const int64_t *blocks,
                                       uint64_t seed, int64_t count, int64_t *out);

/* ---- after the fit ------------------------------------------------------------ */

/* Least-squares means of the levels of factor variable `var` (its label)
 * over a reference grid (the other factors' levels weighted equally, numeric
 * variables at their mean), their Euclidean distances, and permutation
 * p-values of each distance: the residuals of the model without the terms
 * holding `var` are permuted (within blocks) as in the fit, and
 * p = (1 + #{d* >= d}) / (1 + permutations). */
typedef struct es_model_pairwise {
    es_ctx *ctx;
    int64_t nlevels, p, n;
    char **levels;          /* nlevels */
    double *lsmeans;        /* nlevels x p (ld nlevels) */
    double *weights;        /* N x nlevels: LS mean l = sum_i w_il y_i */
    double *dist;           /* nlevels x nlevels */
    double *pval;           /* nlevels x nlevels (diagonal 1) */
} es_model_pairwise;
ES_API es_status es_model_pairwise_fit(es_ctx *ctx, const es_model *m, const char *var,
                                       es_model_pairwise **out);
ES_API void es_model_pairwise_free(es_model_pairwise *pw);

/* Per-variable tests of term `term` (its label): the univariate F of every
 * variable (edge) e, with the fit's reduced and full models and
 * permutations (the same permutation of the rows for every variable), its
 * permutation p-value and the Benjamini-Hochberg q-value over all
 * variables. f, pval, qval: p values each. permutations < 0: the fit's.
 * Time O(permutations x (df + q) x r x p); memory O(block x (df + q) x p). */
ES_API es_status es_model_variable_tests(es_ctx *ctx, const es_model *m, const char *term,
                                         int64_t permutations, double *f, double *pval,
                                         double *qval);

/* Benjamini-Hochberg (1995) adjusted p-values of p[0..n), as R's
 * p.adjust(method = "BH"); NaN entries stay NaN and do not count. */
ES_API es_status es_fdr_bh(es_ctx *ctx, int64_t n, const double *p, double *q);

/* The common allometric component (Mitteroecker et al. 2004): the unit
 * direction of the coefficient of numeric term `term` (e.g. "log(size)";
 * with a grouping factor in the model it is the pooled within-group
 * regression vector), cac (p), and each row's score, its centred data
 * projected on it, scores (N). ES_EINVAL unless term is one numeric
 * column. */
ES_API es_status es_model_cac(es_ctx *ctx, const es_model *m, const char *term, double *cac,
                              double *scores);

/* Index of the term with label `term` in m's design, or -1. */
ES_API int64_t es_model_find_term(const es_model *m, const char *term);

#ifdef __cplusplus
}
#endif
#endif
