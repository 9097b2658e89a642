# Mixed models across participants by lme4, for analysis/mixed.py (which writes the data and reads the table back).
#
#   Rscript models.R KIND DATA.csv OUT.csv SLOPES [FACTORS]   one model
#   Rscript models.R --serve                        many: one job per line on stdin, KIND DATA OUT SLOPES FACTORS separated
#                                                   by tabs, each answered by a line "done" once OUT is written (R and
#                                                   lme4 start once per report, not once per model)
#
# KIND    glmm (binomial glmer, Laplace) or lmm (lmer, REML, lmerTest's Satterthwaite df); group_glmm and group_lmm
#         are a between-subject group crossed with a within factor (group_job below, for analysis/groups.py: its own
#         DATA columns, SLOPES unused)
# DATA    columns y (0/1 for glmm), g (the participant), X0 .. Xk (the fixed-effects design, intercept included as a
#         column of ones where the model has one: the fixed part is y ~ 0 + X0 + ... + Xk)
# SLOPES  comma-separated design columns given a random slope by participant in the maximal model ("" = none)
# FACTORS optional: the SLOPES of one factor's levels comma-separated, factors separated by ";" - reduced as one
#         participant-by-level effect (1 | g:F), the same model whatever the factor's reference level
#
# The maximal model is (1 + SLOPES | g); when it is singular, does not converge or fails, the slopes uncorrelated,
# then without the components estimated at 0 (reduce_random), and only then the intercept-only model (1 | g); the
# table says which and why (info rows structure, slopes: the slopes kept, intercept: yes / no). OUT has the columns
#   row (fixed / sd / corr / info), term, estimate, se, df, p, note
# lme4 missing: exit 4 with one line on stderr. lmerTest missing: an info row 'missing'. Any other failure: an info
# row 'failed' with R's message, never a traceback.
if (!requireNamespace("lme4", quietly = TRUE)) {
  cat("missing R package: lme4\n", file = stderr())
  quit(status = 4)
}
suppressPackageStartupMessages(library(lme4))

# A fit is kept only when it is determined (fit_one): the two optimizers below both finish, lme4's convergence checks
# (check.conv: the gradient, the Hessian) pass for at least one of them, the two agree on the log-likelihood within
# LOGLIK_TOL and on every fixed effect within ESTIMATE_TOL_SE of its SE (or ESTIMATE_TOL_ABS), and, for a glmm, no
# participants' SD exceeds SD_BOUND log-odds. Found in a two-group study: bobyqa alone printed edge 11 = 12.23
# (p 0.097) with an SD of 46.9 log-odds between participants, where lme4's default optimizer reached 1.94 with a
# convergence warning and another level order a higher likelihood - the likelihood is flat out there (a participant
# or cell whose answers nearly all went one way), so no optimizer's numbers are an estimate. An SD of 10 log-odds
# puts a typical participant's odds e^10 (22000) times another's: beyond it, no spread the answers can show.
OPTIMIZERS <- c("bobyqa", "Nelder_Mead")  # glmer's default is bobyqa, then Nelder_Mead; each alone, compared
LOGLIK_TOL <- 0.01
ESTIMATE_TOL_SE <- 0.1
ESTIMATE_TOL_ABS <- 0.01
SD_BOUND <- 10

# One optimizer's fit with its warnings and messages kept (lme4 says "boundary (singular) fit" as a message,
# convergence trouble as warnings): list(m, conv = the convergence messages, why = the error) .
fit_with <- function(kind, f, d, optimizer) {
  said <- character()
  m <- withCallingHandlers(
    tryCatch(
      if (kind == "glmm") {
        glmer(f, data = d, family = binomial,
              control = glmerControl(optimizer = optimizer, optCtrl = list(maxfun = 2e5)))
      } else {
        lmerTest::lmer(f, data = d, REML = TRUE,
                       control = lmerControl(optimizer = optimizer, optCtrl = list(maxfun = 2e5)))
      },
      error = function(e) e),
    warning = function(w) { said <<- c(said, conditionMessage(w)); invokeRestart("muffleWarning") },
    message = function(m) { said <<- c(said, trimws(conditionMessage(m))); invokeRestart("muffleMessage") })
  if (inherits(m, "error")) return(list(m = NULL, why = conditionMessage(m)))
  conv <- c(m@optinfo$conv$lme4$messages, if (m@optinfo$conv$opt != 0) "the optimizer did not finish",
            said[grepl("converge|unidentifiable|Hessian", said)])
  list(m = m, conv = unique(conv[!grepl("singular", conv)]))
}

# Why two fits of one model are not the same fit ("" when they agree within the tolerances above).
disagreement <- function(a, b) {
  la <- as.numeric(logLik(a$m))
  lb <- as.numeric(logLik(b$m))
  fa <- fixef(a$m)
  fb <- fixef(b$m)
  se <- sqrt(pmax(diag(as.matrix(vcov(if (la >= lb) a$m else b$m))), 0))
  off <- names(fa)[abs(fa - fb) > pmax(ESTIMATE_TOL_SE * se, ESTIMATE_TOL_ABS) | !is.finite(fa - fb)]
  words <- c(if (!is.finite(la - lb) || abs(la - lb) > LOGLIK_TOL)
               sprintf("log-likelihood %.3f vs %.3f", la, lb),
             if (length(off)) paste(sprintf("%s %.3g vs %.3g", off, fa[off], fb[off]), collapse = ", "))
  paste(words, collapse = "; ")
}

# The SDs of the participants' effects beyond SD_BOUND (glmm only), in words ("" when none). factors: the F codes'
# columns (reduce_random), to name a participant-by-level effect by its columns.
beyond_bound <- function(kind, m, factors = list()) {
  if (kind != "glmm") return("")
  vc <- as.data.frame(VarCorr(m))
  big <- vc[vc$grp != "Residual" & is.na(vc$var2) & vc$sdcor > SD_BOUND, ]
  if (!nrow(big)) return("")
  named <- vapply(seq_len(nrow(big)), function(i) {
    if (startsWith(big$grp[i], "g:")) {
      cols <- factors[[sub("^g:", "", big$grp[i])]]
      sprintf("each level of %s", paste(cols, collapse = "/"))
    } else if (big$var1[i] == "(Intercept)") "the intercept" else big$var1[i]
  }, "")
  sprintf(paste("gave the participants' SD of %s at %s log-odds, beyond %g (a flat likelihood: the answers of a",
                "participant or a cell nearly all one way)"),
          paste(named, collapse = ", "), paste(sprintf("%.3g", big$sdcor), collapse = ", "), SD_BOUND)
}

# One model fitted by both optimizers and kept only when determined (above); singular fits flagged.
# first_decides (the maximal model, whose fit serves only to be kept or not): where the first optimizer fails, or its
# clean fit is singular, the model cannot be kept whatever the second finds, and the second is not run. On the
# maximal model of a 2 x 3 crossing over 8 participants (analysis/tests/test_crossed.py) Nelder_Mead took 45 s to
# end unconverged where bobyqa's singular fit took 6.5 s.
fit_one <- function(kind, d, xs, random, factors = list(), first_decides = FALSE) {
  f <- as.formula(paste("y ~ 0 +", paste(xs, collapse = " + "), "+", random))
  if (first_decides) {
    lead <- fit_with(kind, f, d, OPTIMIZERS[1])
    if (is.null(lead$m)) return(list(ok = FALSE, m = NULL, why = sprintf("failed (%s: %s)", OPTIMIZERS[1], lead$why)))
    if (!length(lead$conv) && isSingular(lead$m)) {
      return(list(ok = FALSE, m = lead$m, singular = TRUE,
                  why = sprintf("was singular (a variance estimated at 0 or a correlation at +-1, by %s)", OPTIMIZERS[1])))
    }
    fits <- list(lead, fit_with(kind, f, d, OPTIMIZERS[2]))
  } else {
    fits <- lapply(OPTIMIZERS, function(o) fit_with(kind, f, d, o))
  }
  names(fits) <- OPTIMIZERS
  failed <- vapply(fits, function(x) is.null(x$m), TRUE)
  if (all(failed)) return(list(ok = FALSE, why = sprintf("failed (%s)", fits[[1]]$why), m = NULL))
  if (any(failed)) {
    return(list(ok = FALSE, m = NULL, why = sprintf("did not converge (%s failed: %s)", OPTIMIZERS[failed][1],
                                                   fits[failed][[1]]$why)))
  }
  clean <- vapply(fits, function(x) !length(x$conv), TRUE)
  if (!any(clean)) {
    conv <- unique(unlist(lapply(fits, `[[`, "conv")))
    return(list(ok = FALSE, why = sprintf("did not converge (%s)", paste(conv, collapse = "; ")), m = NULL))
  }
  ll <- vapply(fits, function(x) as.numeric(logLik(x$m)), 0)
  apart <- disagreement(fits[[1]], fits[[2]])
  if (nzchar(apart)) {
    # probe: the higher likelihood's fit, only for reduce_random to see which components it puts at 0.
    return(list(ok = FALSE, m = NULL, probe = fits[[which.max(ll)]]$m,
                why = sprintf("did not converge (%s and %s disagree: %s)", OPTIMIZERS[1], OPTIMIZERS[2], apart)))
  }
  # Both agree: the clean one with the higher likelihood.
  ll[!clean] <- -Inf
  m <- fits[[which.max(ll)]]$m
  big <- beyond_bound(kind, m, factors)
  if (nzchar(big)) return(list(ok = FALSE, m = NULL, why = big))
  if (isSingular(m)) {
    return(list(ok = FALSE, why = "was singular (a variance estimated at 0 or a correlation at +-1)", m = m,
                singular = TRUE))
  }
  list(ok = TRUE, m = m, singular = FALSE)
}

# When the maximal model fails: the slopes uncorrelated with each other and with the intercept, (1 | g) + (0 + x | g)
# + ...; where that is singular, the components it estimates at 0 are left out (each a variance on its bound, so the
# fit is the same) and the rest refitted, uncorrelated (Bates et al. 2015, Matuschek et al. 2017: the random part
# reduced as far as the data need, not at once to the intercept). NULL when no slope survives in a non-singular fit.
# A participant effect that is real but uncorrelated, or a slope spread with no intercept spread (a depth matching's
# set-on-real slope), keeps its slope and so its test.
# A factor's columns (FACTORS: its levels' dummies, against a reference level or cell means) are one component, the
# participant-by-level effect (1 | g:F), not a slope per column: uncorrelated slopes of treatment dummies are a
# different model for each reference level (a contrast's spread is the sum of two levels' in one coding, one level's
# in another), so the group contrast of a two-group study moved with the order of the edge levels (0.44 against
# 0.48 in tests/test_glmm_checks.py); (1 | g:F) is the same model whatever the order.
reduce_random <- function(kind, d, xs, slopes, factors = list(), emit = function(...) NULL) {
  factors <- Filter(function(f) length(f) > 0, lapply(factors, function(f) intersect(f, slopes)))
  units <- lapply(setdiff(slopes, unlist(factors)), function(x) list(cols = x, code = x, factor = FALSE))
  for (k in seq_along(factors)) {
    code <- sprintf("F%d", k - 1)
    d[[code]] <- factor(do.call(paste, c(d[factors[[k]]], sep = ":")))
    units[[length(units) + 1]] <- list(cols = factors[[k]], code = code, factor = TRUE)
    emit("info", paste0("factor:", code), note = paste(factors[[k]], collapse = ","))
  }
  by_code <- setNames(lapply(units, `[[`, "cols"), vapply(units, `[[`, "", "code"))
  uncorrelated <- function(intercept, us) {
    paste(c(if (intercept) "(1 | g)", vapply(us, function(u)
      if (u$factor) sprintf("(1 | g:%s)", u$code) else sprintf("(0 + %s | g)", u$code), "")), collapse = " + ")
  }
  said <- function(us) paste(vapply(us, function(u)
    if (u$factor) sprintf("each level of %s", paste(u$cols, collapse = "/")) else u$code, ""), collapse = ", ")
  second <- fit_one(kind, d, xs, uncorrelated(TRUE, units), by_code)
  if (second$ok) {
    return(list(fit = second, slopes = slopes, intercept = TRUE,
                words = sprintf("random intercept and slopes by participant (%s), uncorrelated", said(units)),
                why = "the uncorrelated one was not"))
  }
  probe <- if (is.null(second$m)) second$probe else second$m
  if (is.null(probe)) return(NULL)
  vc <- as.data.frame(VarCorr(probe))
  scale <- if (kind == "lmm") sigma(probe) else 1
  live <- vc$grp != "Residual" & is.na(vc$var2) & vc$sdcor >= 1e-4 * scale
  # lme4 names a repeated grouping factor g, g.1, g.2 ...; a factor's participant-by-level effect g:F0.
  by_level <- startsWith(vc$grp, "g:")
  alive <- c(vc$var1[live & !by_level], sub("^g:", "", vc$grp[live & by_level]))
  keep <- Filter(function(u) u$code %in% alive, units)
  intercept <- "(Intercept)" %in% alive
  if (!length(keep)) return(NULL)
  third <- fit_one(kind, d, xs, uncorrelated(intercept, keep), by_code)
  if (!third$ok) return(NULL)
  dropped <- c(if (!intercept) "the intercept", said(Filter(function(u) !(u$code %in% alive), units)))
  dropped <- dropped[nzchar(dropped)]
  list(fit = third, slopes = unlist(lapply(keep, `[[`, "cols")), intercept = intercept,
       words = sprintf("%sslopes by participant (%s), uncorrelated", if (intercept) "random intercept and " else
                       "random ", said(keep)),
       why = sprintf("the uncorrelated one estimated the spread of %s at 0, so %s left out",
                     paste(dropped, collapse = ", "), if (length(dropped) > 1) "they were" else "it was"))
}

# The maximal model, else a reduced one (reduce_random), else the intercept-only one; its fixed effects, SDs and
# correlations through emit().
fit_job <- function(kind, data_path, slopes, emit, factors = list()) {
  # A participant named "NA" is a participant: no text is read as missing (numbers' empty cells still are).
  d <- read.csv(data_path, stringsAsFactors = FALSE, na.strings = character(0), colClasses = c(g = "character"))
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

  kept <- character()
  intercept <- TRUE
  if (length(slopes)) {
    first <- fit_one(kind, d, xs, sprintf("(1 + %s | g)", paste(slopes, collapse = " + ")), first_decides = TRUE)
    if (first$ok) {
      chosen <- first
      kept <- slopes
      structure <- sprintf("random intercept and slopes by participant (%s)", paste(slopes, collapse = ", "))
    } else {
      reduced <- reduce_random(kind, d, xs, slopes, factors, emit)
      if (!is.null(reduced)) {
        chosen <- reduced$fit
        kept <- reduced$slopes
        intercept <- reduced$intercept
        structure <- sprintf("%s: the model with correlated random slopes (%s) %s; %s",
                             reduced$words, paste(slopes, collapse = ", "), first$why, reduced$why)
      } else {
        chosen <- fit_one(kind, d, xs, "(1 | g)")
        structure <- sprintf(paste("random intercept only: the model with random slopes (%s) %s, and no model",
                                   "with uncorrelated slopes kept a slope"), paste(slopes, collapse = ", "), first$why)
      }
    }
  } else {
    chosen <- fit_one(kind, d, xs, "(1 | g)")
    structure <- "random intercept only (no within-participant term to give a slope)"
  }
  emit("info", "slopes", note = paste(kept, collapse = ","))
  emit("info", "intercept", note = if (intercept) "yes" else "no")
  emit("info", "structure", note = structure)
  if (is.null(chosen$m)) {
    emit("info", "failed", note = chosen$why)
    return(invisible())
  }
  m <- chosen$m
  if (isTRUE(chosen$singular)) emit("info", "singular", note = chosen$why)

  if (kind == "glmm") {
    # Wald z against t with G-1 df: with a handful of participants the normal reference is far too liberal.
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

  # Variance components: an SD on its bound (below isSingular's tolerance) is flagged, and the caller says it in
  # words, never as a number.
  vc <- as.data.frame(VarCorr(m))
  for (i in seq_len(nrow(vc))) {
    r <- vc[i, ]
    if (r$grp == "Residual") {
      emit("sd", "Residual", r$sdcor)
    } else if (is.na(r$var2)) {
      # g:F0 is a factor's participant-by-level effect (reduce_random), named by its code.
      name <- if (startsWith(r$grp, "g:")) sub("^g:", "", r$grp) else if (r$var1 == "(Intercept)") "Intercept" else
        r$var1
      tiny <- r$sdcor < 1e-4 * (if (kind == "lmm") sigma(m) else 1)
      emit("sd", name, if (tiny) 0 else r$sdcor, note = if (tiny) "singular" else "")
    } else {
      a <- if (r$var1 == "(Intercept)") "Intercept" else r$var1
      b <- if (r$var2 == "(Intercept)") "Intercept" else r$var2
      emit("corr", paste(a, b, sep = ":"), r$sdcor, note = if (abs(r$sdcor) > 0.999) "singular" else "")
    }
  }
  invisible()
}

# One job: the table written to out_path whatever happens inside.
run_job <- function(kind, data_path, out_path, slopes, factors = list()) {
  rows <- list()
  emit <- function(row, term, estimate = NA, se = NA, df = NA, p = NA, note = "") {
    rows[[length(rows) + 1]] <<- data.frame(row = row, term = term, estimate = estimate, se = se, df = df, p = p,
                                            note = note, stringsAsFactors = FALSE)
  }
  if (kind == "lmm" && !requireNamespace("lmerTest", quietly = TRUE)) {
    emit("info", "missing", note = "lmerTest")
  } else {
    result <- tryCatch(fit_job(kind, data_path, slopes, emit, factors), error = function(e) e)
    if (inherits(result, "error")) emit("info", "failed", note = sprintf("failed (%s)", conditionMessage(result)))
  }
  out <- if (length(rows)) do.call(rbind, rows) else
    data.frame(row = character(), term = character(), estimate = numeric(), se = numeric(), df = numeric(),
               p = numeric(), note = character())
  write.csv(out, out_path, row.names = FALSE, na = "")
}

slopes_of <- function(text) if (!is.na(text) && nzchar(text)) strsplit(text, ",", fixed = TRUE)[[1]] else character()
# FACTORS: one factor's columns comma-separated, factors separated by ";" ("" = none).
factors_of <- function(text) if (!is.na(text) && nzchar(text)) lapply(strsplit(text, ";", fixed = TRUE)[[1]], slopes_of) else
  list()

# ---- A between-subject group crossed with a within-participant factor (issue 38; analysis/groups.py) ----------------
# KIND group_glmm (binomial glmer, Laplace) or group_lmm (lmer, REML). DATA: y, g (the participant), grp (the group,
# coded G1..), w (the within factor's level, coded W01..), and C0..Ck (other within factors, coded: main effects only).
# The model with the interaction, y ~ grp * w + C.. + RANDOM, and the same without it, y ~ grp + w + C.. + RANDOM, are
# fitted with the first random part that converges and is not singular on the full model: (1 + w | g) (each
# participant's own profile over w), (1 | g) + (1 | g:w) (a participant-by-level deviation of one variance: the
# profile's spread with one parameter), (1 | g). The interaction is tested by comparing the two: a likelihood-ratio
# chi-square for the GLMM; for the LMM the Kenward-Roger F (pbkrtest), which holds its level with few participants
# where the chi-square does not. Each level of w then gets the groups' differences from the full model by emmeans
# (log-odds or the measure's unit; a GLMM's Wald z against t with G - groups df, as the other GLMM tests take t(G-1)),
# unadjusted here: analysis/groups.py Holm-adjusts them. OUT rows: info (engine, structure, failed, singular,
# missing), test (the interaction: estimate = chi-square or F, df, p; note = df2 for F), contrast (term LEVEL|A|B:
# A - B at LEVEL), emmean (term LEVEL|GROUP: the group's estimate at LEVEL on the response scale).
group_fit <- function(kind, f, d) {
  said <- character()
  m <- withCallingHandlers(
    tryCatch(
      if (kind == "group_glmm") {
        glmer(f, data = d, family = binomial,
              control = glmerControl(optimizer = "bobyqa", optCtrl = list(maxfun = 2e5)))
      } else {
        lmer(f, data = d, REML = TRUE, control = lmerControl(optimizer = "bobyqa"))
      },
      error = function(e) e),
    warning = function(w) { said <<- c(said, conditionMessage(w)); invokeRestart("muffleWarning") },
    message = function(m) { said <<- c(said, trimws(conditionMessage(m))); invokeRestart("muffleMessage") })
  if (inherits(m, "error")) return(list(ok = FALSE, why = sprintf("failed (%s)", conditionMessage(m))))
  conv <- c(m@optinfo$conv$lme4$messages, if (m@optinfo$conv$opt != 0) "the optimizer did not finish",
            said[grepl("converge|unidentifiable|Hessian|rank deficient", said)])
  conv <- unique(conv[!grepl("singular", conv)])
  if (length(conv)) return(list(ok = FALSE, why = sprintf("did not converge (%s)", paste(conv, collapse = "; "))))
  if (isSingular(m)) return(list(ok = FALSE, why = "was singular (a variance estimated at 0 or a correlation at +-1)",
                                 singular = TRUE, m = m))
  list(ok = TRUE, m = m)
}

group_job <- function(kind, data_path, emit) {
  d <- read.csv(data_path, stringsAsFactors = FALSE, na.strings = character(0),
                colClasses = c(g = "character", grp = "character", w = "character"))
  d$g <- factor(d$g)
  d$grp <- factor(d$grp, levels = sort(unique(d$grp)))
  d$w <- factor(d$w, levels = sort(unique(d$w)))
  others <- grep("^C[0-9]+$", names(d), value = TRUE)
  for (c in others) d[[c]] <- factor(d[[c]])
  extra <- if (length(others)) paste0(" + ", paste(others, collapse = " + ")) else ""
  version <- packageDescription("lme4")$Version
  glmm <- kind == "group_glmm"
  randoms <- c("(1 + w | g)", "(1 | g) + (1 | g:w)", "(1 | g)")
  words <- c("each participant's own profile over the levels, (1 + w | participant)",
             "a random intercept and a participant-by-level deviation, (1 | participant) + (1 | participant:w)",
             "a random intercept only, (1 | participant)")
  tried <- character()
  chosen <- NULL
  # Each participant's own profile has k (k + 1) / 2 variances and correlations: with as many participants or fewer it
  # cannot be estimated (and a glmer over 11 levels' profiles runs for minutes before it says so).
  k <- nlevels(d$w)
  first <- 1
  if (k * (k + 1) / 2 >= nlevels(d$g)) {
    tried <- sprintf("%s not tried (%d variances and correlations from %d participants)", words[1], k * (k + 1) / 2,
                     nlevels(d$g))
    first <- 2
  }
  for (i in first:length(randoms)) {
    full <- group_fit(kind, as.formula(paste0("y ~ grp * w", extra, " + ", randoms[i])), d)
    if (full$ok) { chosen <- i; break }
    tried <- c(tried, sprintf("%s %s", words[i], full$why))
  }
  if (is.null(chosen)) {
    emit("info", "failed", note = paste("no random part gave a fit:", paste(tried, collapse = "; ")))
    return(invisible())
  }
  emit("info", "structure", note = paste0(words[chosen], if (length(tried)) paste0(" (", paste(tried, collapse = "; "),
                                                                                    ")") else ""))
  emit("info", "random", note = randoms[chosen])
  null <- group_fit(kind, as.formula(paste0("y ~ grp + w", extra, " + ", randoms[chosen])), d)
  m1 <- full$m
  n_groups <- nlevels(d$grp)
  n_people <- nlevels(d$g)
  # The model without the interaction may put a variance on its bound (a real interaction, left out, is no longer
  # there for a participant-by-level variance to share): that is its maximum likelihood, and the comparison of the two
  # likelihoods stands. A fit that failed or did not converge has no maximum to compare.
  if (isTRUE(null$singular)) {
    null$ok <- TRUE
    emit("info", "null_singular", note = "the model without the interaction estimated a variance at 0 (on its bound)")
  }
  if (!null$ok) {
    emit("info", "failed_test", note = sprintf("the model without the interaction %s", null$why))
  } else if (glmm) {
    a <- anova(null$m, m1)
    emit("info", "engine", note = sprintf("lme4 %s glmer (Laplace), likelihood-ratio chi-square", version))
    emit("test", "interaction", a$Chisq[2], NA, a$Df[2], a[["Pr(>Chisq)"]][2])
  } else if (requireNamespace("pbkrtest", quietly = TRUE) && nrow(d) <= 4000) {
    kr <- pbkrtest::KRmodcomp(m1, null$m)
    st <- kr$stats
    emit("info", "engine", note = sprintf("lme4 %s lmer (REML), pbkrtest %s Kenward-Roger F", version,
                                          packageDescription("pbkrtest")$Version))
    emit("test", "interaction", st$Fstat, NA, st$ndf, st$p.value, note = sprintf("%.10g", st$ddf))
  } else {
    a <- anova(null$m, m1, refit = TRUE)
    emit("info", "engine", note = sprintf("lme4 %s lmer (ML refit), likelihood-ratio chi-square (%s)", version,
                                          if (nrow(d) > 4000) "over 4000 answers: Kenward-Roger not computed" else
                                            "pbkrtest not installed"))
    emit("test", "interaction", a$Chisq[2], NA, a$Df[2], a[["Pr(>Chisq)"]][2])
  }
  if (!requireNamespace("emmeans", quietly = TRUE)) {
    emit("info", "missing", note = "emmeans")
    return(invisible())
  }
  emmeans::emm_options(lmer.df = "satterthwaite", lmerTest.limit = 1e5, pbkrtest.limit = 1e5)
  emm <- emmeans::emmeans(m1, ~ grp | w)
  ct <- as.data.frame(summary(emmeans::contrast(emm, method = "pairwise"), adjust = "none", infer = c(FALSE, TRUE)))
  for (i in seq_len(nrow(ct))) {
    r <- ct[i, ]
    pair <- strsplit(as.character(r$contrast), " - ", fixed = TRUE)[[1]]
    if (glmm) {
      df <- n_people - n_groups
      stat <- r$estimate / r$SE
      p <- if (df > 0) 2 * pt(-abs(stat), df) else NA
    } else {
      df <- r$df
      p <- r$p.value
    }
    emit("contrast", paste(as.character(r$w), pair[1], pair[2], sep = "|"), r$estimate, r$SE, df, p)
  }
  em <- as.data.frame(summary(emm, type = "response"))
  value <- if (glmm) "prob" else "emmean"
  for (i in seq_len(nrow(em))) {
    r <- em[i, ]
    emit("emmean", paste(as.character(r$w), as.character(r$grp), sep = "|"), r[[value]], r$SE)
  }
  invisible()
}

run_group_job <- function(kind, data_path, out_path) {
  rows <- list()
  emit <- function(row, term, estimate = NA, se = NA, df = NA, p = NA, note = "") {
    rows[[length(rows) + 1]] <<- data.frame(row = row, term = term, estimate = estimate, se = se, df = df, p = p,
                                            note = note, stringsAsFactors = FALSE)
  }
  result <- tryCatch(group_job(kind, data_path, emit), error = function(e) e)
  if (inherits(result, "error")) emit("info", "failed", note = sprintf("failed (%s)", conditionMessage(result)))
  out <- do.call(rbind, c(rows, list(data.frame(row = "info", term = "done", estimate = NA, se = NA, df = NA, p = NA,
                                                note = "", stringsAsFactors = FALSE))))
  write.csv(out, out_path, row.names = FALSE, na = "")
}

# A job of either family: the group models (group_*) or the models across participants (run_job).
run_any <- function(kind, data_path, out_path, slopes, factors = list()) {
  if (startsWith(kind, "group_")) run_group_job(kind, data_path, out_path) else
    run_job(kind, data_path, out_path, slopes, factors)
}

args <- commandArgs(trailingOnly = TRUE)
if (length(args) == 1 && args[1] == "--serve") {
  input <- file("stdin", open = "r")
  repeat {
    line <- readLines(input, n = 1)
    if (length(line) == 0) break
    job <- strsplit(line, "\t", fixed = TRUE)[[1]]
    run_any(job[1], job[2], job[3], slopes_of(job[4]), factors_of(job[5]))
    cat("done\n")
    flush(stdout())
  }
} else if (length(args) >= 3) {
  run_any(args[1], args[2], args[3], slopes_of(args[4]), factors_of(args[5]))
} else {
  cat("usage: Rscript models.R glmm|lmm DATA.csv OUT.csv [SLOPES] | Rscript models.R --serve\n", file = stderr())
  quit(status = 2)
}
