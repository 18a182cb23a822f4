# tools/oracle/rrpp_reference.R — an independent reference for what
# `edgespace model` adds to the SS/F/p that vegan checks: RRPP's effect
# sizes Z, pairwise distances of LS means and of slopes (with vector
# correlations, length differences and upper confidence limits), error terms
# of nested designs, the comparison of two models, the common allometric
# component and per-landmark tests. Written from the definitions with R's
# own tools on the response itself (model.matrix, qr, qr.fitted, optimise,
# quantile), never from the principal coordinates edgespace works on: the
# Collyer-Adams residual permutation (RRPP) with the permutations given.
#
#   Rscript rrpp_reference.R RESPONSE.csv SKIP DESIGN.csv FORMULA PERMS.csv OUTDIR [KEY=VALUE...]
#
# RESPONSE, SKIP, DESIGN as model_data.R reads them (rows matched by id;
# `size` from centroid_size or scale). PERMS: B rows of N 1-based indices, row i of a
# permuted response takes the residual of row perms[b, i] (what
# es_model_permutations writes). Keys: type=I|II|III, reference=FACTOR=LEVEL,
# pairwise=FACTOR, slopes=VAR, at=data (LS means at the columns' means, so
# log of mean size), error=TERM=ERROR, null=FORMULA, edges=TERM,
# dim=D (per-landmark tests of edges with D coordinates per landmark),
# cac=TERM. Writes OUTDIR/anova.csv (term, df, ss, ms, r2, f, z, p),
# pairwise.csv, comparison.csv, cac.csv (id, score), landmarks.csv (f, p).
a <- commandArgs(trailingOnly = TRUE)
if (length(a) < 6) stop("usage: rrpp_reference.R RESPONSE SKIP DESIGN FORMULA PERMS OUTDIR [K=V...]")
source(file.path(dirname(normalizePath(sub("^--file=", "", grep("^--file=", commandArgs(FALSE),
                                                            value = TRUE)))), "model_data.R"))
opt <- read_options(a[-(1:6)], list(type = "I"))
md <- read_model_data(a[1], a[2], a[3], opt$reference)
Y <- md$Y
des <- md$des
# A wide response (a face study's 27,871 lengths for 90 rows) is rotated into
# n columns, Y Q with Q from R's Householder QR of t(Y): every statistic here
# but the per-landmark ones depends on Y only through Y Y^T, which the
# rotation keeps (Gower 1966), and the permutations then cost n, not p.
if (ncol(Y) > nrow(Y) && is.null(opt$edges)) Y <- Y %*% qr.Q(qr(t(Y)))
perms <- as.matrix(read.csv(a[5], header = FALSE))
B <- nrow(perms)
n <- nrow(Y)
out <- a[6]
g17 <- function(x) ifelse(is.na(x), "NA", sprintf("%.17g", x))

# ---- RRPP's effect size and p-value, from their definitions ----------------
# effect.size (RRPP 2.0.2): Box-Cox of all values with the lambda in [-5, 5]
# that maximizes the profile log-likelihood of the random values (optimise),
# then the standard deviate of the first value, sd with divisor n.
box.cox <- function(y, eps = 0.001) {
  if (any(y <= 0)) y <- y - min(y) + 0.0001
  yr <- y[-1]
  yy <- yr / exp(mean(log(yr)))
  logy <- log(yy)
  ll <- function(la) {
    yt <- if (abs(la) > eps) (yy^la - 1) / la else
      logy * (1 + (la * logy) / 2 * (1 + (la * logy) / 3 * (1 + (la * logy) / 4)))
    -length(yr) / 2 * log(sum((yt - mean(yt))^2))
  }
  la <- optimise(ll, lower = -5, upper = 5, maximum = TRUE)$maximum
  if (abs(la) < eps) la <- 0
  if (la == 0) log(y) else (y^la - 1) / la
}
zscore <- function(x) {
  if (length(unique(x)) == 1) return(0)
  t <- box.cox(x)
  t <- t - mean(t)
  (t[1] - mean(t)) / sqrt(sum(t^2) / length(t))
}
pvalue <- function(x) mean(x >= x[1] - 1.4901161193847656e-08 * max(1, abs(x[1])))

# ---- the model -------------------------------------------------------------
form <- as.formula(paste("~", sub("^\\s*~", "", a[4])))
tt <- terms(form)
X <- model.matrix(tt, des)
asg <- attr(X, "assign")
labels <- attr(tt, "term.labels")
fac <- attr(tt, "factors")
T <- length(labels)
cols <- function(use) which(asg == 0 | asg %in% which(use))
reduced <- function(j) {
  if (opt$type == "I") return(seq_len(T) < j)
  if (opt$type == "III") return(seq_len(T) != j)
  sapply(seq_len(T), function(t) !all(fac[fac[, j] > 0, t] > 0))   # II: not containing j
}
rss <- function(Xs, Ys) sum(qr.resid(qr(Xs), Ys)^2)
fullq <- qr(X)
stream <- function(j) {   # SS of term j, and the complete model's RSS, per permutation
  Xr <- X[, cols(reduced(j)), drop = FALSE]
  Xf <- X[, cols(reduced(j) | seq_len(T) == j), drop = FALSE]
  qr_r <- qr(Xr)
  qr_f <- qr(Xf)
  Fr <- qr.fitted(qr_r, Y)
  Er <- Y - Fr
  df <- qr_f$rank - qr_r$rank
  one <- function(Ys) c(sum(qr.resid(qr_r, Ys)^2) - sum(qr.resid(qr_f, Ys)^2),
                        sum(qr.resid(fullq, Ys)^2))
  s <- cbind(one(Y), sapply(seq_len(B), function(b) one(Fr + Er[perms[b, ], , drop = FALSE])))
  list(ss = s[1, ], rss = s[2, ], df = df)
}
S <- lapply(seq_len(T), stream)
dfe <- n - fullq$rank
tss <- sum(scale(Y, scale = FALSE)^2)
errs <- rep(NA_integer_, T)
if (!is.null(opt$error)) {
  errs[match(sub("=.*", "", opt$error), labels)] <- match(sub("^[^=]*=", "", opt$error), labels)
}
rows <- lapply(seq_len(T), function(j) {
  s <- S[[j]]
  Fs <- if (is.na(errs[j])) (s$ss / s$df) / (s$rss / dfe) else
    (s$ss / s$df) / (S[[errs[j]]]$ss / S[[errs[j]]]$df)
  data.frame(term = labels[j], df = s$df, ss = g17(s$ss[1]), ms = g17(s$ss[1] / s$df),
             r2 = g17(s$ss[1] / tss), f = g17(Fs[1]), z = g17(zscore(Fs)), p = g17(pvalue(Fs)))
})
write.csv(do.call(rbind, rows), file.path(out, "anova.csv"), row.names = FALSE, quote = FALSE)

# ---- pairwise: LS means over a grid, or slopes -----------------------------
pair_table <- function(V, null_use) {   # V(Ys): the L compared vectors (L x p)
  X0 <- X[, cols(null_use), drop = FALSE]
  q0 <- qr(X0)
  F0 <- qr.fitted(q0, Y)
  E0 <- Y - F0
  vs <- c(list(V(Y)), lapply(seq_len(B), function(b) V(F0 + E0[perms[b, ], , drop = FALSE])))
  L <- nrow(vs[[1]])
  res <- NULL
  for (i in 1:(L - 1)) for (k in (i + 1):L) {
    d <- sapply(vs, function(v) sqrt(sum((v[i, ] - v[k, ])^2)))
    cs <- sapply(vs, function(v) sum(v[i, ] * v[k, ]) / sqrt(sum(v[i, ]^2) * sum(v[k, ]^2)))
    an <- acos(pmin(1, pmax(-1, cs)))
    dl <- sapply(vs, function(v) abs(sqrt(sum(v[i, ]^2)) - sqrt(sum(v[k, ]^2))))
    st <- function(x) c(g17(x[1]), g17(quantile(x, 0.95)), g17(zscore(x)), g17(pvalue(x)))
    res <- rbind(res, c(rownames(vs[[1]])[c(i, k)], st(d), g17(cs[1]), st(an * 180 / pi), st(dl)))
  }
  colnames(res) <- c("level_a", "level_b", "d", "ucl", "z", "p", "r", "angle", "angle_ucl",
                     "angle_z", "angle_p", "dlength", "dlength_ucl", "dlength_z", "dlength_p")
  res
}
if (!is.null(opt$pairwise)) {
  g <- opt$pairwise
  lev <- levels(des[[g]])
  holds <- function(v) fac[v, ] > 0
  if (is.null(opt$slopes)) {
    # emmeans' grid: every combination of the factors' levels, numeric
    # variables at their mean as the formula uses them (log(size): mean log),
    # or with at=data at the mean of the column (log of mean size, RRPP's)
    vars <- rownames(fac)
    grid <- list()
    for (v in all.vars(form)) {
      x <- des[[v]]
      grid[[v]] <- if (is.factor(x)) factor(levels(x), levels = levels(x)) else
        if (any(vars == paste0("log(", v, ")")) && is.null(opt$at)) exp(mean(log(x))) else mean(x)
    }
    grid <- expand.grid(grid)
    G <- model.matrix(tt, grid)
    W <- t(sapply(lev, function(l) colMeans(G[grid[[g]] == l, , drop = FALSE])))
    V <- function(Ys) {
      b <- qr.coef(fullq, Ys)
      b[is.na(b)] <- 0
      W %*% b
    }
    tab <- pair_table(V, !holds(g))[, 1:6, drop = FALSE]
  } else {
    x <- eval(parse(text = opt$slopes), des)
    V <- function(Ys) {
      fit <- qr.fitted(fullq, Ys)
      t(sapply(lev, function(l) {
        k <- des[[g]] == l
        xc <- x[k] - mean(x[k])
        colSums(xc * fit[k, , drop = FALSE]) / sum(xc^2)
      }))
    }
    sv <- rownames(fac)[rownames(fac) == opt$slopes]
    tab <- pair_table(V, !(holds(g) & fac[sv, ] > 0))
  }
  write.csv(tab, file.path(out, "pairwise.csv"), row.names = FALSE, quote = FALSE)
}

# ---- two models compared ------------------------------------------------------
if (!is.null(opt$null)) {
  X0 <- model.matrix(as.formula(paste("~", sub("^\\s*~", "", opt$null))), des)
  q0 <- qr(X0)
  F0 <- qr.fitted(q0, Y)
  E0 <- Y - F0
  df <- fullq$rank - q0$rank
  fs <- function(Ys) {
    r1 <- sum(qr.resid(fullq, Ys)^2)
    ((sum(qr.resid(q0, Ys)^2) - r1) / df) / (r1 / dfe)
  }
  Fs <- c(fs(Y), sapply(seq_len(B), function(b) fs(F0 + E0[perms[b, ], , drop = FALSE])))
  ss <- rss(X0, Y) - rss(X, Y)
  write.csv(data.frame(df = df, ss = g17(ss), r2 = g17(ss / tss), f = g17(Fs[1]),
                       z = g17(zscore(Fs)), p = g17(pvalue(Fs))),
            file.path(out, "comparison.csv"), row.names = FALSE, quote = FALSE)
}

# ---- the common allometric component: size after every term without it ------
if (!is.null(opt$cac)) {
  sv <- opt$cac
  x <- eval(parse(text = sv), des)
  X0 <- X[, cols(!(fac[sv, ] > 0)), drop = FALSE]
  r <- qr.resid(qr(X0), x)
  Yc <- scale(Y, scale = FALSE)
  b <- crossprod(Yc, r)
  cac <- b / sqrt(sum(b^2))
  write.csv(data.frame(id = md$ids, score = g17(Yc %*% cac)), file.path(out, "cac.csv"),
            row.names = FALSE, quote = FALSE)
}

# ---- per-landmark tests: a landmark's coordinates together -----------------------
if (!is.null(opt$edges)) {
  j <- match(opt$edges, labels)
  D <- as.integer(opt$dim)
  K <- ncol(Y) / D
  Xr <- X[, cols(reduced(j)), drop = FALSE]
  Xf <- X[, cols(reduced(j) | seq_len(T) == j), drop = FALSE]
  qr_r <- qr(Xr)
  qr_f <- qr(Xf)
  df <- qr_f$rank - qr_r$rank
  Fr <- qr.fitted(qr_r, Y)
  Er <- Y - Fr
  lmF <- function(Ys) {
    a <- colSums(qr.fitted(qr_f, Ys)^2 - qr.fitted(qr_r, Ys)^2)
    e <- colSums(qr.resid(fullq, Ys)^2)
    sapply(seq_len(K), function(k) {
      c <- k + (0:(D - 1)) * K
      (sum(a[c]) / df) / (sum(e[c]) / dfe)
    })
  }
  Fs <- cbind(lmF(Y), sapply(seq_len(B), function(b) lmF(Fr + Er[perms[b, ], , drop = FALSE])))
  write.csv(data.frame(landmark = seq_len(K), f = g17(Fs[, 1]), p = g17(apply(Fs, 1, pvalue))),
            file.path(out, "landmarks.csv"), row.names = FALSE, quote = FALSE)
}
