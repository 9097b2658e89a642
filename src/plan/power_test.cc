// The plan's statistics against closed forms worked by hand (the arithmetic in the comments).
#include "plan/power.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace blurcue::plan {
namespace {

TEST(BinomialTest, SymmetricNullSumsBothTails) {
  // 7 of 10 against 0.5: P(X <= 3) + P(X >= 7) = 2 (1 + 10 + 45 + 120) / 1024 = 352 / 1024.
  EXPECT_NEAR(BinomialTestP(7, 10, 0.5), 352.0 / 1024, 1e-12);
  // 0 of 5: both extremes, 2 / 32.
  EXPECT_NEAR(BinomialTestP(0, 5, 0.5), 2.0 / 32, 1e-12);
}

TEST(BinomialTest, AsymmetricNullSumsTheOutcomesNoMoreLikely) {
  // 3 of 10 against 0.2 (scipy's two-sided rule): P(X = 3) = 0.201326592; only X = 1 (0.268435456) and X = 2
  // (0.301989888) are more likely, so p = 1 - 0.268435456 - 0.301989888 = 0.429574656.
  EXPECT_NEAR(BinomialTestP(3, 10, 0.2), 0.429574656, 1e-9);
  EXPECT_EQ(BinomialTestP(0, 0, 0.5), 1);
}

TEST(BinomialTest, AllOutcomesAtOnceAsOneByOne) {
  // The sorted running sum gives each k's p as BinomialTestP does (summed in another order: to 1e-12).
  for (int n : {0, 1, 2, 7, 10, 31, 200, 1001})
    for (double p : {0.5, 0.2, 1.0 / 3, 0.9}) {
      const std::vector<double> all = BinomialTestPAll(n, p);
      ASSERT_EQ(all.size(), size_t(n) + 1);
      for (int k = 0; k <= n; ++k) EXPECT_NEAR(all[size_t(k)], BinomialTestP(k, n, p), 1e-12) << k << " of " << n;
    }
  EXPECT_NEAR(BinomialTestPAll(10, 0.5)[7], 352.0 / 1024, 1e-12);
}

TEST(Wilson, FourteenOfTwentyByTheClosedForm) {
  // p = 0.7, z = 1.959964: centre (p + z^2 / 2n) / (1 + z^2 / n) = 0.667775, half-width 0.186748.
  const auto [lo, hi] = Wilson95(14, 20);
  EXPECT_NEAR(lo, 0.4810271816464765, 1e-12);
  EXPECT_NEAR(hi, 0.8545227551323956, 1e-12);
  EXPECT_EQ(Wilson95(0, 12).first, 0);
  EXPECT_EQ(Wilson95(12, 12).second, 1);
}

TEST(IncompleteBeta, IntegerParametersAreABinomialTail) {
  // I_x(2, 3) = P(Binomial(4, x) >= 2) = 6 x^2 (1-x)^2 + 4 x^3 (1-x) + x^4; at 0.4: 0.3456 + 0.1536 + 0.0256.
  EXPECT_NEAR(IncompleteBeta(2, 3, 0.4), 0.5248, 1e-12);
  // Past the mean the symmetry branch: I_0.9(2, 3) = 1 - P(Binomial(4, 0.9) <= 1) = 1 - 0.0001 - 0.0036.
  EXPECT_NEAR(IncompleteBeta(2, 3, 0.9), 0.9963, 1e-12);
}

TEST(OneSampleT, SmallSamplesMatchTheClosedFormTails) {
  // {1, 2, 3} against 1: t = 1 / (1 / sqrt 3) = sqrt 3 with 2 df, whose two-sided tail is 1 - t / sqrt(2 + t^2).
  EXPECT_NEAR(OneSampleTTestP({1, 2, 3}, 1), 1 - std::sqrt(3.0 / 5), 1e-12);
  // {0, 1} against 0: t = 1 with 1 df (Cauchy): 1 - 2 atan(1) / pi = 0.5.
  EXPECT_NEAR(OneSampleTTestP({0, 1}, 0), 0.5, 1e-12);
  // No spread: decided by the mean alone; one value: no test.
  EXPECT_EQ(OneSampleTTestP({0.7, 0.7, 0.7}, 0.5), 0);
  EXPECT_EQ(OneSampleTTestP({0.5, 0.5}, 0.5), 1);
  EXPECT_EQ(OneSampleTTestP({0.9}, 0.5), 1);
}

TEST(WelchT, EqualSpreadsByTheClosedFormOfFourDf) {
  // {1, 2, 3} vs {4, 5, 6}: each mean's variance 1/3, t = -3 / sqrt(2/3), Welch's df (2/3)^2 / (2 (1/9)^2 / 2) = 4;
  // with 4 df the two-sided tail is 1 - 1.5 u (1 - u^2 / 3), u = |t| / sqrt(4 + t^2).
  const double t = 3 / std::sqrt(2.0 / 3), u = t / std::sqrt(4 + t * t);
  EXPECT_NEAR(WelchTTestP({1, 2, 3}, {4, 5, 6}), 1 - 1.5 * u * (1 - u * u / 3), 1e-12);
  EXPECT_NEAR(WelchTTestP({4, 5, 6}, {1, 2, 3}), WelchTTestP({1, 2, 3}, {4, 5, 6}), 1e-15);
  EXPECT_EQ(WelchTTestP({1}, {4, 5, 6}), 1);               // one value: no test
  EXPECT_EQ(WelchTTestP({2, 2}, {3, 3}), 0);               // no spread, different means
  EXPECT_EQ(WelchTTestP({2, 2}, {2, 2}), 1);
}

TEST(StudentT, QuantilesMatchTheTable) {
  // t(0.975) from the standard table; df = 1 is the Cauchy's tan(0.475 pi), df = 2 is 2 / sqrt(0.95^2 ... ) closed.
  EXPECT_NEAR(StudentT975(1), std::tan(0.475 * M_PI), 1e-6);
  EXPECT_NEAR(StudentT975(2), 4.302652729, 1e-6);
  EXPECT_NEAR(StudentT975(10), 2.228138852, 1e-6);
  EXPECT_NEAR(StudentT975(30), 2.042272456, 1e-6);
  EXPECT_NEAR(StudentT975(100000), 1.959963985, 1e-4);
}

TEST(OlsSlope, ExactLineAndDegenerateX) {
  EXPECT_NEAR(OlsSlope({{0, 1}, {1, 3}, {2, 5}}), 2, 1e-12);
  EXPECT_NEAR(OlsSlope({{0, 0}, {1, 1}, {2, 0}, {3, 1}}), 0.2, 1e-12);  // sxy 1 / sxx 5
  EXPECT_TRUE(std::isnan(OlsSlope({{1, 0}, {1, 5}})));
  EXPECT_TRUE(std::isnan(OlsSlope({{1, 0}})));
}

}  // namespace
}  // namespace blurcue::plan

namespace blurcue::plan {
namespace {

// Hand-worked sign-flip p (as analysis/study_tests.py sign_flip_p): 7 participants of one answer each, 6 of them one
// way - |sum| 2.5 is reached by 6 or 7 alike of either sign: 2 (7 + 1) / 128 = 0.125 (a t test said 0.047); all 7:
// 2 / 128; shares 1, 1, 0.5 (deviations .5 .5 0): |sum| >= 1 for (+ +) and (- -), either sign of the 0: 4 / 8.
TEST(SignFlipP, HandWorkedCases) {
  EXPECT_NEAR(SignFlipP({0.5, 0.5, 0.5, 0.5, 0.5, 0.5, -0.5}), 16.0 / 128, 1e-15);
  EXPECT_NEAR(SignFlipP(std::vector<double>(7, 0.5)), 2.0 / 128, 1e-15);
  EXPECT_NEAR(SignFlipP({0.5, 0.5, 0}), 0.5, 1e-15);
  EXPECT_EQ(SignFlipP({0.2, -0.2}), 1);  // a sum of 0
  // 20 participants, every one of 3 answers right (+1/2 each): only the two unanimous patterns, 2 / 2^20.
  EXPECT_NEAR(SignFlipP(std::vector<double>(20, 0.5)), 2.0 / (1 << 20), 1e-18);
  // 100 participants, 60 of them +0.1 and 40 -0.1: exactly the binomial's 2 P(X >= 60) of 100 at 1/2 = 0.05689;
  // the normal limit with its lattice step, 2 (1 - Phi(1.9)) = 0.05743.
  std::vector<double> many(60, 0.1);
  many.resize(100, -0.1);
  EXPECT_NEAR(SignFlipP(many), 0.05689, 0.001);
}

// A single answer is no test, whatever the chance level: at chance 0.04 one right answer has the binomial p = 0.04,
// which plan counted as a rejection at alpha 0.05 where the report says "none: one answer cannot test anything" (no
// protocol reaches such a chance level today: an odd one out has at most 6 alternatives).
TEST(OneParticipantTest, ASingleAnswerIsNoTest) {
  EXPECT_NEAR(BinomialTestP(1, 1, 0.04), 0.04, 1e-12);
  EXPECT_TRUE(std::isnan(OneParticipantTestP(1, 1, 0.04)));
  EXPECT_FALSE(OneParticipantTestP(1, 1, 0.04) < 0.05);
  // Two answers both right at 1/25: 0.04^2 = 0.0016, a test.
  EXPECT_NEAR(OneParticipantTestP(2, 2, 0.04), 0.0016, 1e-12);
}

// The golden table (tests/one_participant_golden.py writes it from the report's one_participant_test): tested or
// not, and p to 1e-9 relative, for every k of 1-12, 20 and 40 answers at chance 0.5, 1/3, 0.25, 0.1, 0.04, 0.01.
TEST(OneParticipantTest, MatchesTheReportOnTheGoldenTable) {
  std::ifstream file(BLURCUE_ONE_PARTICIPANT_GOLDEN);
  ASSERT_TRUE(file) << BLURCUE_ONE_PARTICIPANT_GOLDEN;
  std::string line;
  std::getline(file, line);
  int rows = 0, untested = 0;
  while (std::getline(file, line)) {
    std::vector<std::string> f;
    std::stringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) f.push_back(cell);
    ASSERT_EQ(f.size(), 5u) << line;
    const double p = OneParticipantTestP(std::stoi(f[0]), std::stoi(f[1]), std::stod(f[2]));
    if (f[3] == "0") {
      EXPECT_TRUE(std::isnan(p)) << line << ": plan gives p " << p;
      ++untested;
    } else {
      const double want = std::stod(f[4]);
      EXPECT_NEAR(p, want, 1e-9 * std::max(1.0, want)) << line;
    }
    ++rows;
  }
  EXPECT_EQ(rows, 912);
  EXPECT_EQ(untested, 12);  // k = 0 and 1 of one answer at each of the six chance levels
}

}  // namespace
}  // namespace blurcue::plan
