# tools/oracle/model_data.R — the data the model oracles read, read one way
# (sourced by adonis2.R, rrpp_reference.R and rrpp.R):
#   RESPONSE.csv: first column the row id, then SKIP label columns, then the
#   variables (edgespace export --lengths, or a GPA's aligned table);
#   DESIGN.csv: first column the row id, then label columns (rows matched by
#   id). Columns that are all numbers are numeric, others factors (as
#   edgespace reads them); `size` is taken from a column centroid_size or
#   scale when the design has no `size`; reference "FACTOR=LEVEL" relevels.
read_model_data <- function(response, skip, design, reference = NULL) {
  skip <- as.integer(skip)
  ncol <- length(scan(response, what = "", sep = ",", nlines = 1, quiet = TRUE))
  resp <- read.csv(response, check.names = FALSE,
                   colClasses = c(rep("character", 1 + skip), rep("numeric", ncol - 1 - skip)))
  des <- read.csv(design, check.names = FALSE, colClasses = "character")
  names(des)[1] <- "id"
  des <- des[match(resp[[1]], des$id), , drop = FALSE]
  if (anyNA(des$id)) stop("design lacks some response ids")
  for (c in names(des)[-1]) {
    v <- suppressWarnings(as.numeric(des[[c]]))
    des[[c]] <- if (!anyNA(v)) v else factor(des[[c]])
  }
  if (!("size" %in% names(des))) {
    if ("centroid_size" %in% names(des)) des$size <- des$centroid_size
    else if ("scale" %in% names(des)) des$size <- des$scale
  }
  if (!is.null(reference)) {
    f <- sub("=.*", "", reference)
    des[[f]] <- relevel(des[[f]], sub("^[^=]*=", "", reference))
  }
  list(ids = resp[[1]], Y = as.matrix(resp[, -(1:(1 + skip)), drop = FALSE]), des = des)
}

# KEY=VALUE arguments into a list (the value after the first '=').
read_options <- function(kv, defaults = list()) {
  for (x in kv) defaults[[sub("=.*", "", x)]] <- sub("^[^=]*=", "", x)
  defaults
}
