/* lib/include/edgespace/es_model.h — linear models on shape with permutation
 * tests: formulas over label columns, design matrices (aliased terms left
 * out by name), sums of squares of type I, II and III, R^2 and F with
 * permutation p-values by residual randomization (RRPP) and RRPP's effect
 * sizes Z, blocks for repeated measures, error terms of nested designs,
 * coefficients as combinations of rows, pairwise comparisons of
 * least-squares means or of slopes with confidence limits, two models
 * compared, per-variable (per-edge, per-landmark) tests with
 * Benjamini-Hochberg FDR, and the common allometric component.
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
 * a:b, parentheses group sums ((a + b)*c); R's nesting: a/b means a + a:b
 * (b within a; (a + b)/c is a + b + a:b:c, a/b/c is a + a:b + a:b:c), and
 * b %in% a the term b:a. Terms are ordered by degree
 * (main effects, then two-way interactions, ...), keeping the written order
 * within a degree, as R's terms() does. Every model has an intercept. */
typedef struct es_formula es_formula;

typedef enum es_var_kind {
    ES_VAR_AUTO = 0,   /* NAME: numeric if every value is a finite number */
    ES_VAR_FACTOR,     /* factor(NAME) */
    ES_VAR_LOG         /* log(NAME) */
} es_var_kind;

/* Parse text. Errors are ES_EFORMAT naming the 1-based column:
 * "formula: column 9: expected a term after the '/' at column 8, found '+'".
 * A formula that expands to more than ES_FORMULA_MAX_TERMS terms is refused
 * before it is expanded (a*b*...*r, 18 names, would be 262,143 terms). */
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
    const char *reference;      /* a level of a categorical column to put first (the
                                   baseline of treatment contrasts, R's relevel), or NULL:
                                   levels in byte order */
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
    int64_t ndropped;       /* formula terms left out because they add no rank */
    char **dropped;         /* ndropped term labels */
    char **dropped_why;     /* ndropped: "duplicates 'sex'", "is a combination of 'a', 'b'" */
} es_design;

/* Build the design of formula f for N rows from columns (every variable of
 * f must be among them, by name). A term whose columns are combinations of
 * the intercept and the terms before it (the rank of the design's leading
 * columns by a pivoted QR does not grow) is left out with a one-line
 * warning naming the terms it duplicates, and listed in d->dropped; the
 * design is then rebuilt without it. Errors: ES_ENOTFOUND naming a variable
 * without a column; ES_EINVAL for a log of a value <= 0, a number where
 * none parses (log(NAME) of text: naming the row), a factor with one
 * level, a reference that is not a level (listing them), every term left
 * out. Caller owns *out. */
ES_API es_status es_design_build(es_ctx *ctx, const es_formula *f, int64_t n,
                                 const es_model_column *columns, int64_t ncolumns,
                                 es_contrasts contrasts, es_design **out);
ES_API void es_design_free(es_design *d);
/* Why term or variable `name` is not in d (a dropped term, or a variable
 * that only dropped terms hold): "duplicates 'sex'"; NULL if it is in d or
 * was never in the formula. Borrowed from d. */
ES_API const char *es_design_dropped(const es_design *d, const char *name);

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
    const int64_t *error;      /* nterms: the term whose mean square is term j's error
                                  (F = MS_j / MS_error, both from the same permutation, as
                                  RRPP's anova(error =) does for nested designs), -1 the
                                  residual; or NULL: the residual for all */
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
    int64_t *df;            /* nterms: rank added by each term (>= 1) */
    double *ss, *ms, *r2, *f, *pval;  /* nterms; pval NaN without permutations or
                                         when the term cannot be tested */
    double *z;              /* nterms: effect size of F (es_effect_size over the observed
                               and permuted F, RRPP's Z); NaN where pval is */
    int64_t *error;         /* nterms: the error term of each F (-1: the residual) */
    int *testable;          /* nterms: 0 when blocks leave the term's SS unchanged
                               (a term constant within every block, e.g. the block) */
    int64_t df_resid;       /* N - rank */
    double rss, tss;        /* residual and total sums of squares */
    double *fperm;          /* permutations x nterms: F of each permutation */
    double *ssperm;         /* permutations x nterms: SS of each permutation */
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
 * a block id < 0, permutations < 0, all rows equal, a model that fits the
 * rows exactly, a term that adds nothing under type II or III because terms
 * containing it hold its columns, an error term that is the term itself or
 * not in the model), those of es_pca_fit. */
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

/* Pairwise comparisons of the levels of factor variable `var` (its label):
 *  - of their least-squares means over a reference grid (the other factors'
 *    levels weighted equally, a factor nested in `var` (~ pop/ind: every
 *    term holding ind holds pop) over the levels seen with each level of
 *    var, as emmeans does; numeric variables at opts->at, default their
 *    mean as the formula uses them: mean of log(size), not log of mean
 *    size), or
 *  - with opts->covariate (a numeric variable of the model, "log(size)"),
 *    of their slopes on it: the within-level regression of the fitted
 *    values on the covariate (RRPP's pairwise(covariate =)), compared by
 *    distance, by the angle of their vector correlation and by the
 *    difference of their lengths.
 * Under permutation the residuals of a null model are permuted (within
 * blocks) as in the fit and the full model refitted: for LS means the model
 * without the terms holding `var`, for slopes the model without the terms
 * holding both `var` and the covariate (common slopes). For each statistic
 * s: p = #{s* >= s} / (1 + permutations) with the observed counted (RRPP's
 * pval), Z = es_effect_size of the observed and permuted values (RRPP's
 * effect.size), UCL = their quantile at opts->confidence (R's quantile
 * type 7, RRPP's upper confidence limit). A factor nested in another is
 * refused (ES_EINVAL): its levels differ from one level of the other to the
 * next. */
typedef struct es_model_pairwise_opts {
    const char *covariate;  /* compare slopes on this numeric variable; NULL: LS means */
    double confidence;      /* 0.95 */
    const double *at;       /* nvars of the design: the value of each numeric variable
                               for the LS means (NaN: its mean); or NULL: every mean */
} es_model_pairwise_opts;
ES_API void es_model_pairwise_opts_init(es_model_pairwise_opts *opts);

typedef struct es_model_pairwise {
    es_ctx *ctx;
    int64_t nlevels, p, n;
    char **levels;          /* nlevels */
    int slopes;             /* 1: lsmeans holds the levels' slopes on the covariate */
    double confidence;
    int64_t nvars;
    double *at;             /* nvars: the numeric variables' values of the LS means
                               (NaN for factors; for slopes the covariate's is NaN) */
    double *lsmeans;        /* nlevels x p (ld nlevels): LS means, or slopes */
    double *weights;        /* N x nlevels: row l = sum_i w_il y_i */
    double *dist;           /* nlevels x nlevels: Euclidean distances */
    double *pval, *z, *ucl; /* nlevels x nlevels: p (diagonal 1), Z, UCL of dist */
    /* slopes only, else NULL: nlevels x nlevels each */
    double *vcor;           /* vector correlation (cosine) of two slopes */
    double *angle, *angle_p, *angle_z, *angle_ucl;          /* its angle (radians) */
    double *dlength, *dlength_p, *dlength_z, *dlength_ucl;  /* |length a - length b| */
} es_model_pairwise;
ES_API es_status es_model_pairwise_fit(es_ctx *ctx, const es_model *m, const char *var,
                                       const es_model_pairwise_opts *opts,
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

/* The same for groups of variables: group[e] in [0, ngroups) for each of
 * the p variables; the statistic of group g is the multivariate F of its
 * variables together (SS and RSS summed over them), so a landmark's d
 * coordinates are tested as one displacement. f, pval, qval: ngroups. */
ES_API es_status es_model_group_tests(es_ctx *ctx, const es_model *m, const char *term,
                                      int64_t permutations, int64_t ngroups,
                                      const int64_t *group, double *f, double *pval,
                                      double *qval);

/* Benjamini-Hochberg (1995) adjusted p-values of p[0..n), as R's
 * p.adjust(method = "BH"); NaN entries stay NaN and do not count. */
ES_API es_status es_fdr_bh(es_ctx *ctx, int64_t n, const double *p, double *q);

/* The common allometric component (Mitteroecker et al. 2004): the pooled
 * within-group regression vector of the response on numeric term `term`
 * (e.g. "log(size)"): its coefficient in the model of it and every term
 * that does not hold its variable (groups and their interactions, other
 * covariates), so that interactions with size (~ log(size) * group) do not
 * change it; cac (p) its unit direction, scores (N) each row's centred data
 * projected on it. ES_EINVAL unless term is one numeric column. */
ES_API es_status es_model_cac(es_ctx *ctx, const es_model *m, const char *term, double *cac,
                              double *scores);

/* Two models of the same rows compared (RRPP's anova(null, full)): null's
 * design spans a subspace of full's (ES_EINVAL otherwise); SS = RSS_null -
 * RSS_full on df = rank_full - rank_null, F = (SS / df) / (RSS_full /
 * df_resid_full), R^2 = SS / TSS; the residuals of the null model are
 * permuted with full's seed and blocks, both models refitted to each
 * permuted response; p and Z as for terms. Both fits must come from the
 * same response (the same rows and values). */
typedef struct es_model_comparison {
    es_ctx *ctx;
    int64_t n, rank_null, rank_full, df, df_resid_null, df_resid_full, permutations;
    double rss_null, rss_full, tss, ss, ms, r2, f, pval, z;
    double *fperm;          /* permutations: F of each */
} es_model_comparison;
ES_API es_status es_model_compare(es_ctx *ctx, const es_model *null, const es_model *full,
                                  es_model_comparison **out);
ES_API void es_model_comparison_free(es_model_comparison *c);

/* RRPP's effect size (effect.size, Collyer & Adams 2018) of x[0], an
 * observed statistic, among x[0..n) (x[1..n) its permutation values): the
 * values are Box-Cox transformed (shifted by 1e-4 - min when any is <= 0)
 * with the lambda in [-5, 5] that maximizes the profile log-likelihood of
 * x[1..n) (R's optimise: Brent's golden-section search to tolerance
 * eps^0.25), centred, and z = (t_0 - mean t) / sd t (sd with divisor n).
 * All values equal: 0. NaN in x: NaN. */
ES_API es_status es_effect_size(es_ctx *ctx, const double *x, int64_t n, double *z);
/* R's quantile(x, prob, type = 7) of x[0..n): NaN entries left out. */
ES_API es_status es_quantile(es_ctx *ctx, const double *x, int64_t n, double prob, double *q);

/* Index of the term with label `term` in m's design, or -1. */
ES_API int64_t es_model_find_term(const es_model *m, const char *term);

#ifdef __cplusplus
}
#endif
#endif
