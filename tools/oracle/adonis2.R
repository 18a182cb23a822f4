# tools/oracle/adonis2.R — the oracle of edgespace model: vegan's adonis2 on
# Euclidean distances between the rows of a response table (PERMANOVA; on
# Euclidean distances its sums of squares are those of the multivariate
# linear model), written as CSV (term, df, ss, r2, f, p) for
# tests/tools/test_model_oracle.c to compare with `edgespace model -o`.
#
#   Rscript adonis2.R RESPONSE.csv SKIP DESIGN.csv FORMULA BY STRATA NPERM SEED OUT.csv
#
# RESPONSE, SKIP, DESIGN: read by model_data.R (beside this script). BY: terms
# (sequential, type I) or margin (each term after all others). STRATA: a
# column whose values hold the permutations (blocks), or "-" for none.
# NPERM: a count (adonis2 draws them, seeded with SEED), or a CSV file of
# permutations, one per line, 1-based (es_model_permutations': row i of the
# permuted data is row perm[i]), which adonis2 takes as its permutation
# matrix: then its p-values must equal edgespace's exactly.
suppressMessages(library(vegan))
source(file.path(dirname(normalizePath(sub("^--file=", "", grep("^--file=", commandArgs(FALSE),
                                                            value = TRUE)))), "model_data.R"))
a <- commandArgs(trailingOnly = TRUE)
if (length(a) != 9) stop("usage: adonis2.R RESPONSE SKIP DESIGN FORMULA BY STRATA NPERM SEED OUT")
md <- read_model_data(a[1], a[2], a[3])
Y <- md$Y
des <- md$des
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
