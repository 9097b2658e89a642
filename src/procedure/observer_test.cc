#include "procedure/observer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>

#include "core/error.h"

namespace blurcue::procedure {
namespace {

double NormalCdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

// The pixel model's parameters (every record before model= existed names jnd): read as model=pixel.
TEST(ObserverParams, ParsesNamesAndKeepsDefaults) {
  const ObserverParams p = ParseObserver("sim:jnd=0.4,lapse=0,rt=700");
  EXPECT_EQ(p.model, ObserverModel::kPixel);
  EXPECT_DOUBLE_EQ(p.jnd_px, 0.4);
  EXPECT_DOUBLE_EQ(p.lapse, 0);
  EXPECT_DOUBLE_EQ(p.rt_ms, 700);
  EXPECT_DOUBLE_EQ(p.bias_px, ObserverParams{}.bias_px);
  // The canonical form reads back as the same observer.
  const ObserverParams q = ParseObserver(ToString(p));
  EXPECT_EQ(ToString(q), ToString(p));
}

TEST(ObserverParams, RejectsUnknownNamesAndImpossibleValues) {
  for (const char* spec : {"simulated", "sim:jnd=0", "sim:lapse=1.5", "sim:jdn=0.5", "sim:rt=fast", "sim:jnd="}) {
    try {
      ParseObserver(spec);
      ADD_FAILURE() << spec << " was accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::kUsage) << spec;
    }
  }
}

// Pixel-model parameter set for the tests of the old model.
ObserverParams Pixel() {
  ObserverParams p;
  p.model = ObserverModel::kPixel;
  return p;
}

TEST(SimulatedObserver, SameSeedSameAnswers) {
  const ObserverParams p = Pixel();
  SimulatedObserver a(p, 42), b(p, 42), c(p, 43);
  int differ = 0;
  for (int i = 0; i < 200; ++i) {
    const PairView v{1.0 + 0.01 * i, 1.5, 1.2};
    const KeyPress x = a.ChooseSide(v), y = b.ChooseSide(v), z = c.ChooseSide(v);
    EXPECT_EQ(Name(x.action), Name(y.action));
    EXPECT_DOUBLE_EQ(x.after_ms, y.after_ms);
    differ += Name(x.action) != Name(z.action);
  }
  EXPECT_GT(differ, 0) << "another seed should answer differently somewhere";
}

// The choice probabilities match the model's closed form: P(left) = P(D > c) with D ~ N(delta, jnd), c = jnd / 2.
TEST(SimulatedObserver, ChoiceRatesMatchTheModel) {
  ObserverParams p = Pixel();
  p.jnd_px = 0.6;
  p.bias_px = 0;
  p.lapse = 0;
  SimulatedObserver o(p, 7);
  for (double delta : {0.0, 0.3, 0.9}) {
    // left matches the scene, right is off by delta.
    const PairView v{2.0, 2.0 + delta, 2.0};
    std::map<std::string, int> n;
    const int draws = 6000;
    for (int i = 0; i < draws; ++i) ++n[Name(o.ChooseSide(v).action)];
    const double c = p.jnd_px / 2;
    const double left = 1 - NormalCdf((c - delta) / p.jnd_px), right = NormalCdf((-c - delta) / p.jnd_px);
    const double se = std::sqrt(0.25 / draws);
    EXPECT_NEAR(n["left"] / double(draws), left, 4 * se) << "delta " << delta;
    EXPECT_NEAR(n["right"] / double(draws), right, 4 * se) << "delta " << delta;
  }
}

// One object: yes when e = m + N(0, jnd) exceeds jnd / 2 (m its mismatch with the scene), so P(yes) =
// 1 - Phi((jnd / 2 - m) / jnd); a rating counts the criteria k jnd / 2 that e exceeds.
TEST(SimulatedObserver, YesNoAndRatingRatesMatchTheModel) {
  ObserverParams p = Pixel();
  p.jnd_px = 0.6;
  p.lapse = 0;
  SimulatedObserver o(p, 11);
  const int draws = 6000;
  const double se = std::sqrt(0.25 / draws);
  for (double m : {0.0, 0.4, 1.2}) {
    const PairView v{2.0 + m, 0, 2.0};
    int yes = 0, lowest = 0, highest = 0;
    for (int i = 0; i < draws; ++i) yes += Name(o.SayYesNo(v).action) == "yes";
    for (int i = 0; i < draws; ++i) {
      const KeyPress k = o.Rate(v, 5);
      lowest += Name(k.action) == "1";
      highest += Name(k.action) == "5";
    }
    EXPECT_NEAR(yes / double(draws), 1 - NormalCdf((p.jnd_px / 2 - m) / p.jnd_px), 4 * se) << "m " << m;
    EXPECT_NEAR(lowest / double(draws), NormalCdf((p.jnd_px / 2 - m) / p.jnd_px), 4 * se) << "m " << m;
    EXPECT_NEAR(highest / double(draws), 1 - NormalCdf((4 * p.jnd_px / 2 - m) / p.jnd_px), 4 * se) << "m " << m;
  }
}

// Odd one out: with no difference every interval is named 1/n of the time; with a difference the odd one is found as
// often as an independent simulation of the same rule finds it, and more often the larger the difference.
TEST(SimulatedObserver, OddOneOutRatesMatchAnIndependentSimulation) {
  ObserverParams p = Pixel();
  p.jnd_px = 0.5;
  p.lapse = 0;
  SimulatedObserver o(p, 5);
  const int draws = 6000, n = 3;
  const double se = std::sqrt(0.25 / draws);
  std::mt19937_64 rng(99);
  std::normal_distribution<double> noise(0, p.jnd_px);
  double previous = 0;
  for (double delta : {0.0, 0.5, 1.5}) {
    const PairView v{1.0, 1.0 + delta, 1.0};
    int named[4] = {0, 0, 0, 0}, found = 0;
    for (int i = 0; i < draws; ++i) ++named[std::stoi(Name(o.ChooseOdd(v, n, 2).action))];
    for (int i = 0; i < draws; ++i) {
      // The rule by hand: the interval farthest from the mean of the other two.
      const double x[3] = {1.0 + noise(rng), 1.0 + delta + noise(rng), 1.0 + noise(rng)};
      const double d1 = std::abs(x[0] - (x[1] + x[2]) / 2), d2 = std::abs(x[1] - (x[0] + x[2]) / 2),
                   d3 = std::abs(x[2] - (x[0] + x[1]) / 2);
      found += d2 > d1 && d2 > d3;
    }
    EXPECT_NEAR(named[2] / double(draws), found / double(draws), 6 * se) << "delta " << delta;
    if (delta == 0) {
      for (int k = 1; k <= 3; ++k) EXPECT_NEAR(named[k] / double(draws), 1.0 / 3, 4 * se);
    }
    EXPECT_GE(named[2] / double(draws), previous);
    previous = named[2] / double(draws);
  }
  EXPECT_GT(previous, 0.7);  // 3 jnd: found most of the time
}

TEST(SimulatedObserver, LapsesAnswerAtRandomAndBiasFavoursTheBlurredSide) {
  ObserverParams p = Pixel();
  p.jnd_px = 0.01;  // practically noiseless
  p.bias_px = 0;
  p.lapse = 0.3;
  SimulatedObserver o(p, 9);
  const PairView clear{2.0, 4.0, 2.0};  // left is right, by far
  int wrong = 0;
  const int draws = 6000;
  for (int i = 0; i < draws; ++i) wrong += Name(o.ChooseSide(clear).action) != "left";
  EXPECT_NEAR(wrong / double(draws), p.lapse * 2 / 3, 0.02);

  p.lapse = 0;
  p.bias_px = 0.5;
  SimulatedObserver biased(p, 9);
  // Equal mismatch on both sides (1 px too little vs 1 px too much): the bias decides for the blurred side.
  EXPECT_EQ(Name(biased.ChooseSide({1.0, 3.0, 2.0}).action), "right");
  EXPECT_EQ(Name(biased.ChooseSide({3.0, 1.0, 2.0}).action), "left");
}

// Steps through cyclic levels as the runner does and returns the accepted level.
// What an adjustment trial shows: the distance, and for model=arcmin the real blur and each level's (arcmin).
AdjustView AdjustAt(double distance_m, double r_real_arcmin = -1, std::vector<double> level_r_arcmin = {}) {
  AdjustView v;
  v.distance_m = distance_m;
  v.r_real_arcmin = r_real_arcmin;
  v.level_r_arcmin = std::move(level_r_arcmin);
  return v;
}

double Accepted(const std::vector<double>& levels, int start, const std::vector<KeyPress>& presses) {
  int at = start;
  const int n = static_cast<int>(levels.size());
  for (const KeyPress& k : presses) {
    if (Name(k.action) == "next") at = (at + 1) % n;
    if (Name(k.action) == "previous") at = (at + n - 1) % n;
    if (Name(k.action) == "accept") return levels[size_t(at)];
  }
  return NAN;
}

TEST(SimulatedObserver, PixelAdjustmentAcceptsTheLevelNearestItsTarget) {
  ObserverParams p;
  p.model = ObserverModel::kPixel;
  p.sd_log = 0;
  p.tolerance_log = 0;  // must look at every level
  const std::vector<double> levels = {11.6, 2.0, 47.2, 4.8, 80.0, 8.2, 23.4, 3.4, 33.2, 6.8, 16.5};
  for (double distance : {0.4, 1.0, 2.5, 4.0}) {
    for (int start : {0, 5, 10}) {
      SimulatedObserver o(p, 3);
      const auto presses = o.Adjust(levels, start, AdjustAt(distance));
      ASSERT_FALSE(presses.empty());
      EXPECT_EQ(Name(presses.back().action), "accept");
      const double target = p.cutoff_1m * std::pow(distance, p.slope);
      const double best = *std::min_element(levels.begin(), levels.end(), [&](double a, double b) {
        return std::abs(std::log(a / target)) < std::abs(std::log(b / target));
      });
      EXPECT_DOUBLE_EQ(Accepted(levels, start, presses), best) << "distance " << distance << " start " << start;
      // Walks the levels once, then back the shorter way: never more than 1.5 rounds.
      EXPECT_LE(presses.size(), levels.size() * 3 / 2 + 1);
    }
  }
}

// ---- model=arcmin ----

// The model's closed form written out here, apart from observer.cc: s the Gaussian std (arcmin), E the seen blur.
double SeenBlur(double s, double s_i, double p) { return std::pow(std::pow(s, p) + std::pow(s_i, p), 1 / p); }
double Correct2afc(double s_a, double s_b, double s_i, double w, double p) {
  return NormalCdf(0.6744897501960817 * std::abs(std::log(SeenBlur(s_a, s_i, p) / SeenBlur(s_b, s_i, p))) / std::log(1 + w));
}

TEST(ArcminObserver, ProbabilityIsTheClosedFormOnRadiiTwiceTheStd) {
  for (double p_exp : {1.0, 2.0, 3.5}) {
    ObserverParams p;
    p.exponent = p_exp;
    p.intrinsic_arcmin = 0.8;
    p.weber = 0.4;
    for (double a : {0.0, 0.3, 1.0, 2.5, 9.0})
      for (double b : {0.0, 0.2, 1.1, 4.0, 12.0})
        // r = 2 s: the radii given are twice the stds the literature's law is written in.
        EXPECT_NEAR(ProbabilityCorrect2afc(p, a, b), Correct2afc(a / 2, b / 2, 0.8, 0.4, p_exp), 1e-12)
            << a << " vs " << b << ", exponent " << p_exp;
    EXPECT_DOUBLE_EQ(ProbabilityCorrect2afc(p, 3, 3), 0.5);
  }
}

// The dipper: P = 75 % exactly at the threshold increment; for p = 2 the threshold at zero reference is
// 2 s_i sqrt((1+w)^2 - 1), the dip lies at s = s_i / (1+w) with depth 2 s_i ((1+w) - 1/(1+w)) (in r = 2 s), and far
// above the intrinsic blur the threshold grows as w times the reference (Weber's law).
TEST(ArcminObserver, DipperMatchesItsClosedForm) {
  ObserverParams p;
  p.intrinsic_arcmin = 0.7;
  p.weber = 0.35;
  const double si = 0.7, w = 0.35;
  for (double exponent : {1.5, 2.0, 3.0}) {
    p.exponent = exponent;
    for (double r : {0.0, 0.4, 1.0, 3.0, 10.0, 40.0})
      EXPECT_NEAR(ProbabilityCorrect2afc(p, r, r + DiscriminationThresholdArcmin(p, r)), 0.75, 1e-9) << r;
  }
  p.exponent = 2;
  EXPECT_NEAR(DiscriminationThresholdArcmin(p, 0), 2 * si * std::sqrt((1 + w) * (1 + w) - 1), 1e-12);
  // The dip found by a scan of the function, against the closed form.
  double best_r = 0, best = 1e9;
  for (double r = 0; r < 5; r += 1e-4)
    if (const double t = DiscriminationThresholdArcmin(p, r); t < best) best = t, best_r = r;
  EXPECT_NEAR(best_r, 2 * si / (1 + w), 2e-4);
  EXPECT_NEAR(best, 2 * si * ((1 + w) - 1 / (1 + w)), 1e-7);
  EXPECT_LT(best, DiscriminationThresholdArcmin(p, 0));  // a dip below the detection threshold ...
  EXPECT_NEAR(DiscriminationThresholdArcmin(p, 2000) / 2000, w, 1e-3);  // ... and Weber's law far above it
}

// The dipper's shape as the blur-discrimination reviews describe it: the defaults stay within a factor of 1.5 of
// five threshold-vs-reference-blur points (Gaussian std, arcmin: reference blur -> 75 % discrimination increment) -
// about 0.5 arcmin on a sharp edge, a dip to 0.3-0.4 arcmin near a reference of 0.5 arcmin, then a near-Weber rise to
// about 1.5 arcmin at 4 arcmin.
//
// These points are NOT digitised data. They were typed in from the shape of the threshold-vs-reference figures of
// Mather & Smith 2002 (Perception 31:1211-1219) and the data Watson & Ahumada 2011 (J. Vision 11(5):10) compile, as
// recalled, without the papers at hand. Three sessions searched every corpus this project can reach (the papers'
// first pages, abstracts, PubMed mirrors, public code) and found no table or digitised figure of such points; only
// the abstract numbers HonoursPublishedWeberFractionsAndIntrinsicBlur holds were found. Check these points against
// the figures (Mather & Smith 2002 figs. 4-5, or W&A's compiled data) before citing this test as a validation. What it
// does hold: the shape (a dip below the no-blur threshold, then Weber), and the unit - the model is given blurcue
// radii r = 2 s and its increments are halved back to stds, so confusing r with s (a factor 2) fails here.
TEST(ArcminObserver, DipperKeepsTheShapeTheReviewsDescribe) {
  const ObserverParams p;  // the defaults
  struct Point {
    double reference_std, threshold_std;
  };
  const Point points[] = {{0.0, 0.5}, {0.5, 0.35}, {1.0, 0.45}, {2.0, 0.8}, {4.0, 1.5}};
  for (const Point& pt : points) {
    const double model_std = DiscriminationThresholdArcmin(p, 2 * pt.reference_std) / 2;
    EXPECT_LE(model_std, pt.threshold_std * 1.5) << "reference " << pt.reference_std << " arcmin";
    EXPECT_GE(model_std, pt.threshold_std / 1.5) << "reference " << pt.reference_std << " arcmin";
  }
  // The defaults sit in the ranges the literature gives: intrinsic blur 0.5-1 arcmin, Weber fraction 0.3-0.6.
  EXPECT_GE(p.intrinsic_arcmin, 0.5);
  EXPECT_LE(p.intrinsic_arcmin, 1.0);
  EXPECT_GE(p.weber, 0.3);
  EXPECT_LE(p.weber, 0.6);
}

// Two published numbers the model must honour, quoted from the papers' abstracts (not read off a figure):
// - Mather & Smith 2002 (Perception 31:1211): "Weber fractions for blur discrimination ranged from 0.28 to 0.56" -
//   the model's threshold over its reference, well above the intrinsic blur (references of 2-8 arcmin std), lies there;
// - Levi & Klein 1990 (Vision Res. 30:1971, "Equivalent intrinsic blur in spatial vision"): the fovea's equivalent
//   intrinsic blur is about 0.5 arcmin (std) - below it, added blur hardly changes what is seen. The model's dip, the
//   reference at which added blur is best told apart, lies below the intrinsic blur and its unblurred threshold at
//   the intrinsic blur's scale: between 0.5 and 2 x 0.5 arcmin x sqrt((1+w)^2 - 1) for s_i from 0.5 to 1.
TEST(ArcminObserver, HonoursPublishedWeberFractionsAndIntrinsicBlur) {
  const ObserverParams p;
  for (double reference_std : {2.0, 4.0, 8.0}) {
    const double weber = DiscriminationThresholdArcmin(p, 2 * reference_std) / (2 * reference_std);  // r = 2 s
    EXPECT_GE(weber, 0.28) << reference_std;
    EXPECT_LE(weber, 0.56) << reference_std;
  }
  // The threshold at no reference blur: s_i sqrt((1+w)^2 - 1) for the model; for s_i in Levi & Klein's 0.5 to the
  // literature's 1 arcmin and this w, between these bounds.
  const double at_zero_std = DiscriminationThresholdArcmin(p, 0) / 2;
  const double scale = std::sqrt((1 + p.weber) * (1 + p.weber) - 1);
  EXPECT_GE(at_zero_std, 0.5 * scale);
  EXPECT_LE(at_zero_std, 1.0 * scale);
  // Below the intrinsic blur, a little added blur is told apart no worse than none: the dipper's dip lies there.
  EXPECT_LT(DiscriminationThresholdArcmin(p, 2 * 0.4), DiscriminationThresholdArcmin(p, 0));
}

// Simulated "which is more blurred?" answers against the analytic probability: P(1 - lapse) + lapse / 2.
TEST(ArcminObserver, ChoiceRatesMatchTheAnalyticProbability) {
  ObserverParams p;
  p.lapse = 0.06;
  SimulatedObserver o(p, 21);
  const double arcmin_per_px = 0.8;
  const int draws = 8000;
  const double se = std::sqrt(0.25 / draws);
  for (const auto& [a, b] : {std::pair{1.0, 1.0}, {1.0, 1.5}, {2.0, 3.0}, {6.0, 7.0}, {0.2, 2.0}}) {
    const PairView v{b, a, 0, arcmin_per_px};  // left the more blurred (or equal)
    int left = 0;
    for (int i = 0; i < draws; ++i) left += Name(o.ChooseBlurrier(v).action) == "left";
    const double truth = Correct2afc(b * arcmin_per_px / 2, a * arcmin_per_px / 2, p.intrinsic_arcmin, p.weber, 2);
    EXPECT_NEAR(left / double(draws), truth * (1 - p.lapse) + p.lapse / 2, 4 * se) << a << " vs " << b << " px";
  }
}

// "Which fits the scene?" in arcmin: each side's mismatch m = |ln E(side) - ln E(scene)|; left when D = m_right -
// m_left + blurrier bias + noise exceeds half the comparison's noise sd ln(1+w) / z75, right below minus half.
TEST(ArcminObserver, MismatchChoiceRatesMatchTheModel) {
  ObserverParams p;
  p.lapse = 0;
  p.blurrier_bias = 0;
  SimulatedObserver o(p, 17);
  const double sd = std::log(1 + p.weber) / 0.6744897501960817, k = 1.25;  // k arcmin per px
  const int draws = 8000;
  const double se = std::sqrt(0.25 / draws);
  auto ln_e = [&](double r_px) { return std::log(SeenBlur(r_px * k / 2, p.intrinsic_arcmin, 2)); };
  for (double off : {0.0, 0.6, 2.0}) {
    const PairView v{2.0, 2.0 + off, 2.0, k};  // left matches the scene
    std::map<std::string, int> n;
    for (int i = 0; i < draws; ++i) ++n[Name(o.ChooseSide(v).action)];
    const double delta = std::abs(ln_e(2.0 + off) - ln_e(2.0));
    EXPECT_NEAR(n["left"] / double(draws), 1 - NormalCdf((sd / 2 - delta) / sd), 4 * se) << off;
    EXPECT_NEAR(n["right"] / double(draws), NormalCdf((-sd / 2 - delta) / sd), 4 * se) << off;
  }
}

// What the eye gets decides: the same arcmin shown with other px (a photo scaled down, a monitor farther away) is
// answered the same, seed for seed; the same px at a third of the angle is harder
// where the blurs are near the intrinsic blur.
TEST(ArcminObserver, AnswersDependOnVisualAngleNotPixels) {
  const ObserverParams p;
  SimulatedObserver a(p, 5), b(p, 5);
  for (int i = 0; i < 300; ++i) {
    const KeyPress x = a.ChooseBlurrier({4.0, 3.0, 0, 0.5}), y = b.ChooseBlurrier({2.0, 1.5, 0, 1.0});
    EXPECT_EQ(Name(x.action), Name(y.action));
    EXPECT_NEAR(x.after_ms, y.after_ms, 1e-9);
  }
  // Near the intrinsic blur a third of the angle sinks the difference into it (66 % -> 52 %).
  EXPECT_GT(ProbabilityCorrect2afc(p, {1.0, 0.5, 0, 1.0}), ProbabilityCorrect2afc(p, {1.0, 0.5, 0, 1.0 / 3}) + 0.1);
  EXPECT_THROW(ProbabilityCorrect2afc(p, {4.0, 3.0, 0, 0}), Error);  // the angle unknown: no answer in arcmin
}

TEST(ArcminObserver, SideBiasFavoursTheLeftByItsNoiseSds) {
  ObserverParams p;
  p.lapse = 0;
  p.side_bias = 1;
  SimulatedObserver o(p, 3);
  const int draws = 8000;
  int left = 0;
  for (int i = 0; i < draws; ++i) left += Name(o.ChooseBlurrier({2.0, 2.0, 0, 1.0}).action) == "left";
  EXPECT_NEAR(left / double(draws), NormalCdf(1), 4 * std::sqrt(0.25 / draws));  // equal blurs: bias over unit noise
}

// Response times: log-normal around rt for an easy trial, (1 + rthard) rt for one it cannot see (d' = 0).
TEST(ArcminObserver, HardTrialsTakeLonger) {
  ObserverParams p;
  p.lapse = 0;
  SimulatedObserver o(p, 8);
  std::vector<double> hard, easy;
  for (int i = 0; i < 4001; ++i) {
    hard.push_back(o.ChooseBlurrier({2.0, 2.0, 0, 1.0}).after_ms);
    easy.push_back(o.ChooseBlurrier({40.0, 2.0, 0, 1.0}).after_ms);
  }
  std::nth_element(hard.begin(), hard.begin() + 2000, hard.end());
  std::nth_element(easy.begin(), easy.begin() + 2000, easy.end());
  // The median of 4001 log-normal draws (sd 0.3) is within 3 % of the true median with high probability.
  EXPECT_NEAR(hard[2000] / (p.rt_ms * (1 + p.rt_hard)), 1, 0.03);
  EXPECT_NEAR(easy[2000] / p.rt_ms, 1, 0.03);
}

TEST(ObserverParams, ArcminModelIsTheDefaultAndEveryFormReadsBack) {
  const ObserverParams d = ParseObserver("sim");
  EXPECT_EQ(d.model, ObserverModel::kArcmin);
  EXPECT_EQ(ToString(d), "sim:model=arcmin,intrinsic=0.6,weber=0.35,exponent=2,side=0,blurrier=0.3,rthard=0.5,"
                         "lapse=0.04,rt=900,step=350");
  const ObserverParams q = ParseObserver("sim:intrinsic=0.9,weber=0.123456789,exponent=3,side=-0.5,lapse=0");
  EXPECT_EQ(q.model, ObserverModel::kArcmin);
  EXPECT_DOUBLE_EQ(q.weber, 0.123456789);
  EXPECT_EQ(ToString(ParseObserver(ToString(q))), ToString(q));
  EXPECT_DOUBLE_EQ(ParseObserver(ToString(q)).weber, 0.123456789);  // the recorded text is the observer that ran
  const ObserverParams px = ParseObserver("sim:model=pixel");
  EXPECT_EQ(ToString(px), "sim:model=pixel,jnd=0.6,bias=0.2,lapse=0.04,rt=900,step=350,cutoff1m=14,slope=-0.8,"
                          "sdlog=0.15,tol=0.1");
  // The form every record before model= existed holds reads as the pixel observer it was.
  EXPECT_EQ(ToString(ParseObserver("sim:jnd=0.6,bias=0.2,lapse=0.04,rt=900,step=350,cutoff1m=14,slope=-0.8,"
                                   "sdlog=0.15,tol=0.1")),
            ToString(px));
}

TEST(ObserverParams, RejectsEveryBadValueWithOneLineNamingIt) {
  const std::pair<const char*, const char*> cases[] = {
      {"sim:intrinsic=0", "--observer intrinsic must be in (0, 60]"},
      {"sim:intrinsic=nan", "--observer intrinsic must be a number, got 'nan'"},
      {"sim:weber=1e308", "--observer weber must be in (0, 10], got '1e308'"},
      {"sim:weber=-1", "--observer weber must be in (0, 10], got '-1'"},
      {"sim:exponent=", "--observer exponent must be a number, got ''"},
      {"sim:side=inf", "--observer side must be a number"},
      {"sim:rthard=-1", "--observer rthard must be in 0..100"},
      {"sim:rt=1e308", "--observer rt must be in (0, 600000] ms, got '1e308'"},
      {"sim:model=pixel,weber=0.3", "--observer weber belongs to model=arcmin, not model=pixel"},
      {"sim:model=arcmin,jnd=0.3", "--observer jnd belongs to model=pixel, not model=arcmin"},
      {"sim:model=retina", "--observer model must be arcmin or pixel, got 'retina'"},
      {"sim:lapse=0.1,lapse=0.2", "--observer lapse is given twice"},
      {"sim:", "--observer: an empty parameter"},
      {"sim:lapse=0,", "--observer: an empty parameter"},
      {"sim:weber", "--observer weber must be a number, got ''"},
      {"sim:sharpness=2", "--observer: unknown parameter 'sharpness' (known: model, blurrier, exponent, intrinsic, "
                          "rthard, side, weber, lapse, rt, step)"},
      // A slip of a known name gets a did-you-mean (the model's own names: bias is model=pixel's).
      {"sim:jnd=0.6,bais=0", "--observer: unknown parameter 'bais' (did you mean bias?)"},
      {"sim:webr=0.3", "--observer: unknown parameter 'webr' (did you mean weber?)"},
      {"sim:weber=0x10", "--observer weber must be a number, got '0x10'"},  // not 16: decimal only
      {"sim:weber= 0.3", "--observer weber must be a number, got ' 0.3'"},
      {"sim:lapse=0.1 ", "--observer lapse must be a number, got '0.1 '"},
  };
  for (const auto& [spec, message] : cases) {
    try {
      ParseObserver(spec);
      ADD_FAILURE() << spec << " was accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::kUsage) << spec;
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << spec << ": " << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << spec;
    }
  }
}

// Depth matching in visual angle: 22 levels whose blurs (arcmin, blurcue's r) run from 0.4' to 16', shuffled, and a
// real blur r_real. The observer compares every level once with the real picture and takes the closest-looking one:
// level i wins with probability P_i = integral f_i(x) prod_(j != i) (1 - F_j(x)) dx, |D_j| folded normal around
// mu_j = ln E(level j) - ln E(real) with the compare sd. That integral, worked out here numerically, against the
// shares of 3000 seeded trials: within 0.025 each (binomial sd <= 0.009). For a sharp real picture the dipper spreads
// the choices over every level sharper than the eye's intrinsic blur.
TEST(SimulatedObserver, ArcminAdjustmentTakesTheLevelThatLooksClosest) {
  ObserverParams p;
  p.lapse = 0;
  std::vector<double> levels, level_r;
  for (int i = 0; i < 22; ++i) levels.push_back(80 * std::pow(2.0 / 80, i / 21.0));  // cut-offs 80 .. 2
  std::mt19937 shuffle(5);
  std::shuffle(levels.begin(), levels.end(), shuffle);
  for (double c : levels) level_r.push_back(0.4 * 80 / c);  // 0.4' .. 16'
  const double sd = std::log(1 + p.weber) / 0.6744897501960817;
  auto ln_e = [&](double r) { return std::log(SeenBlur(r / 2, p.intrinsic_arcmin, 2)); };
  auto pdf = [](double z) { return std::exp(-z * z / 2) / std::sqrt(2 * M_PI); };
  for (double real : {0.0, 3.0, 6.0}) {
    std::vector<double> mu;
    for (double r : level_r) mu.push_back(ln_e(r) - ln_e(real));
    std::vector<double> expected(levels.size(), 0);
    const int steps = 6000;
    const double top = 10 * sd + 5, dx = top / steps;
    for (int k = 0; k <= steps; ++k) {  // Simpson's rule on [0, top]
      const double x = k * dx, weight = (k == 0 || k == steps ? 1 : k % 2 ? 4 : 2) * dx / 3;
      for (size_t i = 0; i < mu.size(); ++i) {
        double others = 1;
        for (size_t j = 0; j < mu.size(); ++j)
          if (j != i) others *= 1 - (NormalCdf((x - mu[j]) / sd) - NormalCdf((-x - mu[j]) / sd));
        expected[i] += weight * (pdf((x - mu[i]) / sd) + pdf((x + mu[i]) / sd)) / sd * others;
      }
    }
    std::vector<double> share(levels.size(), 0);
    const int n = 3000;
    for (uint64_t seed = 1; seed <= uint64_t(n); ++seed) {
      SimulatedObserver o(p, seed);
      const int start = int(seed % 22);
      const auto presses = o.Adjust(levels, start, AdjustAt(1.0, real, level_r));
      ASSERT_EQ(Name(presses.back().action), "accept");
      ASSERT_GE(presses.size(), levels.size());  // every level seen before the choice
      const auto chosen = std::find(levels.begin(), levels.end(), Accepted(levels, start, presses));
      share[size_t(chosen - levels.begin())] += 1.0 / n;
    }
    double total = 0;
    for (size_t i = 0; i < levels.size(); ++i) {
      total += expected[i];
      EXPECT_NEAR(share[i], expected[i], 0.025) << "real " << real << "', level " << level_r[i] << "'";
    }
    EXPECT_NEAR(total, 1, 1e-6) << real;
  }
  // Without the real blur the arcmin model cannot answer: a usage error, not a guess.
  SimulatedObserver o(p, 1);
  EXPECT_THROW(o.Adjust(levels, 0, AdjustAt(1.0)), Error);
}

// model=pixel is the observer of old, answer for answer: every task's presses over a grid of views and seeds, as text,
// against the hash of the same text from the observer as it was before model= existed (observer.cc at commit afd7490,
// built apart with this very loop: 8772 characters, FNV-1a ee6e6e56d9f704ca). A record made with a seed then is the
// record the pixel model makes now.
TEST(SimulatedObserver, PixelModelAnswersAsTheObserverBeforeIt) {
  ObserverParams p;
  p.model = ObserverModel::kPixel;
  std::string out;
  char text[64];
  auto add = [&](const KeyPress& k) {
    std::snprintf(text, sizeof text, "%s@%.6f;", Name(k.action).c_str(), k.after_ms);
    out += text;
  };
  for (uint64_t seed = 1; seed <= 40; ++seed) {
    SimulatedObserver o(p, seed);
    const double d = 0.1 * double(seed % 9);
    const PairView v{1.5 + d, 1.5 + d * d, 1.5 + 0.2 * d};
    add(o.ChooseSide(v));
    add(o.ChooseSide(v, false));
    add(o.ChooseBlurrier(v));
    add(o.ChooseOdd(v, 3, 2));
    add(o.ChooseOdd(v, 4, 1));
    add(o.SayYesNo(v));
    add(o.Rate(v, 5));
    for (const KeyPress& k :
         o.Adjust({11.6, 2.0, 47.2, 4.8, 80.0, 8.2, 23.4}, int(seed % 7), AdjustAt(0.4 + 0.1 * double(seed))))
      add(k);
  }
  uint64_t hash = 1469598103934665603ULL;
  for (unsigned char c : out) hash = (hash ^ c) * 1099511628211ULL;
  EXPECT_EQ(out.size(), 8772u);
  EXPECT_EQ(hash, 0xee6e6e56d9f704caULL) << out.substr(0, 200);
}

}  // namespace
}  // namespace blurcue::procedure
