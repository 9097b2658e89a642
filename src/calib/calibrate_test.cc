// The calibration pipeline against ground-truth scenes: a board on a table rendered through a thin lens with
// known pose and known blur (src/synth), calibrated as a photo would be.
#include "calib/calibrate.h"

#include <algorithm>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <map>
#include <string>
#include <cstdio>

#include <opencv2/core/utility.hpp>
#include <opencv2/calib3d.hpp>

#include "calib/calib_test_util.h"
#include "calib/scene_blur.h"
#include "calib/truth.h"
#include "core/error.h"
#include "optics/fit.h"
#include "synth/scene.h"

namespace blurcue::calib {
namespace {



const synth::Scene& Rendered(const synth::SceneOptions& o) { return Calibrated(o).scene; }

void PrintSideBySide(const Calibration& r) {
  std::printf("edge  true   model  thesis  eq3.7  fitted\n");
  for (size_t e = 0; e < r.result.edges.size(); ++e) {
    const EdgeResult& edge = r.result.edges[e];
    std::printf("%4d %6.2f %6.2f %6.2f %6.2f %6.2f\n", edge.index, r.cmp.true_r_per_edge[e], edge.r_px,
                edge.r_thesis_px, edge.r_estimated_px, edge.r_fitted_px);
  }
}

TEST(Calibrate, PoseWithinOneMillimetreAndHalfDegree) {
  const Calibration& r = Calibrated(Thesis());
  EXPECT_LT(r.cmp.translation_error_mm, 1.0);
  EXPECT_LT(r.cmp.rotation_error_deg, 0.5);
  EXPECT_LT(r.cmp.max_depth_error_mm, 1.0);
  EXPECT_LT(r.result.pose.reprojection_error_px, 0.5);
}

// The sections measured on every core must give the numbers measured one after another, bit for bit: two orders of
// the same computation, on rendered photos with noise (sharp and blurred edges, a distorted lens: bowed sections).
// A live view's subset (only_sections): those sections read what the whole measurement reads for them, the others
// are left unmeasured (not usable, no flags), and no reference edge is asked for.
TEST(Calibrate, OnlySectionsMeasuresThoseAloneAsTheWholeMeasurementDoes) {
  const synth::Scene& scene = Rendered(Thesis());
  CalibrateOptions whole, subset;
  whole.fit_model = subset.fit_model = false;
  subset.only_sections = {7 * 4 + 2, 7 * 9 + 6, 3};  // edge 5 section 3, edge 10 section 7, edge 1 section 4
  const CalibResult a = Calibrate(scene.image, scene.camera, scene.board, whole);
  const CalibResult b = Calibrate(scene.image, scene.camera, scene.board, subset);
  int measured = 0;
  for (size_t e = 0; e < a.edges.size(); ++e)
    for (size_t k = 0; k < a.edges[e].sections.size(); ++k) {
      const SectionResult &x = a.edges[e].sections[k], &y = b.edges[e].sections[k];
      const int flat = int(e * 7 + k);
      const bool asked = flat == 7 * 4 + 2 || flat == 7 * 9 + 6 || flat == 3;
      SCOPED_TRACE("edge " + std::to_string(x.edge) + " section " + std::to_string(x.section));
      if (asked) {
        ++measured;
        EXPECT_TRUE(x.fit.ok);
        EXPECT_EQ(y.fit.ok, x.fit.ok);
        EXPECT_EQ(y.fit.r_px, x.fit.r_px);
        EXPECT_EQ(y.thesis.r_px, x.thesis.r_px);
      } else {
        EXPECT_FALSE(y.fit.ok);
        EXPECT_TRUE(y.fit.flags.empty());
      }
      EXPECT_EQ(y.u_mm, x.u_mm);  // every section's geometry is the pose's either way
    }
  EXPECT_EQ(measured, 3);
}

TEST(Calibrate, ParallelSectionsGiveTheSerialNumbers) {
  std::printf("OpenCV threads: %d\n", cv::getNumThreads());
  synth::SceneOptions distorted = Thesis();
  distorted.camera.dist_coeffs = {-0.12, 0, 0, 0, 0};
  for (const synth::SceneOptions& o : {Thesis(), Blurry(), distorted}) {
    const synth::Scene& scene = Rendered(o);
    CalibrateOptions serial, parallel;
    serial.parallel_sections = false;
    parallel.parallel_sections = true;
    const CalibResult a = Calibrate(scene.image, scene.camera, scene.board, serial);
    const CalibResult b = Calibrate(scene.image, scene.camera, scene.board, parallel);
    ASSERT_EQ(a.edges.size(), b.edges.size());
    int usable = 0;
    for (size_t e = 0; e < a.edges.size(); ++e)
      for (size_t k = 0; k < a.edges[e].sections.size(); ++k) {
        const SectionResult &x = a.edges[e].sections[k], &y = b.edges[e].sections[k];
        SCOPED_TRACE("edge " + std::to_string(x.edge) + " section " + std::to_string(x.section));
        EXPECT_EQ(x.fit.ok, y.fit.ok);
        EXPECT_EQ(x.fit.flags, y.fit.flags);
        EXPECT_EQ(x.fit.r_px, y.fit.r_px);
        EXPECT_EQ(x.fit.disc_r_px, y.fit.disc_r_px);
        EXPECT_EQ(x.fit.floor_sigma_px, y.fit.floor_sigma_px);
        EXPECT_EQ(x.fit.offset_px, y.fit.offset_px);
        EXPECT_EQ(x.fit.step, y.fit.step);
        EXPECT_EQ(x.fit.rms_rel, y.fit.rms_rel);
        EXPECT_EQ(x.fit.samples, y.fit.samples);
        EXPECT_EQ(x.thesis.r_px, y.thesis.r_px);
        EXPECT_EQ(x.r_fitted_px, y.r_fitted_px);
        usable += x.fit.ok;
      }
    EXPECT_GT(usable, 60);  // the comparison covers real fits, not 77 flagged sections
    EXPECT_EQ(a.model.focus_mm, b.model.focus_mm);
    EXPECT_EQ(a.model.aperture_mm, b.model.aperture_mm);
    EXPECT_EQ(a.reference_r_px, b.reference_r_px);
  }
}

TEST(Calibrate, ElevenEdgesOfSevenSectionsNearestFirst) {
  const Calibration& r = Calibrated(Thesis());
  ASSERT_EQ(r.result.edges.size(), 11u);
  for (size_t e = 0; e < 11; ++e) {
    EXPECT_EQ(r.result.edges[e].sections.size(), 7u);
    if (e > 0) {
      EXPECT_GT(r.result.edges[e].u_mm, r.result.edges[e - 1].u_mm);
    }
  }
  // Focus is on edge 1 (the thesis set-up), so edge 1 is nearly sharp and blur grows with depth.
  EXPECT_NEAR(r.result.edges[0].u_mm, 342.3, 1.0);
  EXPECT_GT(r.result.edges[10].r_px, r.result.edges[5].r_px);
  EXPECT_GT(r.result.edges[5].r_px, r.result.edges[0].r_px);
}

TEST(Calibrate, ModelFitWithinToleranceOfTrueBlur) {
  const Calibration& r = Calibrated(Blurry());
  PrintSideBySide(r);
  int ok = 0, within = 0;
  for (const auto& s : r.cmp.sections) {
    if (!s.model.answered) continue;
    ++ok;
    within += std::abs(s.model.error_px) <= MeasureTolerancePx(s.true_r_px);
  }
  EXPECT_GE(ok, 0.8 * r.cmp.sections.size());
  EXPECT_GE(within, 0.9 * ok) << within << " of " << ok << " usable sections within max(0.25 px, 5 %)";
}

TEST(Calibrate, FittedModelPredictsHeldOutEdges) {
  const Calibration& r = Calibrated(Blurry());
  const optics::Lens lens = optics::Lens::FromCamera(r.scene.camera);
  std::vector<optics::BlurSample> train;
  for (const auto& edge : r.result.edges)
    for (const auto& s : edge.sections)
      if (edge.index <= 7 && s.fit.ok) train.push_back({s.u_mm, s.fit.r_px, 1.0});
  const optics::FittedModel model = optics::FitThinLens(lens, train);
  for (int e = 8; e <= 11; ++e) {
    const EdgeResult& edge = r.result.edges[e - 1];
    const double truth = r.cmp.true_r_per_edge[e - 1];
    EXPECT_NEAR(model.PredictPx(lens, edge.u_mm), truth, 0.05 * truth) << "edge " << e;
  }
}

TEST(Calibrate, Eq37FromTheReferenceEdgeFollowsTheThinLens) {
  // Truth is a thin lens, so eq. 3.7 from a well-measured reference must land near the truth too.
  const Calibration& r = Calibrated(Blurry());
  const TruthComparison& c = r.cmp;
  for (int e = 2; e <= 11; ++e)
    EXPECT_NEAR(r.result.edges[e - 1].r_estimated_px, c.true_r_per_edge[e - 1], 0.1 * c.true_r_per_edge[e - 1] + 0.1)
        << "edge " << e;
}

// Optics as real lenses make them (issue 25, "Must hold"): a defocus disc or Gaussian convolved with a lens floor,
// vignetting, JPEG, sensor noise; focus off the board, on edge 1, and mid-board (both sides of focus, in-focus
// sections included). Truth is the applied kernels' second moment (synth). Measured and fitted r_px: median
// relative error <= 2 %, p90 <= 5 % over every section the measurement answers, and it answers >= 90 % of them.
struct RealOptics {
  const char* name;
  synth::SceneOptions options;
};

std::vector<RealOptics> RealOpticsScenes() {
  std::vector<RealOptics> out;
  synth::SceneOptions a = Thesis(0.003);
  a.focus_mm = 260, a.floor_sigma_px = 0.6, a.vignetting = 0.35, a.jpeg_quality = 92;
  out.push_back({"disc x floor 0.6 px, focus off the board, vignetting 35 %, JPEG 92", a});
  synth::SceneOptions b = Thesis(0.002);
  b.psf = synth::Psf::kGaussian, b.focus_mm = 430, b.floor_sigma_px = 0.45;
  out.push_back({"Gaussian x floor 0.45 px, focus mid-board", b});
  synth::SceneOptions c = Thesis(0.003);
  c.floor_sigma_px = 0.35, c.vignetting = 0.2, c.jpeg_quality = 95;
  out.push_back({"disc x floor 0.35 px, focus on edge 1, vignetting 20 %, JPEG 95", c});
  return out;
}

struct RelErrors {
  double median = 0, p90 = 0;
  int n = 0;
};
RelErrors Relative(const TruthComparison& cmp, MethodError SectionComparison::*m) {
  std::vector<double> e;
  for (const auto& s : cmp.sections)
    if ((s.*m).answered) e.push_back(std::abs((s.*m).error_px) / s.true_r_px);
  RelErrors out;
  out.n = int(e.size());
  if (e.empty()) return out;
  std::sort(e.begin(), e.end());
  out.median = e[e.size() / 2];
  out.p90 = e[std::min(e.size() - 1, size_t(0.9 * e.size()))];
  return out;
}

TEST(Calibrate, RealOpticsMeasuredAndFittedWithinTwoPercentMedianFivePercentP90) {
  for (const RealOptics& scene : RealOpticsScenes()) {
    const Calibration& r = Calibrated(scene.options);
    const RelErrors measured = Relative(r.cmp, &SectionComparison::model);
    const RelErrors fitted = Relative(r.cmp, &SectionComparison::fitted);
    double r_min = 1e9;
    for (const auto& s : r.cmp.sections) r_min = std::min(r_min, s.true_r_px);
    std::printf("%s (true r from %.2f px; model %s, %s): measured %d/%zu, median %.2f %%, p90 %.2f %%; "
                "fitted median %.2f %%, p90 %.2f %%\n",
                scene.name, r_min, r.result.model.kind.c_str(), optics::FloorText(r.result.model).c_str(), measured.n,
                r.cmp.sections.size(), 100 * measured.median, 100 * measured.p90, 100 * fitted.median,
                100 * fitted.p90);
    EXPECT_GE(measured.n, 0.9 * r.cmp.sections.size()) << scene.name;
    EXPECT_LE(measured.median, 0.02) << scene.name;
    EXPECT_LE(measured.p90, 0.05) << scene.name;
    EXPECT_LE(fitted.median, 0.02) << scene.name;
    EXPECT_LE(fitted.p90, 0.05) << scene.name;
  }
}

// Focus inside the board (400 mm: edge 1 at 342 mm, edge 11 at 527 mm), so the blur falls to the lens floor
// (0.35 px std: r = 0.70 px) on edge 4 and grows both ways, with a disc and with a Gaussian defocus. Before the
// floor model's aperture stepped in D^2 (src/optics/fit.cc), both kept the thin lens alone at focus 225 mm,
// aperture 0.84 mm: r_fitted_px off by a median 17 %, p90 33 %. Against the truth the renderer applied (focus,
// aperture, per-section r).
TEST(Calibrate, FocusInsideTheBoardFitsFocusApertureAndRadius) {
  for (synth::Psf psf : {synth::Psf::kDisc, synth::Psf::kGaussian}) {
    synth::SceneOptions o = Thesis(0.003);
    o.psf = psf, o.focus_mm = 400, o.floor_sigma_px = 0.35, o.jpeg_quality = 95;
    const Calibration& r = Calibrated(o);
    const optics::FittedModel& m = r.result.model;
    const RelErrors fitted = Relative(r.cmp, &SectionComparison::fitted);
    const char* name = psf == synth::Psf::kDisc ? "disc x floor" : "Gaussian x floor";
    std::printf("%s, focus 400 mm: model %s focus %.1f mm aperture %.3f mm floor %.3f px; fitted r median %.2f %%, "
                "p90 %.2f %%\n", name, m.kind.c_str(), m.focus_mm, m.aperture_mm, m.floor_px, 100 * fitted.median,
                100 * fitted.p90);
    EXPECT_EQ(m.kind, "thin_lens+floor") << name;
    // Synth renders and the fit models blur through the same optics::BlurRadiusPx; that function is pinned apart from
    // both by ThinLens.MatchesTextbookBlurCircle and ThinLens.ThesisNumbers, so a shared error cannot cancel here.
    EXPECT_NEAR(m.focus_mm, r.scene.focus_mm, 0.02 * r.scene.focus_mm) << name;
    EXPECT_NEAR(m.aperture_mm, r.scene.camera.ApertureMm(), 0.03 * r.scene.camera.ApertureMm()) << name;
    // The floor as rendered: 2 x the std of the taps synth applied (truth's floor_sigma_applied_px), not the nominal
    // 2 x 0.35 px, which the taps match only while the supersampling is fine enough.
    const double floor_px = 2 * r.scene.truth.at("floor_sigma_applied_px").get<double>();
    EXPECT_NEAR(m.floor_px, floor_px, 0.07) << name;
    // The sections nearest focus read the floor itself: it is pinned, and its range holds the truth.
    EXPECT_TRUE(m.floor_determined) << name << ": " << optics::FloorText(m);
    EXPECT_LE(m.floor_lo_px, floor_px * 1.01) << name;
    EXPECT_GE(m.floor_hi_px, floor_px * 0.99) << name;
    EXPECT_EQ(fitted.n, int(r.cmp.sections.size())) << name;
    EXPECT_LE(fitted.median, 0.02) << name;
    EXPECT_LE(fitted.p90, 0.05) << name;
  }
}

// Issue 25 (b): with focus off the board (260 mm; every section 2-4.4 px, the disc dominating) the floor (0.6 px
// std: 2 x 0.6 = 1.2 px) changes the sections' radii almost as a slightly other focus and aperture would; the fit
// read 1.59 px. The floor is then said to be not determined, with the range of floors that fit alike, and the truth
// lies in it; the fitted radius stays right (the Must-hold test above).
TEST(Calibrate, FloorOffFocusIsNotDeterminedAndItsRangeHoldsTheTruth) {
  const Calibration& r = Calibrated(RealOpticsScenes()[0].options);
  const optics::FittedModel& m = r.result.model;
  std::printf("focus off the board: model %s, %s (truth 1.20 px)\n", m.kind.c_str(), optics::FloorText(m).c_str());
  EXPECT_FALSE(m.floor_determined);
  EXPECT_LE(m.floor_lo_px, 1.2);
  EXPECT_GE(m.floor_hi_px, 1.2);
  EXPECT_NE(optics::FloorText(m).find("not determined"), std::string::npos);
  const Json model = CalibToJson(r.result)["model"];
  EXPECT_FALSE(model["floor_determined"].get<bool>());
  EXPECT_EQ(model["choice"]["thin_lens+floor"]["floor_range_px"].size(), 2u);
}

// Issue 25 (a): a board turned about the table normal by 20, 30 and 45 degrees both ways puts its edges diagonal in
// the photo and its squares become parallelograms. The sampling window's ends follow the crossing board lines
// (edge_blur.h, EdgeSegment::cross_a/b); a rectangle's corners reached into the next square and read r 1-2 % high at
// 45 degrees (p90 3 %). Disc x floor 0.6 px, focus off the board (r 2.2-4.4 px), noise 0.003: measured and fitted
// r median <= 2 %, p90 <= 5 % over every section.
TEST(Calibrate, TurnedBoardMeasuredAndFittedWithinTwoPercentMedianFivePercentP90) {
  for (double yaw : {20.0, -20.0, 30.0, -30.0, 45.0, -45.0}) {
    synth::SceneOptions o = Thesis(0.003);
    o.focus_mm = 260, o.floor_sigma_px = 0.6, o.yaw_deg = yaw;
    const Calibration& r = Calibrated(o);
    const RelErrors measured = Relative(r.cmp, &SectionComparison::model);
    const RelErrors fitted = Relative(r.cmp, &SectionComparison::fitted);
    std::printf("yaw %+.0f deg: measured %d/%zu, median %.2f %%, p90 %.2f %%; fitted median %.2f %%, p90 %.2f %%\n",
                yaw, measured.n, r.cmp.sections.size(), 100 * measured.median, 100 * measured.p90,
                100 * fitted.median, 100 * fitted.p90);
    EXPECT_GE(measured.n, int(0.95 * r.cmp.sections.size())) << yaw;
    EXPECT_LE(measured.median, 0.02) << yaw;
    EXPECT_LE(measured.p90, 0.05) << yaw;
    EXPECT_LE(fitted.median, 0.02) << yaw;
    EXPECT_LE(fitted.p90, 0.05) << yaw;
  }
}

// Lens distortion in camera.json (issue 25 item 1): the photo's blur is the lens's times the map's stretch across
// each edge, so the measurement (in photo px) and the model (fitted in ideal px, predicted back with each section's
// stretch) must hold the same targets as without: median <= 2 %, p90 <= 5 %, focus off the board. Barrel k1 = -0.12
// with the issue's optics (floor 0.6 px, vignetting 35 %, JPEG 92) and pincushion k1 = +0.05 with a plain disc.
// The board is turned and shifted towards a corner: centred, as in the thesis, it sees stretches of 2 % at most;
// here up to 5 % (barrel) and 2 % (pincushion).
TEST(Calibrate, DistortedPhotoMeasuredAndFittedWithinTwoPercentMedianFivePercentP90) {
  synth::SceneOptions cornered = Thesis(0.003);
  cornered.focus_mm = 260, cornered.edge1_u_mm = 300, cornered.yaw_deg = 30, cornered.lateral_mm = 30;
  synth::SceneOptions barrel = cornered;
  barrel.floor_sigma_px = 0.6, barrel.vignetting = 0.35, barrel.jpeg_quality = 92;
  barrel.camera.dist_coeffs = {-0.12, 0, 0, 0, 0};
  synth::SceneOptions pincushion = cornered;
  pincushion.camera.dist_coeffs = {0.05, 0, 0, 0};
  for (const synth::SceneOptions& o : {barrel, pincushion}) {
    const Calibration& r = Calibrated(o);
    const RelErrors measured = Relative(r.cmp, &SectionComparison::model);
    const RelErrors fitted = Relative(r.cmp, &SectionComparison::fitted);
    // How far the stretch moves the truth: the check has teeth only if ignoring it would miss the targets.
    double stretch_lo = 1e9, stretch_hi = 0;
    for (const synth::SectionTruth& t : r.scene.sections)
      stretch_lo = std::min(stretch_lo, t.stretch), stretch_hi = std::max(stretch_hi, t.stretch);
    std::printf("k1 = %+.2f (stretch %.3f..%.3f; model %s): measured %d/%zu, median %.2f %%, p90 %.2f %%; fitted "
                "median %.2f %%, p90 %.2f %%\n",
                o.camera.dist_coeffs[0], stretch_lo, stretch_hi, r.result.model.kind.c_str(), measured.n,
                r.cmp.sections.size(), 100 * measured.median, 100 * measured.p90, 100 * fitted.median,
                100 * fitted.p90);
    EXPECT_GE(measured.n, 0.9 * r.cmp.sections.size());
    EXPECT_LE(measured.median, 0.02);
    EXPECT_LE(measured.p90, 0.05);
    EXPECT_LE(fitted.median, 0.02);
    EXPECT_LE(fitted.p90, 0.05);
    EXPECT_GT(std::max(1 - stretch_lo, stretch_hi - 1), o.camera.dist_coeffs[0] < 0 ? 0.04 : 0.015);
    // Where the stretch exceeds 3 %, ignoring it would use up most of the p90 target there; with it each answered
    // section is within the target.
    for (const SectionComparison& c : r.cmp.sections) {
      const synth::SectionTruth& t = r.scene.sections[(c.edge - 1) * 7 + (c.section - 1)];
      if (std::abs(1 - t.stretch) > 0.03 && c.model.answered) {
        EXPECT_LE(std::abs(c.model.error_px), 0.05 * c.true_r_px) << "edge " << c.edge << " section " << c.section
                                                                  << ", stretch " << t.stretch;
      }
    }
    // Each section's stretch against OpenCV's own distortion (cv::projectPoints, not core::LensDistortion, which synth
    // and calib share): the width across the edge of a small step in the board's plane, perpendicular to the edge, as
    // the distorted image shows it over the pinhole image's. calib.json carries it.
    const Json j = CalibToJson(r.result);
    const std::array<double, 9> k9 = r.scene.camera.Intrinsics();
    const cv::Matx33d K(k9.data());
    cv::Matx33d R;
    cv::Rodrigues(r.scene.rvec, R);
    const cv::Vec3d board_normal(R(0, 2), R(1, 2), R(2, 2));
    auto project = [&](const std::vector<cv::Point3d>& p, const std::vector<double>& dist) {
      std::vector<cv::Point2d> out;
      cv::projectPoints(p, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, dist, out);
      return out;
    };
    // Width across: the step's component perpendicular to the edge's image.
    auto across = [](const std::vector<cv::Point2d>& q) {
      const cv::Point2d t = q[1] - q[0], d = q[2] - q[0];
      return std::abs(t.x * d.y - t.y * d.x) / std::hypot(t.x, t.y);
    };
    for (size_t e = 0; e < r.result.edges.size(); ++e) {
      const auto& sections = r.result.edges[e].sections;
      ASSERT_GE(sections.size(), 2u);
      const cv::Vec3d along = cv::normalize(sections.back().midpoint_camera_mm - sections.front().midpoint_camera_mm);
      const cv::Vec3d perpendicular = cv::normalize(board_normal.cross(along));
      for (size_t k = 0; k < sections.size(); ++k) {
        const cv::Vec3d m = sections[k].midpoint_camera_mm;
        const double h = 0.05;  // mm on the board: a fraction of a px
        const std::vector<cv::Point3d> p{cv::Point3d(m), cv::Point3d(m + h * along), cv::Point3d(m + h * perpendicular)};
        const double independent = across(project(p, r.scene.camera.dist_coeffs)) / across(project(p, {}));
        EXPECT_NEAR(sections[k].stretch, independent, 2e-3) << "edge " << e + 1 << " section " << k + 1;
        EXPECT_EQ(j["edges"][e]["sections"][k]["stretch"], sections[k].stretch);
      }
    }
    // A virtual object at a section's midpoint gets the model's radius times the round stretch there, within a few
    // % of the photo's blur across the edge (a round kernel cannot be stretched across and along at once).
    const SceneCalib scene = SceneCalibFromJson(j, "calib.json: ");
    size_t most = 0;  // the section with the largest stretch
    for (size_t i = 0; i < r.scene.sections.size(); ++i)
      if (std::abs(1 - r.scene.sections[i].stretch) > std::abs(1 - r.scene.sections[most].stretch)) most = i;
    const SectionResult& far = r.result.edges[most / 7].sections[most % 7];
    const double truth = r.cmp.sections[most].true_r_px;
    const double fitted_at = BlurAtPx(scene, BlurSource::kFitted, far.midpoint_camera_mm);
    EXPECT_NEAR(fitted_at / StretchAt(scene, far.midpoint_camera_mm),
                r.result.model.PredictPx(optics::Lens::FromCamera(scene.camera), far.u_mm), 1e-9);
    EXPECT_NEAR(fitted_at, truth, 0.05 * truth);
    // The same model fitted to the photo's radii as they are (no stretch) misses that section by more than twice.
    std::vector<optics::BlurSample> raw;
    for (const auto& edge : r.result.edges)
      for (const auto& sec : edge.sections)
        if (sec.fit.ok) raw.push_back({sec.u_mm, sec.fit.r_px, 1.0});
    const optics::Lens lens = optics::Lens::FromCamera(r.result.camera);
    const double unstretched = optics::FitThinLens(lens, raw).PredictPx(lens, far.u_mm);
    std::printf("  most stretched section (stretch %.3f): true %.3f px, fitted %.3f px, fitted ignoring the stretch "
                "%.3f px\n", r.scene.sections[most].stretch, truth, far.r_fitted_px, unstretched);
    // (Barrel's 5 % only: pincushion's 2 % here is within the fit's own error.)
    if (r.scene.sections[most].stretch < 0.96) {
      EXPECT_LT(2 * std::abs(far.r_fitted_px - truth), std::abs(unstretched - truth));
    }
  }
}

// Model no more than the scene needs: a floor where the optics have one, none where they do not, chosen by
// leave-one-out error and written to calib.json with both candidates' errors and eq. 3.7's beside them.
TEST(Calibrate, ModelChoiceByHeldOutErrorIsWrittenWithBothFits) {
  const Calibration& with_floor = Calibrated(RealOpticsScenes()[2].options);  // floor 0.35 px, focus on edge 1
  const Json a = CalibToJson(with_floor.result)["model"]["choice"];
  std::printf("floor scene: %s\n", a.dump().c_str());
  EXPECT_EQ(a["chosen"], "thin_lens+floor");
  EXPECT_LT(a["thin_lens+floor"]["loo_rms_px"].get<double>(), 0.9 * a["thin_lens"]["loo_rms_px"].get<double>());
  EXPECT_NEAR(a["thin_lens+floor"]["floor_px"].get<double>(), 0.7, 0.07);  // 2 x 0.35 px
  EXPECT_GT(a["eq37"]["sections"].get<int>(), 0);
  const Json b = CalibToJson(Calibrated(Blurry()).result)["model"]["choice"];
  std::printf("no-floor scene: %s\n", b.dump().c_str());
  EXPECT_EQ(b["chosen"], "thin_lens");
  EXPECT_TRUE(b["thin_lens+floor"]["loo_rms_px"].is_number());
}

TEST(Calibrate, JsonHasEveryFieldTheIssueNames) {
  const Calibration& r = Calibrated(Thesis());
  const Json j = CalibToJson(r.result);
  for (const char* key : {"camera", "board", "pose", "reference_edge", "edges"}) EXPECT_TRUE(j.contains(key)) << key;
  for (const char* key : {"rvec", "tvec", "reprojection_error_px"}) EXPECT_TRUE(j["pose"].contains(key)) << key;
  ASSERT_EQ(j["edges"].size(), 11u);
  for (const Json& e : j["edges"]) {
    EXPECT_TRUE(e.contains("index") && e.contains("u_mm"));
    ASSERT_EQ(e["sections"].size(), 7u);
    for (const Json& s : e["sections"])
      for (const char* key : {"u_mm", "r_px", "r_thesis_px", "r_estimated_px", "r_fitted_px", "ok"})
        EXPECT_TRUE(s.contains(key)) << key;
  }
}

TEST(Calibrate, PhotoWithoutBoardIsNotFound) {
  const synth::Scene& scene = Rendered(Thesis());
  try {
    Calibrate(scene.image_no_board, scene.camera, scene.board);
    FAIL() << "expected no board";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kNotFound);
    EXPECT_NE(std::string(e.what()).find("7x10"), std::string::npos);
  }
}

TEST(Calibrate, BoardOfAnotherSizeIsNotFound) {
  const synth::Scene& scene = Rendered(Thesis());
  Board other = scene.board;
  other.cols = 8;
  try {
    Calibrate(scene.image, scene.camera, other);
    FAIL() << "expected no 8x10 board";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kNotFound);
  }
}

TEST(Calibrate, CameraOfAnotherImageSizeIsAnInputError) {
  const synth::Scene& scene = Rendered(Thesis());
  try {
    Calibrate(scene.image, ThesisCamera(), scene.board);
    FAIL() << "expected a size mismatch";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    EXPECT_NE(std::string(e.what()).find("1148x764"), std::string::npos);
  }
}

TEST(SceneCalib, ReadsBackCalibJsonAndAnswersEverySource) {
  const Calibration& r = Calibrated(Blurry());
  const SceneCalib scene = SceneCalibFromJson(CalibToJson(r.result), "calib.json: ");
  ASSERT_EQ(scene.sections.size(), 77u);
  // At the midpoint of edge 9 section 4 each source answers, and all agree with the truth within 2 % (measured: 0.14 %
  // for the edge's mean, 0.17 % estimated, 0.06 % fitted; it was 15 %, which a radius 10 % off passed).
  const SectionResult& s = r.result.edges[8].sections[3];
  const double truth = r.cmp.sections[8 * 7 + 3].true_r_px;
  double fixed = 0;
  EXPECT_EQ(BlurAtPx(scene, ParseBlurSource("none", nullptr), s.midpoint_camera_mm), 0.0);
  EXPECT_EQ(ParseBlurSource("measured_section", nullptr), BlurSource::kMeasuredSection);
  const BlurSource fixed_source = ParseBlurSource("2.5", &fixed);
  EXPECT_EQ(BlurAtPx(scene, fixed_source, s.midpoint_camera_mm, fixed), 2.5);
  EXPECT_NEAR(BlurAtPx(scene, BlurSource::kMeasuredSection, s.midpoint_camera_mm), s.fit.r_px, 1e-9);
  // "measured" is the edge's value, the mean of its usable sections (thesis Fig. 4.11), the same at either end of
  // the edge and beside the board on its line: a left and a right card get one value.
  double sum = 0;
  int usable = 0;
  for (const SectionResult& section : r.result.edges[8].sections)
    if (section.fit.ok) sum += section.fit.r_px, ++usable;
  ASSERT_GT(usable, 3);
  const double edge_mean = sum / usable;
  EXPECT_NEAR(edge_mean, r.result.edges[8].r_px, 1e-9);  // the calibration's own edge table says the same
  const cv::Vec3d first = r.result.edges[8].sections.front().midpoint_camera_mm;
  const cv::Vec3d last = r.result.edges[8].sections.back().midpoint_camera_mm;
  for (const cv::Vec3d& at : {s.midpoint_camera_mm, first, last, first + 0.8 * (first - last), last + 0.8 * (last - first)})
    EXPECT_NEAR(BlurAtPx(scene, BlurSource::kMeasured, at), edge_mean, 1e-9);
  EXPECT_NEAR(edge_mean, truth, 0.02 * truth);
  EXPECT_NEAR(BlurAtPx(scene, BlurSource::kEstimated, s.midpoint_camera_mm), truth, 0.02 * truth);
  EXPECT_NEAR(BlurAtPx(scene, BlurSource::kFitted, s.midpoint_camera_mm), truth, 0.02 * truth);
  // A point off the board, beyond edge 11, still gets an estimate: that is the point of the model.
  const cv::Vec3d beyond = scene.ToCamera({87.5, 300, 0});
  EXPECT_GT(BlurAtPx(scene, BlurSource::kFitted, beyond), r.cmp.true_r_per_edge[10]);
}

// "measured" is the nearest edge's own value or an error: an edge with no usable section (all flagged, or not in
// the file) must not borrow the next edge's value, which the record would then state as this edge's.
TEST(SceneCalib, MeasuredIsTheNearestEdgesOwnValueOrAnError) {
  const Calibration& r = Calibrated(Blurry());
  Json j = CalibToJson(r.result);
  for (Json& section : j["edges"][8]["sections"]) section["ok"] = false;  // edge 9: every section flagged
  SceneCalib scene = SceneCalibFromJson(j, "calib.json: ");
  // Edge 10: no section at all (a file lists every edge, RequireWholeCalib; a scene built in code may not).
  scene.sections.erase(std::remove_if(scene.sections.begin(), scene.sections.end(),
                                      [](const SceneCalib::Section& s) { return s.edge == 10; }),
                       scene.sections.end());
  const auto midpoint = [&](int edge) { return r.result.edges[edge - 1].sections[3].midpoint_camera_mm; };
  for (int edge : {9, 10}) {
    try {
      BlurAtPx(scene, BlurSource::kMeasured, midpoint(edge));
      ADD_FAILURE() << "edge " << edge << " has no usable section, yet measured gave a value";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("edge " + std::to_string(edge) + " (the nearest) has no usable"),
                std::string::npos) << e.what();
    }
  }
  // Its neighbours keep their own values, and the other sources still answer at edge 9.
  for (int edge : {8, 11}) EXPECT_NEAR(BlurAtPx(scene, BlurSource::kMeasured, midpoint(edge)), r.result.edges[edge - 1].r_px, 1e-9);
  EXPECT_GT(BlurAtPx(scene, BlurSource::kFitted, midpoint(9)), 0);
  // measured_section alike: the nearest section's own value or an error naming it (it gave edge 8's or 10's section
  // before, recorded as this place's), and a usable section's own value.
  try {
    BlurAtPx(scene, BlurSource::kMeasuredSection, midpoint(9));
    ADD_FAILURE() << "edge 9 section 4 is not usable, yet measured_section gave a value";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("edge 9 section 4 (the nearest) is not usable"), std::string::npos) << e.what();
  }
  EXPECT_NEAR(BlurAtPx(scene, BlurSource::kMeasuredSection, midpoint(8)), r.result.edges[7].sections[3].fit.r_px, 1e-9);
}

// A command's blur source and a protocol's are one vocabulary (core/blur_source.h): each word a protocol may write
// names the same source here, "fixed" is no word (a number is), and a misspelt word is refused with a did-you-mean.
TEST(SceneBlur, CommandsReadTheProtocolsBlurSourceWords) {
  EXPECT_EQ(BlurSourceWords(), (std::vector<std::string>{"none", "measured", "measured_section", "estimated", "fitted"}));
  for (const BlurSource source : kBlurSources) {
    if (source == BlurSource::kFixed) continue;
    EXPECT_EQ(ParseBlurSource(ToString(source), nullptr), source) << ToString(source);
  }
  EXPECT_THROW(ParseBlurSource("fixed", nullptr), Error);
  try {
    ParseBlurSource("mesured", nullptr);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("got 'mesured' (did you mean measured?)"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace blurcue::calib
