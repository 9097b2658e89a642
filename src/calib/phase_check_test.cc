// Identifiability per section (phase_check.h) against truth computed here: a level edge drawn in closed form (a
// Gaussian blur over the pixel's box) and filtered after sampling by taps written out in the test, and a filtered
// ground-truth scene (synth's truth: its kernels' and the post filter's taps' second moments).
#include "calib/phase_check.h"
#include "calib/phase_fit.h"
#include "calib/phase_flags.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include "calib/calibrate.h"
#include "synth/scene.h"

namespace blurcue::calib {
namespace {

double Phi(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }
// Integral of Phi(t / s) dt: the Gaussian ESF's antiderivative.
double IntPhi(double t, double s) {
  return t * Phi(t / s) + s * std::exp(-0.5 * t * t / (s * s)) / std::sqrt(2 * M_PI);
}

struct Drawn {
  cv::Mat linear;
  double true_r_px = 0;
};

// A dark-to-bright edge along the rows at y = edge_y (slope: its rise per column), a Gaussian optical blur of std
// sigma_px averaged over each pixel's box, then a Gaussian of std post_px at whole pixels down the columns.
Drawn DrawEdge(double edge_y, double slope, double sigma_px, double post_px) {
  cv::Mat sampled(60, 200, CV_32F);
  for (int y = 0; y < sampled.rows; ++y)
    for (int x = 0; x < sampled.cols; ++x) {
      const double d = y - (edge_y + slope * (x - 100));
      const double esf = IntPhi(d + 0.5, sigma_px) - IntPhi(d - 0.5, sigma_px);
      sampled.at<float>(y, x) = static_cast<float>(0.05 + 0.75 * esf);
    }
  std::vector<double> taps;
  double sum = 0, second = 0;
  for (int k = -3; k <= 3; ++k) taps.push_back(std::exp(-0.5 * k * k / (post_px * post_px))), sum += taps.back();
  for (int k = -3; k <= 3; ++k) taps[k + 3] /= sum, second += k * k * taps[k + 3];
  Drawn out;
  out.linear = cv::Mat::zeros(sampled.size(), CV_32F);
  for (int y = 3; y < sampled.rows - 3; ++y)
    for (int x = 0; x < sampled.cols; ++x)
      for (int k = -3; k <= 3; ++k) out.linear.at<float>(y, x) += float(taps[k + 3]) * sampled.at<float>(y - k, x);
  out.true_r_px = 2 * std::sqrt(sigma_px * sigma_px + second);
  return out;
}

size_t FamilyIndex(double sigma_px, double sharpen) {
  const auto& f = PhaseFamilies();
  for (size_t i = 0; i < f.size(); ++i)
    if (std::abs(f[i].sigma_px - sigma_px) < 1e-9 && std::abs(f[i].sharpen - sharpen) < 1e-9) return i;
  return f.size();
}

TEST(PhaseCheck, LevelEdgeFilteredAfterSamplingReadsTrueUnderItsFamilyAndNotUnderTheOptics) {
  // Halfway between rows, where the optics-alone model reads sub-pixel blur about half its size.
  const Drawn d = DrawEdge(30.5, 0, 0.2, 0.45);
  const EdgeSegment segment{{40, 30.5}, {160, 30.5}, 12};
  const ModelFit fit = MeasureEdgeModel(d.linear, segment);
  ASSERT_TRUE(fit.ok);
  const PhaseCheck check = CheckPhase(d.linear, segment, fit);
  ASSERT_TRUE(check.limited);
  EXPECT_NEAR(check.span_px, 0, 1e-9);
  EXPECT_NEAR(check.phase_px, 0.5, 1e-9);
  const size_t right = FamilyIndex(0.45, 0);
  ASSERT_LT(right, check.families.size());
  EXPECT_NEAR(check.families[right].r_px, d.true_r_px, 0.03 * d.true_r_px);
  EXPECT_GT(std::abs(check.families[0].r_px - d.true_r_px), 0.15 * d.true_r_px)
      << "optics alone " << check.families[0].r_px;
  for (size_t c = 0; c < check.families.size(); ++c)
    EXPECT_LE(check.families[right].chi2, check.families[c].chi2) << PhaseFamilies()[c].Name();
}

TEST(PhaseCheck, EdgeCrossingThePixelRowsIsSampledAtEveryPhase) {
  // 1.5 deg: its phase moves 1.6 px along the 60 px measured.
  const double slope = std::tan(1.5 * M_PI / 180);
  const Drawn d = DrawEdge(30.3, slope, 0.4, 0.45);
  const EdgeSegment segment{{40, 30.3 - 60 * slope}, {160, 30.3 + 60 * slope}, 12};
  const ModelFit fit = MeasureEdgeModel(d.linear, segment);
  const PhaseCheck check = CheckPhase(d.linear, segment, fit);
  EXPECT_FALSE(check.limited);
  EXPECT_NEAR(check.axis_deg, 1.5, 1e-6);
  EXPECT_GT(check.span_px, 1);
  EXPECT_TRUE(check.families.empty());
}

// Sections made by hand: the families' chi-squares choose one; a section whose alike families' readings differ is
// flagged with its reason and left unusable, one whose readings agree keeps the chosen family's reading.
TEST(PhaseCheck, SectionTheAlikeFamiliesLeaveOpenIsFlaggedAndTheOthersReadWithTheChosenFamily) {
  const size_t n = PhaseFamilies().size(), a = FamilyIndex(0.4, 0), b = FamilyIndex(0.45, 0);
  CalibResult result;
  result.edges.resize(2);
  for (int e = 0; e < 2; ++e) {
    SectionResult s;
    s.edge = e + 1, s.section = 1, s.u_mm = 400;
    s.fit.ok = true, s.fit.r_px = 0.7;
    s.phase.limited = true, s.phase.bins = 20;
    s.phase.families.assign(n, PhaseReading{});
    for (size_t c = 0; c < n; ++c) s.phase.families[c] = {1.5, 0, 0.01, 1e4};
    s.phase.families[a] = {e == 0 ? 0.80 : 0.86, 0, 0.001, 20};  // alike with b (within 25 x the best's per point)
    s.phase.families[b] = {0.87, 0, 0.001, 18};
    result.edges[e].sections.push_back(s);
  }
  const PhaseChoice choice = ChoosePhaseFamily(result);
  EXPECT_EQ(choice.chosen, b);
  EXPECT_TRUE(choice.alike[a]);
  EXPECT_EQ(choice.limited, 2);
  EXPECT_EQ(choice.flagged, 1);
  const ModelFit& open = result.edges[0].sections[0].fit;
  EXPECT_FALSE(open.ok);
  EXPECT_EQ(open.flags, std::vector<std::string>{"phase_limited"});
  EXPECT_NE(open.phase_why.find("0.80-0.87 px"), std::string::npos) << open.phase_why;
  const ModelFit& agreed = result.edges[1].sections[0].fit;
  EXPECT_TRUE(agreed.ok);
  EXPECT_DOUBLE_EQ(agreed.r_px, 0.87);
  EXPECT_EQ(SectionsLeftOut(result), (std::map<std::string, int>{{"phase_limited", 1}}));
}

// Neighbours along each family's own axis, as the families are listed (std for the Gaussians, amount for the unsharp
// masks of one std; the optics alone is the zero of every axis).
TEST(PhaseCheck, NeighboursAreTheNextStdOrAmountOnEitherSide) {
  auto set = [](std::vector<size_t> v) {
    std::sort(v.begin(), v.end());
    return v;
  };
  EXPECT_EQ(set(PhaseNeighbours(FamilyIndex(0.45, 0))), set({FamilyIndex(0.4, 0), FamilyIndex(0.5, 0)}));
  EXPECT_EQ(set(PhaseNeighbours(FamilyIndex(0.35, 0))), set({0, FamilyIndex(0.4, 0)}));
  EXPECT_EQ(set(PhaseNeighbours(FamilyIndex(0.6, 0.5))), set({FamilyIndex(0.6, 0.3), FamilyIndex(0.6, 0.7)}));
  EXPECT_EQ(set(PhaseNeighbours(FamilyIndex(1.0, 0.15))), set({0, FamilyIndex(1.0, 0.3)}));
  EXPECT_EQ(set(PhaseNeighbours(FamilyIndex(0.8, 0))), set({FamilyIndex(0.7, 0)}));
  EXPECT_EQ(set(PhaseNeighbours(0)), set({FamilyIndex(0.35, 0), FamilyIndex(0.6, 0.15), FamilyIndex(0.8, 0.15),
                                          FamilyIndex(1.0, 0.15)}));
}

// The refinement between the families finds a bowl's floor that lies off the grid (an unsharp mask of amount 0.25,
// std 0.9 px, between the families' 0.8 and 1.0 px), staying a mask; a Gaussian is refined along its std alone.
TEST(PhaseFit, RefinesBetweenTheFamiliesToTheLeastChiSquare) {
  int calls = 0;
  auto bowl = [&](const PhaseFamily& f) {
    ++calls;
    return 100 + 4000 * (f.sigma_px - 0.9) * (f.sigma_px - 0.9) + 9000 * (f.sharpen - 0.25) * (f.sharpen - 0.25);
  };
  const PhaseFamily mask = RefinePhaseFamily({0.8, 0.3}, bowl, 40);
  EXPECT_TRUE(mask.fitted);
  EXPECT_NEAR(mask.sigma_px, 0.9, 0.02);
  EXPECT_NEAR(mask.sharpen, 0.25, 0.02);
  EXPECT_LE(calls, 40);
  auto gauss_bowl = [](const PhaseFamily& f) { return 50 + 3000 * (f.sigma_px - 0.38) * (f.sigma_px - 0.38) + f.sharpen; };
  const PhaseFamily gauss = RefinePhaseFamily({0.35, 0}, gauss_bowl, 20);
  EXPECT_NEAR(gauss.sigma_px, 0.38, 0.01);
  EXPECT_EQ(gauss.sharpen, 0.0);
  // The optics alone has nothing to refine.
  EXPECT_FALSE(RefinePhaseFamily({0, 0}, bowl).fitted);
}

// The profiles pin a mask's second moment (amount x its Gaussian's taps' variance) far more than its std: a narrow
// valley along that product, curved in (std, amount). From the grid's 0.7 at 0.6 px (on the valley's floor, its
// variance 0.7 x 0.332) to the true 0.25 at 0.9 px (0.25 x 0.81 = 0.203) the search in (std, amount) stayed at its
// start (calibrate on undetermined_coverage.py's mask 0.25/0.9 seed 12: chi-square per point 3.5, edges 4-7 7-12 %
// high); along the valley it finds the floor.
TEST(PhaseFit, FollowsTheValleyOfOneSecondMoment) {
  auto variance = [](const PhaseFamily& f) {
    double sum = 0, second = 0;  // the Gaussian at whole pixels out to 4 std, written out here
    const int reach = std::max(1, int(std::ceil(4 * f.sigma_px)));
    for (int k = -reach; k <= reach; ++k) {
      const double g = std::exp(-0.5 * (k / f.sigma_px) * (k / f.sigma_px));
      sum += g, second += k * k * g;
    }
    return f.sharpen * second / sum;
  };
  const double target = variance({0.9, 0.25});
  auto valley = [&](const PhaseFamily& f) {
    const double dv = variance(f) - target;
    return 100 + 2e6 * dv * dv + 300 * (f.sigma_px - 0.9) * (f.sigma_px - 0.9);
  };
  const PhaseFamily mask = RefinePhaseFamily({0.6, 0.7}, valley, 30);
  EXPECT_NEAR(mask.sigma_px, 0.9, 0.05);
  EXPECT_NEAR(mask.sharpen, 0.25, 0.03);

  // The valley's ends that fit alike (within 10 of the found one's 100 here: 300 x d^2 > 10 past d = 0.183 px, the
  // first 0.02 px step beyond at 0.20 px), each with the found mask's second moment, a Gaussian none.
  const std::array<PhaseFamily, 2> ends = ValleyEnds({0.9, 0.25}, valley, 10);
  EXPECT_NEAR(ends[0].sigma_px, 0.70, 1e-9);
  EXPECT_NEAR(ends[1].sigma_px, 1.10, 1e-9);
  for (const PhaseFamily& end : ends) EXPECT_NEAR(variance(end), target, 1e-9 * target);
  const std::array<PhaseFamily, 2> none = ValleyEnds({0.45, 0}, valley, 10);
  EXPECT_EQ(none[0].sigma_px, 0.45);
  EXPECT_EQ(none[1].sigma_px, 0.45);
}

// Sections made by hand, read best by an unsharp mask of amount 0.5 (std 0.6 px). Its taps' second moment, written
// out here: -0.5 x the Gaussian's at whole pixels. Where the mask cancels most of the optics' blur (read 0.30 px from
// optics of sqrt(0.30^2 - 4 V) px) a 2 % error in the optics' reading moves the section's by more than 0.04 px: flagged,
// with the optics' radius in the reason; at 0.90 px it moves it by less than 8 %: kept. A third section whose reading
// lies 0.15 px below both neighbouring amounts' readings is flagged for that.
TEST(PhaseCheck, SectionWhereTheChosenSharpeningCancelsMostOfTheBlurOrJumpsIsFlagged) {
  const size_t n = PhaseFamilies().size(), chosen = FamilyIndex(0.6, 0.5);
  double sum = 0, second = 0;
  for (int k = -3; k <= 3; ++k) sum += std::exp(-0.5 * k * k / 0.36), second += k * k * std::exp(-0.5 * k * k / 0.36);
  const double v = -0.5 * second / sum;  // the unsharp mask's taps' variance (px^2)
  CalibResult result;
  const double reading[3] = {0.30, 0.90, 0.75}, neighbour[3] = {0.30, 0.90, 0.92};
  result.edges.resize(3);
  for (int e = 0; e < 3; ++e) {
    SectionResult s;
    s.edge = e + 1, s.section = 1, s.u_mm = 400;
    s.fit.ok = true, s.fit.r_px = 1.0;
    s.phase.limited = true, s.phase.bins = 20;
    s.phase.families.assign(n, PhaseReading{});
    for (size_t c = 0; c < n; ++c) s.phase.families[c] = {1.5, 0, 0.01, 1e4};
    for (const size_t c : PhaseNeighbours(chosen)) s.phase.families[c] = {neighbour[e], 0, 0.01, 1e4};
    s.phase.families[chosen] = {reading[e], 0, 0.001, 18};
    result.edges[e].sections.push_back(s);
  }
  const PhaseChoice choice = ChoosePhaseFamily(result);
  EXPECT_EQ(choice.chosen, chosen);
  EXPECT_EQ(choice.flagged, 2);
  const ModelFit& cancelled = result.edges[0].sections[0].fit;
  EXPECT_FALSE(cancelled.ok);
  char optics[40];
  std::snprintf(optics, sizeof optics, "optics %.2f px, read 0.30 px", std::sqrt(0.09 - 4 * v));
  EXPECT_NE(cancelled.phase_why.find(optics), std::string::npos) << cancelled.phase_why << " / " << optics;
  EXPECT_TRUE(result.edges[1].sections[0].fit.ok);
  EXPECT_DOUBLE_EQ(result.edges[1].sections[0].fit.r_px, 0.90);
  const ModelFit& jumped = result.edges[2].sections[0].fit;
  EXPECT_FALSE(jumped.ok);
  EXPECT_NE(jumped.phase_why.find("lies 0.17 px outside"), std::string::npos) << jumped.phase_why;
  EXPECT_NE(choice.summary.find("2 flagged phase_limited (0 where the kinds that fit alike read apart, 0 where masks along "
                                "the chosen one's valley (one second moment, fitting alike) read apart, 1 where the "
                                "sharpening cancels"),
            std::string::npos)
      << choice.summary;
}

// The chosen mask's valley ends (masks of its second moment that fit alike) read a section at few phases 0.72 and
// 0.88 px about its 0.80 px: 0.16 px apart, over max(0.04 px, 8 % of 0.80); flagged, and it joins the lens fit at its
// reading. One whose ends read 0.88-0.93 px about 0.90 is not (0.05 under 0.072), nor one at every phase whose ends
// read 0.70-0.95 px (its own profile pins the optics' shape).
TEST(PhaseCheck, SectionTheMaskValleyReadsApartIsFlaggedAndJoinsTheFit) {
  const size_t n = PhaseFamilies().size(), chosen = FamilyIndex(0.6, 0.5);
  CalibResult result;
  result.phase.has_valley = true;
  result.phase.valley[0] = {0.56, 0.55, true}, result.phase.valley[1] = {0.64, 0.45, true};
  const double reading[3] = {0.80, 0.90, 0.85}, ends[3][2] = {{0.72, 0.88}, {0.88, 0.93}, {0.70, 0.95}};
  result.edges.resize(3);
  for (int e = 0; e < 3; ++e) {
    SectionResult s;
    s.edge = e + 1, s.section = 1, s.u_mm = 400;
    s.fit.ok = true, s.fit.r_px = 1.0;
    s.phase.limited = e < 2, s.phase.every_phase = e == 2, s.phase.bins = 20;
    s.phase.families.assign(n, PhaseReading{});
    for (size_t c = 0; c < n; ++c) s.phase.families[c] = {1.5, 0, 0.01, 1e4};
    for (const size_t c : PhaseNeighbours(chosen)) s.phase.families[c] = {reading[e], 0, 0.01, 1e4};
    s.phase.families[chosen] = {reading[e], 0, 0.001, 18};
    s.phase.valley_r_px[0] = ends[e][0], s.phase.valley_r_px[1] = ends[e][1];
    result.edges[e].sections.push_back(s);
  }
  const PhaseChoice choice = ChoosePhaseFamily(result);
  EXPECT_EQ(choice.chosen, chosen);
  EXPECT_EQ(choice.flagged, 1);
  const SectionResult& apart = result.edges[0].sections[0];
  EXPECT_FALSE(apart.fit.ok);
  EXPECT_TRUE(apart.phase.joins_fit);
  EXPECT_NE(apart.fit.phase_why.find("read 0.72-0.88 px here"), std::string::npos) << apart.fit.phase_why;
  EXPECT_DOUBLE_EQ(apart.phase.range_lo_px, 0.72);
  EXPECT_DOUBLE_EQ(apart.phase.range_hi_px, 0.88);
  EXPECT_TRUE(result.edges[1].sections[0].fit.ok);
  EXPECT_TRUE(result.edges[2].sections[0].fit.ok);
  EXPECT_NE(choice.summary.find("1 where masks along the chosen one's valley"), std::string::npos) << choice.summary;
}

// After the lens fit, a measured section on the board's outer edge whose reading lies off the fit's prediction by more
// than max(0.04 px, 8 %) less the prediction's standard error is flagged and joins the fit at its reading (worked
// by hand: 0.70 against 0.62 +- 0.01 is 0.08 off, over 0.056 - 0.01; 0.66 is 0.04 off, under it; an inner edge's
// and the optics alone's are never flagged).
TEST(PhaseCheck, OuterEdgeSectionOffTheLensFitIsFlaggedAfterIt) {
  auto section = [](int edge, double r, double fitted) {
    SectionResult s;
    s.edge = edge, s.section = 1, s.u_mm = 400;
    s.fit.ok = true, s.fit.r_px = r;
    s.r_fitted_px = fitted, s.r_fitted_se_px = 0.01;
    return s;
  };
  CalibResult result;
  result.edges.resize(3);
  result.edges[0].sections = {section(1, 0.70, 0.62), section(1, 0.66, 0.62)};
  result.edges[1].sections = {section(2, 0.80, 0.62)};  // inner: the table is not beside it
  result.edges[2].sections = {section(3, 0.50, 0.62)};  // 0.12 off: flagged
  EXPECT_EQ(FlagOffTheLensFit(result), 0);              // the optics alone chosen: nothing after the fit
  result.phase.chosen = 1;
  EXPECT_EQ(FlagOffTheLensFit(result), 2);
  const SectionResult& off = result.edges[0].sections[0];
  EXPECT_FALSE(off.fit.ok);
  EXPECT_TRUE(off.phase.joins_fit);
  EXPECT_DOUBLE_EQ(off.phase.range_lo_px, 0.62);
  EXPECT_DOUBLE_EQ(off.phase.range_hi_px, 0.70);
  EXPECT_NE(off.fit.phase_why.find("its reading (0.70 px) lies 0.08 px off the lens fit's 0.62 px"), std::string::npos)
      << off.fit.phase_why;
  EXPECT_TRUE(result.edges[0].sections[1].fit.ok);
  EXPECT_TRUE(result.edges[1].sections[0].fit.ok);
  EXPECT_FALSE(result.edges[2].sections[0].fit.ok);
}

// The scene: a level camera, the image filtered after sampling. The check finds the filter and every section
// reads within max(0.05 px, 10 %) of synth's truth or is flagged; without it, the edges halfway between rows do not.
TEST(PhaseCheck, FilteredSceneReadsTrueOrFlaggedWhereTheUncheckedReadingIsOff) {
  synth::SceneOptions o;
  o.focus_mm = 430;
  o.floor_sigma_px = 0.2;
  o.noise_std = 0.0025;
  o.seed = 3;
  o.post_filter = {synth::PostFilter::kGaussian, 0.45, 0};
  const synth::Scene scene = synth::RenderScene(o);
  auto off = [&](const CalibResult& r) {
    int n = 0;
    for (const auto& e : r.edges)
      for (const auto& s : e.sections) {
        const double truth = scene.sections[(e.index - 1) * 7 + (s.section - 1)].r_px;
        n += s.fit.ok && std::abs(s.fit.r_px - truth) > std::max(0.05, 0.1 * truth);
      }
    return n;
  };
  const CalibResult checked = Calibrate(scene.image, scene.camera, scene.board);
  EXPECT_EQ(PhaseFamilies()[checked.phase.chosen].sigma_px, 0.45);
  EXPECT_EQ(off(checked), 0);
  CalibrateOptions unchecked;
  unchecked.phase_check = false;
  EXPECT_GE(off(Calibrate(scene.image, scene.camera, scene.board, unchecked)), 5);
}


// A short section of an edge 37 deg off the pixel rows (every phase): its 18 px measured put about 1.8 pixels in each
// 0.1 px bin across it. Held to 3 samples a bin, as a level edge's, the profile kept a handful of bins (fewer than 6:
// not read per family at all; a board turned 60 deg read such a section 0.61 px for 0.13 px, unflagged).
TEST(PhaseCheck, ShortSectionAtEveryPhaseKeepsItsWholeProfile) {
  const double sigma_px = 0.35, angle = 37 * M_PI / 180;  // a Gaussian's r is 2 sigma
  const cv::Point2d c(40.3, 40.1), t(std::cos(angle), std::sin(angle)), n(-t.y, t.x);
  cv::Mat linear(80, 80, CV_32F);
  for (int y = 0; y < linear.rows; ++y)
    for (int x = 0; x < linear.cols; ++x) {
      double sum = 0;  // the Gaussian ESF averaged over the pixel's box (8 x 8 points)
      for (int i = 0; i < 8; ++i)
        for (int j = 0; j < 8; ++j)
          sum += Phi(n.dot(cv::Point2d(x + (i + 0.5) / 8 - 0.5, y + (j + 0.5) / 8 - 0.5) - c) / sigma_px);
      linear.at<float>(y, x) = static_cast<float>(0.05 + 0.75 * sum / 64);
    }
  CalibResult result;
  result.edges.resize(1);
  SectionResult s;
  s.segment = EdgeSegment{c - 18 * t, c + 18 * t, 10};
  s.fit = MeasureEdgeModel(linear, s.segment);
  ASSERT_TRUE(s.fit.ok);
  result.edges[0].sections.push_back(s);
  ReadPhaseFamilies(result, linear, {}, false);
  const PhaseCheck& check = result.edges[0].sections[0].phase;
  ASSERT_TRUE(check.every_phase) << "bins " << check.bins;
  EXPECT_GT(check.bins, 100);  // +-(2 r + 6) px at 0.1 px: 148
  ASSERT_FALSE(check.families.empty());
  EXPECT_NEAR(check.families[0].r_px, 2 * sigma_px, 0.03 * 2 * sigma_px);
}

}  // namespace
}  // namespace blurcue::calib
