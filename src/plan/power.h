#pragma once
// The statistics a plan needs to say how often a study's tests would succeed: the exact binomial test the report
// runs per condition (scipy's two-sided "minlike" rule, as analysis/stats.py binom_p), the Wilson interval it draws,
// and a one-sample t-test across participants. Closed forms only; no randomness here.
#include <cstddef>
#include <utility>
#include <vector>

namespace blurcue::plan {

// P(X = k) for X ~ Binomial(n, p), from log-gamma (exact to ~1e-13 relative for n up to millions).
double BinomialPmf(int k, int n, double p);

// Exact two-sided binomial test of k of n against p: the summed probability of every outcome no more likely than k
// (relative tolerance 1e-7, as scipy.stats.binomtest). 1 when n == 0.
double BinomialTestP(int k, int n, double p);

// BinomialTestP(k, n, p) for every k in 0 .. n at once, in O(n log n) (the outcomes' probabilities sorted once, the
// sum of those no more likely than k's read from their running sum): the plan needs every k of every n up to
// --participants x trials, which one BinomialTestP (O(n)) per k made O(n^3) - minutes to hours past 3000 participants.
std::vector<double> BinomialTestPAll(int n, double p);

// The report's test of one participant's k of n answers against chance (analysis/study_tests.py
// one_participant_test): the exact binomial p (BinomialTestP); NaN - no test - for n < 2: a single answer is one way
// or the other and guessing gives either often (at a chance level below alpha, one answer right would otherwise count
// as a rejection the report never makes). tests/one_participant_golden.py holds the two equal on a grid of cases.
double OneParticipantTestP(int k, int n, double chance);

// Wilson score interval (95 %) of k of n: (low, high); (0, 1) when n == 0.
std::pair<double, double> Wilson95(int k, int n);

// The regularized incomplete beta function I_x(a, b) (continued fraction, Numerical Recipes' betacf).
double IncompleteBeta(double a, double b, double x);

// The exact two-sided sign-flip permutation p of deviations around 0 (analysis/study_tests.py sign_flip_p: each
// participant's share - 0.5): the share of the 2^G sign patterns whose sum is at least as far from 0 as the
// observed one (within 1e-9: ties count as reached). Every pattern counted, by meet in the middle (two halves'
// sums, one sorted): 2^(G/2) log work, up to G = 24; beyond, the sum's normal limit. NaN for no deviations.
double SignFlipP(const std::vector<double>& deviations);
inline constexpr size_t kSignFlipExactUpTo = 24;
// SignFlipP's normal limit from the deviations' sum, sum of squares and smallest non-zero size (its lattice step).
double SignFlipNormalP(double sum, double square, double step);

// Two-sided p of a one-sample t-test of `values` against `mu`: 1 for fewer than two values; 0 or 1 when they do not
// vary (0 when their mean differs from mu).
double OneSampleTTestP(const std::vector<double>& values, double mu);

// Two-sided p of Welch's two-sample t-test of a against b (unequal variances, Welch-Satterthwaite df): 1 when either
// has fewer than two values; 0 or 1 when neither varies (0 when their means differ).
double WelchTTestP(const std::vector<double>& a, const std::vector<double>& b);

// The 97.5 % quantile of Student's t with df degrees of freedom (df >= 1; bisection on IncompleteBeta to 1e-10):
// a 95 % interval of a mean of n values is mean +- StudentT975(n - 1) sd / sqrt(n).
double StudentT975(int df);

// The least-squares slope of y on x over the points (x, y); NaN for fewer than two distinct x.
double OlsSlope(const std::vector<std::pair<double, double>>& points);

}  // namespace blurcue::plan
