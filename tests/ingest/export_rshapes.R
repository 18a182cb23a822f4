# tests/ingest/export_rshapes.R OUTDIR — every landmark array of R's shapes
# package (brains, dna.dat, the apes, ...) written as edgespace reads them:
# OUTDIR/<name>_landmarks.csv (specimen,landmark,x,y[,z]) and
# OUTDIR/<name>_specimens.csv (specimen,set), ids "<name>_001" ... as in the
# tables that were refused before the specimens map was fixed. R's own sums
# of each array go to OUTDIR/<name>_oracle.csv (n,k,d,sum,sumsq,first,last)
# so the test checks what was read against R, not against the file it wrote.
args <- commandArgs(trailingOnly = TRUE)
out <- args[1]
suppressMessages(library(shapes))
items <- data(package = "shapes")$results[, "Item"]
env <- new.env()
for (item in items) {
  name <- sub(" .*", "", item)
  suppressWarnings(try(data(list = name, package = "shapes", envir = env), silent = TRUE))
  if (!exists(name, envir = env, inherits = FALSE)) next
  x <- get(name, envir = env)
  if (is.list(x) && !is.null(x$x)) x <- x$x
  if (!is.array(x) || length(dim(x)) != 3 || !is.numeric(x)) next
  if (any(!is.finite(x))) next
  k <- dim(x)[1]; d <- dim(x)[2]; n <- dim(x)[3]
  if (!(d %in% c(2, 3)) || n < 2) next
  base <- gsub("[^A-Za-z0-9]", "_", name)
  ids <- sprintf("%s_%03d", base, seq_len(n))
  rows <- expand.grid(landmark = seq_len(k), s = seq_len(n))
  coords <- t(sapply(seq_len(nrow(rows)), function(r) x[rows$landmark[r], , rows$s[r]]))
  long <- data.frame(specimen = ids[rows$s], landmark = rows$landmark, coords)
  names(long) <- c("specimen", "landmark", c("x", "y", "z")[seq_len(d)])
  # shuffled rows: the reader must not depend on the table's order
  set.seed(1)
  long <- long[sample(nrow(long)), ]
  write.csv(format(long, digits = 17), file.path(out, paste0(base, "_landmarks.csv")),
            row.names = FALSE, quote = FALSE)
  spec <- data.frame(specimen = ids, set = base)[sample(n), ]
  write.csv(spec, file.path(out, paste0(base, "_specimens.csv")), row.names = FALSE, quote = FALSE)
  oracle <- data.frame(n = n, k = k, d = d, sum = sum(x), sumsq = sum(x^2),
                       first = x[1, 1, 1], last = x[k, d, n])
  write.csv(format(oracle, digits = 17), file.path(out, paste0(base, "_oracle.csv")),
            row.names = FALSE, quote = FALSE)
}
