# tools/oracle/rrpp.R — RRPP itself (lm.rrpp, anova, pairwise, summary) on
# the same data and with the very permutations edgespace used, where an
# RRPP is installed (it is not a Debian package: tools/oracle/install_rrpp.sh
# builds it from its source with Debian's R packages). RRPP draws its own
# permutations through its internal perm.index; that one function is
# replaced by one that hands back ours, so p-values and effect sizes can be
# compared number for number. Same arguments and outputs as
# rrpp_reference.R (anova.csv, pairwise.csv, comparison.csv); the library
# is taken from $ES_RRPP_LIB when set.
lib <- Sys.getenv("ES_RRPP_LIB")
if (nzchar(lib)) .libPaths(c(lib, .libPaths()))
suppressMessages(library(RRPP))
a <- commandArgs(trailingOnly = TRUE)
source(file.path(dirname(normalizePath(sub("^--file=", "", grep("^--file=", commandArgs(FALSE),
                                                            value = TRUE)))), "model_data.R"))
opt <- read_options(a[-(1:6)], list(type = "I"))
md <- read_model_data(a[1], a[2], a[3], opt$reference)
Y <- md$Y
des <- md$des
perms <- as.matrix(read.csv(a[5], header = FALSE))
B <- nrow(perms)
n <- nrow(Y)
out <- a[6]
g17 <- function(x) ifelse(is.na(x), "NA", sprintf("%.17g", x))
ours <- c(list(seq_len(n)), lapply(seq_len(B), function(b) as.integer(perms[b, ])))
names(ours) <- c("obs", paste("iter", seq_len(B), sep = "."))
attr(ours, "seed") <- 1
assignInNamespace("perm.index", function(n, iter, block = NULL, seed = NULL) ours, "RRPP")

dat <- des
dat$Y <- Y
fitf <- function(rhs) lm.rrpp(as.formula(paste("Y", sub("^\\s*~", "~", rhs))), data = dat,
                              iter = B, SS.type = opt$type, print.progress = FALSE)
fit <- fitf(a[4])
err <- NULL
labels <- attr(terms(as.formula(a[4])), "term.labels")
if (!is.null(opt$error)) {
  err <- rep("Residuals", length(labels))
  err[match(sub("=.*", "", opt$error), labels)] <- sub("^[^=]*=", "", opt$error)
}
av <- anova(fit, effect.type = "F", error = err)$table
k <- seq_along(labels)
write.csv(data.frame(term = labels, df = av$Df[k], ss = g17(av$SS[k]), ms = g17(av$MS[k]),
                     r2 = g17(av$Rsq[k]), f = g17(av$F[k]), z = g17(av$Z[k]),
                     p = g17(av[k, ncol(av)])),
          file.path(out, "anova.csv"), row.names = FALSE, quote = FALSE)
if (!is.null(opt$pairwise)) {
  g <- opt$pairwise
  tl <- terms(as.formula(a[4]))
  fac <- attr(tl, "factors")
  keep <- if (is.null(opt$slopes)) fac[g, ] == 0 else !(fac[g, ] > 0 & fac[opt$slopes, ] > 0)
  rhs0 <- if (any(keep)) paste("~", paste(labels[keep], collapse = " + ")) else "~ 1"
  pw <- pairwise(fit, fit.null = fitf(rhs0), groups = des[[g]],
                 covariate = if (is.null(opt$slopes)) NULL else eval(parse(text = opt$slopes), des))
  d <- summary(pw, test.type = "dist", confidence = 0.95)$summary.table
  lv <- do.call(rbind, strsplit(rownames(d), ":"))
  tab <- data.frame(level_a = lv[, 1], level_b = lv[, 2], d = g17(d[, 1]), ucl = g17(d[, 2]),
                    z = g17(d[, 3]), p = g17(d[, 4]))
  if (!is.null(opt$slopes)) {
    v <- summary(pw, test.type = "VC", angle.type = "deg", confidence = 0.95)$summary.table
    dl <- summary(pw, test.type = "DL", confidence = 0.95)$summary.table
    tab <- cbind(tab, r = g17(v[, 1]), angle = g17(v[, 2]), angle_ucl = g17(v[, 3]),
                 angle_z = g17(v[, 4]), angle_p = g17(v[, 5]), dlength = g17(dl[, 1]),
                 dlength_ucl = g17(dl[, 2]), dlength_z = g17(dl[, 3]), dlength_p = g17(dl[, 4]))
  }
  write.csv(tab, file.path(out, "pairwise.csv"), row.names = FALSE, quote = FALSE)
}
if (!is.null(opt$null)) {
  cmp <- anova(fitf(opt$null), fit, effect.type = "F")$table
  # RRPP 2.0's table ends with a column its code adds by a typo (tab$DF); P holds p
  pc <- if ("P" %in% names(cmp)) cmp$P[2] else cmp[2, ncol(cmp)]
  write.csv(data.frame(df = cmp$Df[2], ss = g17(cmp$SS[2]), r2 = g17(cmp$Rsq[2]),
                       f = g17(cmp$F[2]), z = g17(cmp$Z[2]), p = g17(pc)),
            file.path(out, "comparison.csv"), row.names = FALSE, quote = FALSE)
}
