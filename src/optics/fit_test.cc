#include "optics/fit.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"

namespace blurcue::optics {
namespace {

const Lens kThesisLens{21.0, 21.0 / 5.6, 5.1e-3};
constexpr double kInfinity = std::numeric_limits<double>::infinity();
// Table 4.3's edge depths (given there in cm), edge 1 nearest.
const double kEdgeMm[] = {342.3, 359.6, 377.0, 394.3, 411.7, 429.0, 446.3, 463.7, 481.0, 498.3, 527.3};

// Textbook blur-circle radius in px, r = D f |u - u0| / (2 u (u0 - f) pitch), independent of the code under test.
double TruthPx(double u0, double u, double aperture_mm = kThesisLens.aperture_mm, double floor_px = 0,
               double pitch_mm = kThesisLens.pixel_pitch_mm) {
  const double f = kThesisLens.focal_length_mm;
  const double c = std::isinf(u0) ? aperture_mm * f / u : aperture_mm * f * std::abs(u - u0) / (u * (u0 - f));
  const double r = c / 2 / pitch_mm;
  return std::sqrt(r * r + floor_px * floor_px);
}

struct SceneSpec {
  double focus_mm = 258.18;  // what the thesis's r1 = 8 px at edge 1 implies
  double floor_px = 0;
  double noise_px = 0;
  int first_edge = 1, last_edge = 11;
  uint64_t seed = 1;
};

// 7 sections per edge, like the 11 x 7 sections of the thesis's board.
std::vector<BlurSample> Samples(const SceneSpec& spec) {
  std::mt19937_64 rng(spec.seed);
  std::normal_distribution<double> noise(0.0, spec.noise_px);
  std::vector<BlurSample> out;
  for (int e = spec.first_edge; e <= spec.last_edge; ++e)
    for (int s = 0; s < 7; ++s) {
      const double u = kEdgeMm[e - 1];
      const double r = TruthPx(spec.focus_mm, u, kThesisLens.aperture_mm, spec.floor_px);
      out.push_back({u, std::max(0.0, r + (spec.noise_px > 0 ? noise(rng) : 0.0)), 1.0});
    }
  return out;
}

TEST(FitThinLens, RecoversFocusAndApertureFromExactSamples) {
  const FittedModel m = FitThinLens(kThesisLens, Samples({}));
  EXPECT_NEAR(m.focus_mm, 258.18, 0.01 * 258.18);
  EXPECT_NEAR(m.aperture_mm, 3.75, 0.01 * 3.75);
  EXPECT_EQ(m.kind, "thin_lens");
  EXPECT_EQ(m.floor_px, 0.0);
  EXPECT_EQ(m.samples_used, 77);
  EXPECT_EQ(m.outliers, 0);
  EXPECT_LT(m.rms_px, 1e-3);
  EXPECT_LT(m.loo_rms_px, 1e-3);
}

TEST(FitThinLens, RecoversFocusAndApertureFromNoisySamples) {
  SceneSpec spec;
  spec.noise_px = 0.2;
  const FittedModel m = FitThinLens(kThesisLens, Samples(spec));
  EXPECT_NEAR(m.focus_mm, 258.18, 0.03 * 258.18);
  EXPECT_NEAR(m.aperture_mm, 3.75, 0.03 * 3.75);
  // The residual is the noise, no more and not much less.
  EXPECT_GT(m.rms_px, 0.1);
  EXPECT_LT(m.rms_px, 0.3);
}

TEST(FitThinLens, RobustToGrossOutliers) {
  SceneSpec spec;
  spec.noise_px = 0.1;
  std::vector<BlurSample> samples = Samples(spec);
  // A printing flaw (dark spots) doubles the measured radius on every tenth section.
  int flawed = 0;
  for (size_t i = 3; i < samples.size(); i += 10) samples[i].r_px *= 2, ++flawed;
  ASSERT_GE(flawed, 7);
  const FittedModel m = FitThinLens(kThesisLens, samples);
  EXPECT_NEAR(m.focus_mm, 258.18, 0.03 * 258.18);
  EXPECT_NEAR(m.aperture_mm, 3.75, 0.03 * 3.75);
  EXPECT_EQ(m.outliers, flawed);
  EXPECT_LT(m.rms_px, 0.3);
}

TEST(FitThinLens, FocusInsideTheSampleRange) {
  SceneSpec spec;
  spec.focus_mm = 430.0;
  const FittedModel m = FitThinLens(kThesisLens, Samples(spec));
  EXPECT_NEAR(m.focus_mm, 430.0, 0.01 * 430.0);
  EXPECT_NEAR(m.aperture_mm, 3.75, 0.01 * 3.75);
}

TEST(FitThinLens, FocusBeyondAllSamples) {
  SceneSpec spec;
  spec.focus_mm = 800.0;
  spec.noise_px = 0.1;
  const FittedModel m = FitThinLens(kThesisLens, Samples(spec));
  EXPECT_NEAR(m.focus_mm, 800.0, 0.03 * 800.0);
  EXPECT_NEAR(m.aperture_mm, 3.75, 0.03 * 3.75);
}

TEST(FitThinLens, FocusAtInfinity) {
  SceneSpec spec;
  spec.focus_mm = kInfinity;
  const FittedModel m = FitThinLens(kThesisLens, Samples(spec));
  // Beyond 1 km is infinity for a 21 mm lens looking at half a metre.
  EXPECT_GT(m.focus_mm, 1e6);
  EXPECT_NEAR(m.aperture_mm, 3.75, 0.01 * 3.75);
  EXPECT_NEAR(m.PredictPx(kThesisLens, 1000.0), TruthPx(kInfinity, 1000.0), 0.01 * TruthPx(kInfinity, 1000.0));
}

TEST(FitThinLens, KeepsFloorWhenDataHaveOne) {
  SceneSpec spec;
  spec.focus_mm = 430.0;
  spec.floor_px = 1.5;
  spec.noise_px = 0.05;
  const FittedModel m = FitThinLens(kThesisLens, Samples(spec));
  EXPECT_EQ(m.kind, "thin_lens+floor");
  EXPECT_NEAR(m.floor_px, 1.5, 0.1 * 1.5);
  EXPECT_NEAR(m.focus_mm, 430.0, 0.02 * 430.0);
  EXPECT_NEAR(m.aperture_mm, 3.75, 0.03 * 3.75);
  EXPECT_LT(m.loo_rms_px, 0.1);
}

TEST(FitThinLens, DropsFloorWhenDataHaveNone) {
  SceneSpec spec;
  spec.focus_mm = 430.0;
  spec.noise_px = 0.05;
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    spec.seed = seed;
    const FittedModel m = FitThinLens(kThesisLens, Samples(spec));
    EXPECT_EQ(m.kind, "thin_lens") << "seed " << seed;
    EXPECT_EQ(m.floor_px, 0.0) << "seed " << seed;
  }
}

TEST(FitThinLens, NoFloorWhenNotAllowed) {
  SceneSpec spec;
  spec.focus_mm = 430.0;
  spec.floor_px = 1.5;
  FitOptions options;
  options.allow_floor = false;
  const FittedModel m = FitThinLens(kThesisLens, Samples(spec), options);
  EXPECT_EQ(m.kind, "thin_lens");
  EXPECT_EQ(m.floor_px, 0.0);
  // The floor it may not model shows up in the residual.
  EXPECT_GT(m.rms_px, 0.1);
}

TEST(FitThinLens, PredictsHeldOutDepths) {
  SceneSpec spec;
  spec.noise_px = 0.1;
  spec.last_edge = 7;
  const FittedModel m = FitThinLens(kThesisLens, Samples(spec));
  for (int e = 8; e <= 11; ++e) {
    const double truth = TruthPx(258.18, kEdgeMm[e - 1]);
    EXPECT_NEAR(m.PredictPx(kThesisLens, kEdgeMm[e - 1]), truth, 0.05 * truth) << "edge " << e;
  }
}

TEST(FitThinLens, ZeroWeightDropsSample) {
  std::vector<BlurSample> samples = Samples({});
  samples.push_back({400.0, 1000.0, 0.0});
  const FittedModel m = FitThinLens(kThesisLens, samples);
  EXPECT_EQ(m.samples_used, 77);
  EXPECT_EQ(m.outliers, 0);
  EXPECT_NEAR(m.focus_mm, 258.18, 0.01 * 258.18);
}

TEST(FitThinLens, FewerThanThreeSamplesIsNotFound) {
  const std::vector<BlurSample> two = {{342.3, 8.0, 1.0}, {527.3, 16.6, 1.0}, {400.0, 12.0, 0.0}};
  try {
    FitThinLens(kThesisLens, two);
    FAIL() << "expected Error(kNotFound)";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kNotFound);
    EXPECT_NE(std::string(e.what()).find("got 2"), std::string::npos) << e.what();
  }
}

TEST(FitThinLens, SamplesAtOneDepthIsNotFound) {
  const std::vector<BlurSample> one_depth = {{400.0, 8.0, 1.0}, {400.0, 8.5, 1.0}, {400.0, 7.5, 1.0}};
  try {
    FitThinLens(kThesisLens, one_depth);
    FAIL() << "expected Error(kNotFound)";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kNotFound);
    EXPECT_NE(std::string(e.what()).find("one depth"), std::string::npos) << e.what();
  }
}

TEST(FitThinLens, SampleInsideFocalLengthIsDomainError) {
  std::vector<BlurSample> samples = Samples({});
  samples[5].u_mm = 20.0;
  try {
    FitThinLens(kThesisLens, samples);
    FAIL() << "expected Error(kDomain)";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kDomain);
    EXPECT_NE(std::string(e.what()).find("sample 5"), std::string::npos) << e.what();
  }
}

TEST(FitThinLens, NegativeRadiusIsInputError) {
  std::vector<BlurSample> samples = Samples({});
  samples[2].r_px = -1.0;
  try {
    FitThinLens(kThesisLens, samples);
    FAIL() << "expected Error(kInput)";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    EXPECT_NE(std::string(e.what()).find("sample 2 r_px: must be a finite number >= 0, got -1"), std::string::npos)
        << e.what();
  }
}

TEST(FitThinLens, SampleAtInfinityIsUsable) {
  // A far background sample (u = infinity) has the finite radius D f / (2 (u0 - f) pitch).
  std::vector<BlurSample> samples = Samples({});
  const double at_infinity =
      kThesisLens.aperture_mm * kThesisLens.focal_length_mm / (2 * (258.18 - kThesisLens.focal_length_mm)) / kThesisLens.pixel_pitch_mm;
  samples.push_back({kInfinity, at_infinity, 1.0});
  const FittedModel m = FitThinLens(kThesisLens, samples);
  EXPECT_EQ(m.samples_used, 78);
  EXPECT_EQ(m.outliers, 0);
  EXPECT_NEAR(m.focus_mm, 258.18, 0.01 * 258.18);
}

// The synth take's optics (synth-take: 23.4 mm sensor over 1148 px, f = 21 mm at f/5.6, floor std 0.35 px, so
// r = 0.7 px at focus) over its depths (edge 1 at 360 mm to edge 11 at 640 mm across the take's frames), 7
// sections a depth, each radius from the textbook formula with a little measurement noise.
std::vector<BlurSample> TakeSamples(double focus_mm, double floor_px, uint64_t seed = 3) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::vector<BlurSample> out;
  for (int k = 0; k <= 14; ++k)
    for (int s = 0; s < 7; ++s) {
      const double u = 360.0 + 20.0 * k;
      const double r = TruthPx(focus_mm, u, kThesisLens.aperture_mm, floor_px, 23.4 / 1148);
      out.push_back({u, std::max(0.0, r + noise(rng)), 1.0});
    }
  return out;
}

// Focus inside the sampled depths with a floor: the blur falls to the floor at focus and grows both ways. The
// search over focus warm-starts each candidate from its neighbour; an aperture driven to 0 far from focus (a flat
// floor fits there best) once stayed 0 all along the search, because the floor model's slope in D vanishes at D = 0,
// so the floor model never reached focus and the thin lens alone was kept (focus 178 mm, aperture 0.50 mm for a
// 0.7 px floor).
TEST(FitThinLens, FloorModelFindsFocusInsideTheSampledDepths) {
  const Lens take{21.0, 21.0 / 5.6, 23.4 / 1148};
  for (double floor_px : {0.35, 0.7, 1.0}) {
    const FittedModel m = FitThinLens(take, TakeSamples(450.0, floor_px));
    EXPECT_EQ(m.kind, "thin_lens+floor") << "floor " << floor_px;
    EXPECT_NEAR(m.focus_mm, 450.0, 0.01 * 450.0) << "floor " << floor_px;
    EXPECT_NEAR(m.aperture_mm, 3.75, 0.02 * 3.75) << "floor " << floor_px;
    EXPECT_NEAR(m.floor_px, floor_px, 0.03) << "floor " << floor_px;
    EXPECT_LT(m.rms_px, 0.015) << "floor " << floor_px;
  }
}

// Focus in front of, inside and behind the sampled depths, with and without a floor: the fitted radius at every
// sampled depth within 2 % of the textbook one (issue 25's median target, held here at every depth), or within
// 0.01 px (the samples' noise) where the textbook radius is near 0 (focus without a floor).
TEST(FitThinLens, FittedRadiusWithinTwoPercentOnEitherSideOfFocus) {
  const Lens take{21.0, 21.0 / 5.6, 23.4 / 1148};
  for (double focus_mm : {300.0, 450.0, 520.0, 700.0, 1000.0})
    for (double floor_px : {0.0, 0.7}) {
      const FittedModel m = FitThinLens(take, TakeSamples(focus_mm, floor_px));
      for (double u = 360.0; u <= 640.0; u += 20.0) {
        const double truth = TruthPx(focus_mm, u, take.aperture_mm, floor_px, take.pixel_pitch_mm);
        EXPECT_NEAR(m.PredictPx(take, u), truth, std::max(0.02 * truth, 0.01))
            << "focus " << focus_mm << " floor " << floor_px << " u " << u << ": " << m.kind << " focus "
            << m.focus_mm << " aperture " << m.aperture_mm << " floor " << m.floor_px;
      }
      // Off the board, at the true focus, the blur is the floor alone: a thin lens kept where the floor buys only
      // a few thousandths of a px on the board (the choice's absolute margin was 0.01 px) put its focus elsewhere
      // and drew 0.24 px there for focus 1000 mm, 0.7 px floor. Within 10 %: where every sample is blurred well
      // beyond the floor, the floor is the fit's least determined part (0.66 px for focus 300 mm).
      if (floor_px > 0) {
        EXPECT_NEAR(m.PredictPx(take, focus_mm), floor_px, 0.1 * floor_px)
            << "focus " << focus_mm << ": " << m.kind << " focus " << m.focus_mm << " floor " << m.floor_px;
      }
    }
}

TEST(FittedModel, PredictPxAddsFloorInQuadrature) {
  FittedModel m;
  m.focus_mm = 430.0;
  m.aperture_mm = 3.75;
  m.floor_px = 2.0;
  for (double u : {342.3, 430.0, 527.3})
    EXPECT_NEAR(m.PredictPx(kThesisLens, u), TruthPx(430.0, u, 3.75, 2.0), 1e-9) << "u = " << u;
}

}  // namespace
}  // namespace blurcue::optics
