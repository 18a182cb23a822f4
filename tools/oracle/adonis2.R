# tools/oracle/adonis2.R — the oracle of edgespace model: vegan's adonis2 on
# Euclidean distances between the rows of a response table (PERMANOVA; on
# Euclidean distances its sums of squares are those of the multivariate
# linear model), written as CSV (term, df, ss, r2, f, p) for
# tests/tools/test_model_oracle.c to compare with `edgespace model -o`.
#
#   Rscript adonis2.R RESPONSE.csv SKIP DESIGN.csv FORMULA BY STRATA NPERM SEED OUT.csv
#
# RESPONSE: first column the row id, then SKIP label columns, then the
# variables. DESIGN: first column the row id, then the label columns the
# formula names (rows matched by id). Columns that are all numbers are
# numeric, others factors (as edgespace reads them); `size` is taken from a
# column centroid_size or scale when the design has no `size`. BY: terms
# (sequential, type I) or margin (each term after all others). STRATA: a
# column whose values hold the permutations (blocks), or "-" for none.
# NPERM: a count (adonis2 draws them, seeded with SEED), or a CSV file of
# permutations, one per line, 1-based (es_model_permutations': row i of the
# permuted data is row perm[i]), which adonis2 takes as its permutation
# matrix: then its p-values must equal edgespace's exactly.
suppressMessages(library(vegan))
a <- commandArgs(trailingOnly = TRUE)
if (length(a) != 9) stop("usage: adonis2.R RESPONSE SKIP DESIGN FORMULA BY STRATA NPERM SEED OUT")
skip <- as.integer(a[2])
ncol <- length(scan(a[1], what = "", sep = ",", nlines = 1, quiet = TRUE))
resp <- read.csv(a[1], check.names = FALSE,
                 colClasses = c(rep("character", 1 + skip), rep("numeric", ncol - 1 - skip)))
des <- read.csv(a[3], check.names = FALSE, colClasses = "character")
names(des)[1] <- "id"
ids <- resp[[1]]
des <- des[match(ids, des$id), , drop = FALSE]
if (anyNA(des$id)) stop("design lacks some response ids")
Y <- as.matrix(resp[, -(1:(1 + skip)), drop = FALSE])
for (c in names(des)[-1]) {
  v <- suppressWarnings(as.numeric(des[[c]]))
  des[[c]] <- if (!anyNA(v)) v else factor(des[[c]])
}
if (!("size" %in% names(des))) {
  if ("centroid_size" %in% names(des)) des$size <- des$centroid_size
  else if ("scale" %in% names(des)) des$size <- des$scale
}
f <- as.formula(paste("dist(Y)", a[4]))
set.seed(as.integer(a[8]))
perm <- if (file.exists(a[7])) as.matrix(read.csv(a[7], header = FALSE)) else
  if (a[6] == "-") as.integer(a[7]) else
  permute::how(nperm = as.integer(a[7]), blocks = des[[a[6]]])
res <- adonis2(f, data = des, by = a[5], permutations = perm)
g <- function(x) ifelse(is.na(x), "NA", sprintf("%.17g", x))   # round trip
out <- data.frame(term = rownames(res), df = res$Df, ss = g(res$SumOfSqs), r2 = g(res$R2),
                  f = g(res$F), p = g(res[["Pr(>F)"]]))
write.csv(out, a[9], row.names = FALSE, quote = FALSE)
