# How often the report's tests across participants reject a true null at 0.05 (a measurement, not a unit test; about
# 10 minutes of CPU). Run: Rscript analysis/tests/measure_glmm_type1.R [REPS]   (seed fixed below)
#
# Simulated observers: G participants, 6 answers at each of 11 edges (x = edge - 6), logit p = 0.3 + u + v x with
# u ~ N(0, 0.8^2) and v ~ N(0, 0.3^2) per participant: the average slope is 0, so every rejection of the slope is an
# error. The GLMM is fitted as analysis/models.R fits it (bobyqa; the maximal (1 + x | g), else (1 | g) when that is
# singular or does not converge, with the reduced random part between them); the cluster-robust GLM as analysis/stats.py's (CR1: sandwich::vcovCL type HC1,
# whose factor is G/(G-1) (N-1)/(N-K); written out below, as sandwich::vcovCL type HC1 computes it, since
# scripts/setup.sh does not install r-cran-sandwich).
suppressPackageStartupMessages(library(lme4))
args <- commandArgs(trailingOnly = TRUE)
reps <- if (length(args)) as.integer(args[1]) else 300
set.seed(20261126)
ctrl <- glmerControl(optimizer = "bobyqa", optCtrl = list(maxfun = 2e5))
quiet <- function(expr) suppressMessages(suppressWarnings(expr))
one <- function(G) {
  d <- expand.grid(rep = 1:6, edge = 1:11, g = factor(1:G))
  d$x <- d$edge - 6
  u <- rnorm(G, 0, 0.8)
  v <- rnorm(G, 0, 0.3)
  d$y <- rbinom(nrow(d), 1, plogis(0.3 + u[d$g] + v[d$g] * d$x))
  m <- quiet(glmer(y ~ x + (1 + x | g), d, binomial, control = ctrl))
  conv <- m@optinfo$conv$lme4$messages
  kept <- !isSingular(m) && !length(conv[!grepl("singular", conv)])
  z_max <- coef(summary(m))["x", "z value"]
  m0 <- quiet(glmer(y ~ x + (1 | g), d, binomial, control = ctrl))
  z_int <- coef(summary(m0))["x", "z value"]
  # models.R's reduced random part (reduce_random): the slope uncorrelated, then without a component at 0.
  reduced <- FALSE
  z_red <- NA
  if (!kept) {
    ok <- function(m) { conv <- m@optinfo$conv$lme4$messages
                        !isSingular(m) && !length(conv[!grepl("singular", conv)]) }
    mu <- quiet(glmer(y ~ x + (1 | g) + (0 + x | g), d, binomial, control = ctrl))
    if (ok(mu)) {
      reduced <- TRUE; z_red <- coef(summary(mu))["x", "z value"]
    } else {
      vc <- as.data.frame(VarCorr(mu))
      alive <- vc$var1[is.na(vc$var2) & vc$sdcor >= 1e-4]
      if ("x" %in% alive) {
        mr <- quiet(glmer(if ("(Intercept)" %in% alive) y ~ x + (1 | g) + (0 + x | g) else y ~ x + (0 + x | g),
                          d, binomial, control = ctrl))
        if (ok(mr)) { reduced <- TRUE; z_red <- coef(summary(mr))["x", "z value"] }
      }
    }
  }
  z_chosen <- if (kept) z_max else z_int
  g <- glm(y ~ x, binomial, d)
  X <- model.matrix(g)
  bread <- solve(crossprod(X, X * g$weights))
  scores <- rowsum(X * (d$y - fitted(g)), d$g)
  N <- nrow(X); K <- ncol(X)
  V <- G / (G - 1) * (N - 1) / (N - K) * bread %*% crossprod(scores) %*% bread
  z_cr1 <- coef(g)["x"] / sqrt(V[2, 2])
  reject_t <- function(z) 2 * pt(-abs(z), G - 1) < 0.05
  c(kept = kept, kept_t = kept && reject_t(z_max), fallback_t = !kept && reject_t(z_int),
    reduced = reduced, reduced_t = reduced && reject_t(z_red),
    chosen_z = 2 * pnorm(-abs(z_chosen)) < 0.05, chosen_t = reject_t(z_chosen), cr1_t = unname(reject_t(z_cr1)))
}
for (G in c(4, 8)) {
  r <- t(replicate(reps, one(G)))
  k <- sum(r[, "kept"])
  cat(sprintf(paste0("G = %d, %d data sets: maximal model kept in %d; rejected at 0.05 by",
                     "\n  the maximal GLMM's Wald t(G-1) where kept (the report's GLMM p)  %.3f of %d",
                     "\n  the reduced random part's Wald t(G-1) where it kept the slope   %.3f of %d",
                     "\n  the intercept-only fallback's Wald t(G-1) (the report gives none) %.3f of %d",
                     "\n  maximal else intercept-only, Wald z (normal reference)         %.3f",
                     "\n  maximal else intercept-only, Wald t(G-1)                       %.3f",
                     "\n  the cluster-robust GLM, CR1 and t(G-1)                         %.3f\n"),
              G, reps, k, sum(r[, "kept_t"]) / max(k, 1), k, sum(r[, "reduced_t"]) / max(sum(r[, "reduced"]), 1),
              sum(r[, "reduced"]), sum(r[, "fallback_t"]) / max(reps - k, 1), reps - k,
              mean(r[, "chosen_z"]), mean(r[, "chosen_t"]), mean(r[, "cr1_t"])))
}
