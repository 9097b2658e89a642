# Mixed models across participants by lme4, for analysis/mixed.py (which writes the data and reads the table back).
#
#   Rscript models.R KIND DATA.csv OUT.csv SLOPES
#
# KIND    glmm (binomial glmer, Laplace) or lmm (lmer, REML, lmerTest's Satterthwaite df)
# DATA    columns y (0/1 for glmm), g (the participant), X0 .. Xk (the fixed-effects design, intercept included as a
#         column of ones where the model has one: the fixed part is y ~ 0 + X0 + ... + Xk)
# SLOPES  comma-separated design columns given a random slope by participant in the maximal model ("" = none)
#
# The maximal model is (1 + SLOPES | g); when it is singular, does not converge or fails, the intercept-only model
# (1 | g) is fitted instead and the table says which and why. OUT has the columns
#   row (fixed / sd / corr / info), term, estimate, se, df, p, note
# Exit 4 with one line on stderr when a package is missing; any other failure is an info row, never a traceback.
args <- commandArgs(trailingOnly = TRUE)
if (length(args) < 3) {
  cat("usage: Rscript models.R glmm|lmm DATA.csv OUT.csv [SLOPES]\n", file = stderr())
  quit(status = 2)
}
kind <- args[1]
data_path <- args[2]
out_path <- args[3]
slopes <- if (length(args) >= 4 && nzchar(args[4])) strsplit(args[4], ",")[[1]] else character()

needed <- c("lme4", if (kind == "lmm") "lmerTest")
for (pkg in needed) {
  if (!requireNamespace(pkg, quietly = TRUE)) {
    cat(sprintf("missing R package: %s\n", pkg), file = stderr())
    quit(status = 4)
  }
}
suppressPackageStartupMessages(library(lme4))

rows <- list()
emit <- function(row, term, estimate = NA, se = NA, df = NA, p = NA, note = "") {
  rows[[length(rows) + 1]] <<- data.frame(row = row, term = term, estimate = estimate, se = se, df = df, p = p,
                                          note = note, stringsAsFactors = FALSE)
}
finish <- function() {
  out <- if (length(rows)) do.call(rbind, rows) else
    data.frame(row = character(), term = character(), estimate = numeric(), se = numeric(), df = numeric(),
               p = numeric(), note = character())
  write.csv(out, out_path, row.names = FALSE, na = "")
  quit(status = 0)
}

d <- read.csv(data_path, stringsAsFactors = FALSE)
d$g <- factor(d$g)
xs <- grep("^X[0-9]+$", names(d), value = TRUE)
n_groups <- nlevels(d$g)
version <- packageDescription("lme4")$Version
engine <- if (kind == "glmm") {
  sprintf("lme4 %s glmer (Laplace), Wald t(G-1)", version)
} else {
  sprintf("lme4 %s lmer (REML), lmerTest %s Satterthwaite df", version, packageDescription("lmerTest")$Version)
}
emit("info", "engine", note = engine)

formula_of <- function(random) {
  as.formula(paste("y ~ 0 +", paste(xs, collapse = " + "), "+", random))
}

# One fit with its warnings and messages kept (lme4 says "boundary (singular) fit" as a message, convergence
# trouble as warnings).
fit_one <- function(random) {
  said <- character()
  f <- formula_of(random)
  m <- withCallingHandlers(
    tryCatch(
      if (kind == "glmm") {
        glmer(f, data = d, family = binomial,
              control = glmerControl(optimizer = "bobyqa", optCtrl = list(maxfun = 2e5)))
      } else {
        lmerTest::lmer(f, data = d, REML = TRUE, control = lmerControl(optimizer = "bobyqa"))
      },
      error = function(e) e),
    warning = function(w) { said <<- c(said, conditionMessage(w)); invokeRestart("muffleWarning") },
    message = function(m) { said <<- c(said, trimws(conditionMessage(m))); invokeRestart("muffleMessage") })
  if (inherits(m, "error")) {
    return(list(ok = FALSE, why = sprintf("failed (%s)", conditionMessage(m)), m = NULL, random = random))
  }
  conv <- c(m@optinfo$conv$lme4$messages, if (m@optinfo$conv$opt != 0) "the optimizer did not finish",
            said[grepl("converge|unidentifiable|Hessian", said)])
  conv <- unique(conv[!grepl("singular", conv)])
  if (length(conv)) {
    return(list(ok = FALSE, why = sprintf("did not converge (%s)", paste(conv, collapse = "; ")), m = m, random = random,
                converged = FALSE))
  }
  if (isSingular(m)) {
    return(list(ok = FALSE, why = "was singular (a variance estimated at 0 or a correlation at +-1)", m = m,
                random = random, converged = TRUE, singular = TRUE))
  }
  list(ok = TRUE, m = m, random = random, converged = TRUE, singular = FALSE)
}

intercept_only <- "(1 | g)"
if (length(slopes)) {
  maximal <- sprintf("(1 + %s | g)", paste(slopes, collapse = " + "))
  first <- fit_one(maximal)
  if (first$ok) {
    chosen <- first
    structure <- sprintf("random intercept and slopes by participant (%s)", paste(slopes, collapse = ", "))
  } else {
    chosen <- fit_one(intercept_only)
    structure <- sprintf("random intercept only: the model with random slopes (%s) %s",
                         paste(slopes, collapse = ", "), first$why)
  }
} else {
  chosen <- fit_one(intercept_only)
  structure <- "random intercept only (no within-participant term to give a slope)"
}
emit("info", "structure", note = structure)

if (is.null(chosen$m)) {
  emit("info", "failed", note = chosen$why)
  finish()
}
m <- chosen$m
if (!isTRUE(chosen$converged)) {
  emit("info", "failed", note = chosen$why)
  finish()
}
singular <- isTRUE(chosen$singular)
if (singular) emit("info", "singular", note = chosen$why)

if (kind == "glmm") {
  co <- coef(summary(m))
  df <- n_groups - 1
  for (term in rownames(co)) {
    z <- co[term, "Estimate"] / co[term, "Std. Error"]
    emit("fixed", term, co[term, "Estimate"], co[term, "Std. Error"], df, 2 * pt(-abs(z), df))
  }
} else {
  co <- coef(summary(m, ddf = "Satterthwaite"))
  for (term in rownames(co)) {
    emit("fixed", term, co[term, "Estimate"], co[term, "Std. Error"], co[term, "df"], co[term, "Pr(>|t|)"])
  }
}

# Variance components: an SD on its bound (isSingular's tolerance on the relative covariance factor) is said in
# words by the caller, never printed as a number.
vc <- as.data.frame(VarCorr(m))
for (i in seq_len(nrow(vc))) {
  r <- vc[i, ]
  if (r$grp == "Residual") {
    emit("sd", "Residual", r$sdcor)
  } else if (is.na(r$var2)) {
    name <- if (r$var1 == "(Intercept)") "Intercept" else r$var1
    tiny <- r$sdcor < 1e-4 * max(1, if (kind == "lmm") sigma(m) else 1)
    emit("sd", name, if (tiny) 0 else r$sdcor, note = if (tiny) "singular" else "")
  } else {
    a <- if (r$var1 == "(Intercept)") "Intercept" else r$var1
    b <- if (r$var2 == "(Intercept)") "Intercept" else r$var2
    emit("corr", paste(a, b, sep = ":"), r$sdcor, note = if (abs(r$sdcor) > 0.999) "singular" else "")
  }
}
finish()
