#include "session/observer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>

#include "core/error.h"

namespace blurcue::session {
namespace {

double Phi(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

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
    EXPECT_EQ(x.action, y.action);
    EXPECT_DOUBLE_EQ(x.after_ms, y.after_ms);
    differ += x.action != z.action;
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
    for (int i = 0; i < draws; ++i) ++n[o.ChooseSide(v).action];
    const double c = p.jnd_px / 2;
    const double left = 1 - Phi((c - delta) / p.jnd_px), right = Phi((-c - delta) / p.jnd_px);
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
    for (int i = 0; i < draws; ++i) yes += o.SayYesNo(v).action == "yes";
    for (int i = 0; i < draws; ++i) {
      const std::string r = o.Rate(v, 5).action;
      lowest += r == "1";
      highest += r == "5";
    }
    EXPECT_NEAR(yes / double(draws), 1 - Phi((p.jnd_px / 2 - m) / p.jnd_px), 4 * se) << "m " << m;
    EXPECT_NEAR(lowest / double(draws), Phi((p.jnd_px / 2 - m) / p.jnd_px), 4 * se) << "m " << m;
    EXPECT_NEAR(highest / double(draws), 1 - Phi((4 * p.jnd_px / 2 - m) / p.jnd_px), 4 * se) << "m " << m;
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
    for (int i = 0; i < draws; ++i) ++named[std::stoi(o.ChooseOdd(v, n, 2).action)];
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
  for (int i = 0; i < draws; ++i) wrong += o.ChooseSide(clear).action != "left";
  EXPECT_NEAR(wrong / double(draws), p.lapse * 2 / 3, 0.02);

  p.lapse = 0;
  p.bias_px = 0.5;
  SimulatedObserver biased(p, 9);
  // Equal mismatch on both sides (1 px too little vs 1 px too much): the bias decides for the blurred side.
  EXPECT_EQ(biased.ChooseSide({1.0, 3.0, 2.0}).action, "right");
  EXPECT_EQ(biased.ChooseSide({3.0, 1.0, 2.0}).action, "left");
}

// Steps through cyclic levels as the runner does and returns the accepted level.
double Accepted(const std::vector<double>& levels, int start, const std::vector<KeyPress>& presses) {
  int at = start;
  const int n = static_cast<int>(levels.size());
  for (const KeyPress& k : presses) {
    if (k.action == "next") at = (at + 1) % n;
    if (k.action == "previous") at = (at + n - 1) % n;
    if (k.action == "accept") return levels[size_t(at)];
  }
  return NAN;
}

TEST(SimulatedObserver, AdjustmentAcceptsTheLevelNearestItsTarget) {
  ObserverParams p;
  p.sd_log = 0;
  p.tolerance_log = 0;  // must look at every level
  const std::vector<double> levels = {11.6, 2.0, 47.2, 4.8, 80.0, 8.2, 23.4, 3.4, 33.2, 6.8, 16.5};
  for (double distance : {0.4, 1.0, 2.5, 4.0}) {
    for (int start : {0, 5, 10}) {
      SimulatedObserver o(p, 3);
      const auto presses = o.Adjust(levels, start, distance);
      ASSERT_FALSE(presses.empty());
      EXPECT_EQ(presses.back().action, "accept");
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

}  // namespace
}  // namespace blurcue::session
