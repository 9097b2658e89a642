#include "calib/edge_blur.h"
#include "calib/edge_window.h"

#include <gtest/gtest.h>

#include <limits>

#include <array>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <string>

#include <opencv2/imgproc.hpp>

#include "core/image.h"

namespace blurcue::calib {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A straight black/white edge with known blur, rendered independently of the code under test: the optical
// ESF evaluated at 8x supersampled positions in linear light, then area-averaged to pixels (the pixel aperture).
struct EdgeSpec {
  std::string psf = "disc";  // "disc" (radius r) or "gaussian" (std r / 2); "disc x gaussian": disc of radius r
                             // convolved with a Gaussian of std floor_px
  double floor_px = 0;
  double r_px = 4;
  double angle_deg = 7;      // direction of the edge line from the image x axis
  double offset_px = 0;      // true edge position along the segment's normal
  double black = 0.04, white = 0.80;
  double noise = 0;          // Gaussian noise std, linear
  bool srgb8 = true;         // round trip through 8-bit sRGB, as a photo would be stored
  int size_px = 160;
  double half_window_px = 50;
  double length_px = 120;
  int spots = 0;             // dark printing spots on the bright side near the edge
  double bow_px = 0;         // the edge is the parabola bowing this far off the chord at its middle (0: straight)
  double stripe_px = 0;      // > 0: parallel edges every stripe_px across the image, steps alternating (a board's
                             // column of squares, blurred as a whole); the one through the centre rises
  // > 0 (Gaussian only): the colours also alternate along the edge every checker_px, the section's square centred:
  // a checkerboard whose X-junctions lie at the section's ends when checker_px = length_px. A Gaussian is separable,
  // so the blurred board is the product of the blurred steps across and the blurred columns along.
  double checker_px = 0;
  unsigned seed = 1;
};

struct EdgeImage {
  cv::Mat linear;  // CV_32F, what MeasureEdgeModel sees
  cv::Mat grey8;   // 8-bit sRGB, what MeasureEdgeThesis sees
  EdgeSegment segment;
};

// Disc of radius R convolved with a Gaussian of std f, by direct quadrature (t = R sin a over the semicircle,
// 600 midpoint steps), tabulated every 1/250 px: shares nothing with the code under test.
struct DiscGaussEsf {
  double R, f, lo, step = 4e-3;
  std::vector<double> table;
  DiscGaussEsf(double R_, double f_) : R(R_), f(f_), lo(-(R_ + 8 * f_)) {
    const int n = static_cast<int>(std::ceil(-2 * lo / step)) + 2;
    table.resize(n);
    const int K = 600;
    for (int i = 0; i < n; ++i) {
      const double x = lo + i * step;
      double sum = 0;
      for (int k = 0; k < K; ++k) {
        const double a = -kPi / 2 + kPi * (k + 0.5) / K;
        // semicircle density (2 / (pi R^2)) sqrt(R^2 - t^2) dt with t = R sin a, dt = R cos a da
        const double w = 2 / kPi * std::cos(a) * std::cos(a) * kPi / K;
        sum += w * 0.5 * std::erfc(-(x - R * std::sin(a)) / (f * std::sqrt(2.0)));
      }
      table[i] = sum;
    }
  }
  double operator()(double x) const {
    const double u = (x - lo) / step;
    if (u <= 0) return 0;
    if (u >= table.size() - 1) return 1;
    const int i = static_cast<int>(u);
    return table[i] + (u - i) * (table[i + 1] - table[i]);
  }
};

double OpticalEsf(const std::string& psf, double r, double x) {
  if (r <= 0) return x > 0 ? 1.0 : x < 0 ? 0.0 : 0.5;
  if (psf == "gaussian") return 0.5 * std::erfc(-x / (0.5 * r * std::sqrt(2.0)));
  const double u = x / r;
  if (u <= -1) return 0;
  if (u >= 1) return 1;
  return 0.5 + (u * std::sqrt(1 - u * u) + std::asin(u)) / kPi;
}

EdgeImage Render(const EdgeSpec& spec) {
  const int S = 8, N = spec.size_px;
  const double th = spec.angle_deg * kPi / 180;
  const cv::Point2d t(std::cos(th), std::sin(th)), n(-t.y, t.x);
  const cv::Point2d c(0.5 * (N - 1), 0.5 * (N - 1));
  const double reach = spec.psf == "gaussian" ? 4 * spec.r_px : spec.r_px + 8 * spec.floor_px;
  std::optional<DiscGaussEsf> mixed;
  if (spec.psf == "disc x gaussian") mixed.emplace(spec.r_px, spec.floor_px);
  cv::Mat fine(N * S, N * S, CV_32F);
  for (int j = 0; j < N * S; ++j) {
    float* row = fine.ptr<float>(j);
    const double y = (j + 0.5) / S - 0.5;
    for (int i = 0; i < N * S; ++i) {
      const double x = (i + 0.5) / S - 0.5;
      const double along = 2 * ((x - c.x) * t.x + (y - c.y) * t.y) / spec.length_px;
      const double d = (x - c.x) * n.x + (y - c.y) * n.y - spec.offset_px - spec.bow_px * (1 - along * along);
      auto esf = [&](double x) {
        return x < -reach ? 0.0 : x > reach ? 1.0 : mixed ? (*mixed)(x) : OpticalEsf(spec.psf, spec.r_px, x);
      };
      double e = esf(d);
      if (spec.stripe_px > 0) {
        // Edges at k g, k = -K..K with K even: the steps alternate and sum to 0 left of the centre's.
        const int K = 2 * static_cast<int>(std::ceil(N / spec.stripe_px));
        e = 0;
        for (int k = -K; k <= K; ++k) e += (k % 2 ? -1 : 1) * esf(d - k * spec.stripe_px);
      }
      if (spec.checker_px > 0) {
        const double sd = 0.5 * spec.r_px, s_along = (x - c.x) * t.x + (y - c.y) * t.y, L = spec.checker_px;
        double q = 0;  // the blurred columns, +1 inside the centred square
        for (int m = -(N / int(L) + 2); m <= N / int(L) + 2; ++m)
          q += (m % 2 ? -1 : 1) * 0.5 * (std::erfc(-(s_along - (m - 0.5) * L) / (sd * std::sqrt(2.0))) -
                                           std::erfc(-(s_along - (m + 0.5) * L) / (sd * std::sqrt(2.0))));
        e = 0.5 * (1 + (2 * e - 1) * q);
      }
      row[i] = static_cast<float>(spec.black + (spec.white - spec.black) * e);
    }
  }
  EdgeImage out;
  cv::resize(fine, out.linear, cv::Size(N, N), 0, 0, cv::INTER_AREA);
  for (int k = 0; k < spec.spots; ++k) {
    const double along = -20 + 40.0 * k / std::max(1, spec.spots - 1);
    const cv::Point2d p = c + along * t + (spec.offset_px + 3 + 1.5 * spec.r_px) * n;
    cv::circle(out.linear, cv::Point(cvRound(p.x), cvRound(p.y)), 3, cv::Scalar(0.03), cv::FILLED);
  }
  if (spec.noise > 0) {
    cv::Mat noise(out.linear.size(), CV_32F);
    cv::RNG rng(spec.seed);
    rng.fill(noise, cv::RNG::NORMAL, 0, spec.noise);
    out.linear += noise;
  }
  cv::min(cv::max(out.linear, 0.0), 1.0, out.linear);
  out.grey8 = EncodeSrgb8(out.linear);
  if (spec.srgb8) out.linear = DecodeSrgb8(out.grey8);
  out.segment.a = c - 0.5 * spec.length_px * t;
  out.segment.b = c + 0.5 * spec.length_px * t;
  out.segment.half_window_px = spec.half_window_px;
  return out;
}

// What the edge model must get right on a clean synthetic edge (noise 1 %, any angle): within 0.06 px or 1.5 %. The
// sweeps measured at most 0.053 px at r = 4 and 1.05 % at r = 12; the error this guards against is a radius
// several per cent off (a whole-pixel-sampled kernel, a mis-scaled LSF moment): 5 % off fails at every r > 1.2 px,
// 10 % off at every r > 0.6 px.
// (It was max(0.25 px, 5 %): 50 % at r = 0.5.)
double Tolerance(double r) { return std::max(0.06, 0.015 * r); }
// An 8-bit edge of 5 % contrast spans ~8 code values: within 0.12 px or 3 % (measured: 0.078 px at r = 1, 2.5 % at r = 8).
double LowContrastTolerance(double r) { return std::max(0.12, 0.03 * r); }

bool HasFlag(const ModelFit& fit, const std::string& flag) {
  return std::find(fit.flags.begin(), fit.flags.end(), flag) != fit.flags.end();
}

std::string Describe(const ModelFit& fit) {
  std::string s = "r=" + std::to_string(fit.r_px) + " psf=" + fit.psf + " rms_rel=" + std::to_string(fit.rms_rel) +
                  " flags:";
  for (const auto& f : fit.flags) s += " " + f;
  return s;
}

const double kRadii[] = {0.5, 1, 2, 4, 8, 12, 20};
const double kAngles[] = {0, 7, 30, 90};

void ExpectSweepWithinTolerance(const std::string& psf) {
  unsigned seed = 1;
  for (double angle : kAngles)
    for (double r : kRadii) {
      EdgeSpec spec;
      spec.psf = psf;
      spec.r_px = r;
      spec.angle_deg = angle;
      spec.noise = 0.01;
      spec.seed = seed++;
      const EdgeImage img = Render(spec);
      const ModelFit fit = MeasureEdgeModel(img.linear, img.segment);
      EXPECT_TRUE(fit.ok) << psf << " r=" << r << " angle=" << angle << ": " << Describe(fit);
      EXPECT_NEAR(fit.r_px, r, Tolerance(r)) << psf << " angle=" << angle << ": " << Describe(fit);
    }
}

TEST(EdgeModel, DiscRadiusWithinToleranceAtAnyAngle) { ExpectSweepWithinTolerance("disc"); }

TEST(EdgeModel, GaussianRadiusWithinToleranceAtAnyAngle) { ExpectSweepWithinTolerance("gaussian"); }

TEST(EdgeModel, PicksTheBetterFittingFamilyForLargeBlur) {
  for (const std::string psf : {"disc", "gaussian"}) {
    EdgeSpec spec;
    spec.psf = psf;
    spec.r_px = 10;
    spec.noise = 0.005;
    const EdgeImage img = Render(spec);
    const ModelFit fit = MeasureEdgeModel(img.linear, img.segment);
    EXPECT_EQ(fit.psf, psf) << "disc " << fit.disc_r_px << " floor " << fit.floor_sigma_px << " se "
                            << fit.shape_se_rad;
  }
}

// The DESIGN.md definition on known profiles: r = 2 x the LSF's standard deviation, pixel aperture removed. A
// Gaussian of std s reads 2 s, a disc of radius R reads R, a disc convolved with a Gaussian floor of std f reads
// sqrt(R^2 + 4 f^2), within 2 %, from a floor alone (a focused edge) to a large disc, at two angles, with noise.
TEST(EdgeModel, SecondMomentOfAnyShapeWithinTwoPercent) {
  struct Case {
    const char* psf;
    double r, floor, truth;
  };
  const Case cases[] = {
      {"gaussian", 0.7, 0, 0.7},   {"gaussian", 1.4, 0, 1.4},     {"gaussian", 6, 0, 6},
      {"disc", 1.0, 0, 1.0},       {"disc", 3, 0, 3},             {"disc x gaussian", 0.3, 0.35, std::hypot(0.3, 0.7)},
      {"disc x gaussian", 0.8, 0.35, std::hypot(0.8, 0.7)},       {"disc x gaussian", 1.3, 0.6, std::hypot(1.3, 1.2)},
      {"disc x gaussian", 4, 0.6, std::hypot(4, 1.2)},            {"disc x gaussian", 8, 0.45, std::hypot(8, 0.9)},
  };
  for (const Case& c : cases)
    for (double angle : {4.0, 30.0}) {
      EdgeSpec spec;
      spec.psf = c.psf;
      spec.r_px = c.r;
      spec.floor_px = c.floor;
      spec.angle_deg = angle;
      spec.noise = 0.002;
      const EdgeImage img = Render(spec);
      const ModelFit fit = MeasureEdgeModel(img.linear, img.segment);
      EXPECT_TRUE(fit.ok) << c.psf << " " << c.r << " " << c.floor << ": " << Describe(fit);
      EXPECT_NEAR(fit.r_px, c.truth, 0.02 * c.truth)
          << c.psf << " R/r " << c.r << " floor " << c.floor << " angle " << angle << ": " << Describe(fit)
          << " disc " << fit.disc_r_px << " floor " << fit.floor_sigma_px;
    }
}

// Where the profile supports it the split is found: a 6 px disc with a 1 px floor.
TEST(EdgeModel, RecoversDiscAndFloorWhereTheProfileSupportsIt) {
  EdgeSpec spec;
  spec.psf = "disc x gaussian";
  spec.r_px = 6;
  spec.floor_px = 1.0;
  spec.noise = 0.002;
  spec.srgb8 = false;
  const EdgeImage img = Render(spec);
  const ModelFit fit = MeasureEdgeModel(img.linear, img.segment);
  EXPECT_FALSE(fit.shape_ambiguous) << fit.shape_se_rad;
  EXPECT_NEAR(fit.disc_r_px, 6, 0.2) << Describe(fit);
  EXPECT_NEAR(fit.floor_sigma_px, 1.0, 0.15) << Describe(fit);
}

// A slowly varying level across the window (vignetting: 8 % over the window) does not widen the edge.
TEST(EdgeModel, SlopingLevelsDoNotWidenTheEdge) {
  for (double r : {0.7, 3.0}) {
    EdgeSpec spec;
    spec.psf = "gaussian";
    spec.r_px = r;
    spec.noise = 0.002;
    spec.srgb8 = false;
    EdgeImage img = Render(spec);
    const double th = spec.angle_deg * kPi / 180;
    const cv::Point2d n(-std::sin(th), std::cos(th)), c(0.5 * (spec.size_px - 1), 0.5 * (spec.size_px - 1));
    for (int y = 0; y < img.linear.rows; ++y)
      for (int x = 0; x < img.linear.cols; ++x)
        img.linear.at<float>(y, x) *= static_cast<float>(1 + 0.0008 * ((x - c.x) * n.x + (y - c.y) * n.y));
    const ModelFit fit = MeasureEdgeModel(img.linear, img.segment);
    EXPECT_NEAR(fit.r_px, r, 0.02 * r) << Describe(fit);
  }
}

// The truth above comes from the disc's closed-form ESF; here a real 2-D disc kernel (antialiased, 4x
// supersampled) blurs a sharp edge, so "disc of radius R measures r = R" holds for the PSF itself.
TEST(EdgeModel, RealDiscConvolutionMeasuresItsRadius) {
  const int S = 4, N = 120;
  const double R = 6, th = 7 * kPi / 180;
  const cv::Point2d t(std::cos(th), std::sin(th)), n(-t.y, t.x), c(0.5 * (N - 1), 0.5 * (N - 1));
  cv::Mat fine(N * S, N * S, CV_32F);
  for (int j = 0; j < N * S; ++j)
    for (int i = 0; i < N * S; ++i) {
      const double x = (i + 0.5) / S - 0.5, y = (j + 0.5) / S - 0.5;
      fine.at<float>(j, i) = (x - c.x) * n.x + (y - c.y) * n.y > 0 ? 0.8f : 0.04f;
    }
  const int kr = static_cast<int>(std::ceil(R * S));
  cv::Mat kernel(2 * kr + 1, 2 * kr + 1, CV_32F);
  const int sub = 8;
  for (int j = -kr; j <= kr; ++j)
    for (int i = -kr; i <= kr; ++i) {
      int inside = 0;
      for (int q = 0; q < sub; ++q)
        for (int p = 0; p < sub; ++p) {
          const double x = i - 0.5 + (p + 0.5) / sub, y = j - 0.5 + (q + 0.5) / sub;
          inside += x * x + y * y <= R * S * R * S;
        }
      kernel.at<float>(j + kr, i + kr) = static_cast<float>(inside);
    }
  kernel /= cv::sum(kernel)[0];
  cv::filter2D(fine, fine, -1, kernel, cv::Point(-1, -1), 0, cv::BORDER_REPLICATE);
  cv::Mat linear;
  cv::resize(fine, linear, cv::Size(N, N), 0, 0, cv::INTER_AREA);
  const EdgeSegment seg{c - 50.0 * t, c + 50.0 * t, 40};
  const ModelFit fit = MeasureEdgeModel(linear, seg);
  EXPECT_TRUE(fit.ok) << Describe(fit);
  EXPECT_NEAR(fit.r_px, R, Tolerance(R)) << Describe(fit);
  EXPECT_EQ(fit.psf, "disc");
}

// Without modelling the pixel's own area a sharp edge would read about 0.58 px.
// A lens distortion bows a board's straight edge (calibrate.cc gives the bow from the projected midpoint): sampled
// across the parabola the bowed edge measures its own blur; taken as straight, the bow's spread adds to it.
TEST(EdgeModel, BowedEdgeMeasuredAcrossItsCurve) {
  EdgeSpec spec;
  spec.r_px = 1.2;
  spec.bow_px = 4;
  spec.angle_deg = 7;
  EdgeImage img = Render(spec);
  const ModelFit curved = MeasureEdgeModel(img.linear, [&] { EdgeSegment s = img.segment; s.bow_px = 4; return s; }());
  EXPECT_TRUE(curved.ok) << Describe(curved);
  EXPECT_NEAR(curved.r_px, 1.2, 0.02 * 1.2) << Describe(curved);
  const ModelFit straight = MeasureEdgeModel(img.linear, img.segment);
  // Taken as straight it reads 9 % high (11 % before the bins' own spread was modelled: part of that was theirs).
  EXPECT_GT(std::abs(straight.r_px - 1.2), 0.05 * 1.2) << Describe(straight);
}

TEST(EdgeModel, SharpEdgeMeasuresNearZero) {
  for (double angle : {0.0, 7.0, 30.0, 45.0}) {
    EdgeSpec spec;
    spec.r_px = 0;
    spec.angle_deg = angle;
    spec.noise = 0.005;
    const EdgeImage img = Render(spec);
    const ModelFit fit = MeasureEdgeModel(img.linear, img.segment);
    EXPECT_TRUE(fit.ok) << "angle=" << angle << ": " << Describe(fit);
    EXPECT_LT(fit.r_px, 0.25) << "angle=" << angle << ": " << Describe(fit);
  }
}

TEST(EdgeModel, ReportsOffsetAndSignedStep) {
  EdgeSpec spec;
  spec.offset_px = 1.3;
  spec.srgb8 = false;
  const EdgeImage img = Render(spec);
  const ModelFit fit = MeasureEdgeModel(img.linear, img.segment);
  EXPECT_NEAR(fit.offset_px, 1.3, 0.05);
  EXPECT_NEAR(fit.step, 0.76, 0.01);
  // The same edge walked the other way: the normal flips, and with it the step and the offset.
  const EdgeSegment reversed{img.segment.b, img.segment.a, img.segment.half_window_px};
  const ModelFit back = MeasureEdgeModel(img.linear, reversed);
  EXPECT_NEAR(back.offset_px, -1.3, 0.05);
  EXPECT_NEAR(back.step, -0.76, 0.01);
  EXPECT_NEAR(back.r_px, fit.r_px, 0.02);
}

TEST(EdgeModel, DarkPrintingSpotsAreRejectedAndFlagged) {
  EdgeSpec spec;
  spec.r_px = 4;
  spec.noise = 0.01;
  spec.spots = 3;
  const EdgeImage img = Render(spec);
  const ModelFit fit = MeasureEdgeModel(img.linear, img.segment);
  EXPECT_TRUE(fit.ok) << Describe(fit);
  EXPECT_TRUE(HasFlag(fit, "flaw")) << Describe(fit);
  EXPECT_NEAR(fit.r_px, 4, Tolerance(4)) << Describe(fit);
}

TEST(EdgeModel, CleanEdgeHasNoFlags) {
  EdgeSpec spec;
  spec.noise = 0.01;
  const EdgeImage img = Render(spec);
  const ModelFit fit = MeasureEdgeModel(img.linear, img.segment);
  EXPECT_TRUE(fit.ok);
  EXPECT_TRUE(fit.flags.empty()) << Describe(fit);
  EXPECT_GT(fit.samples, 1000);
}

TEST(EdgeModel, LowContrastIsFlagged) {
  EdgeSpec spec;
  spec.black = 0.40;
  spec.white = 0.42;
  spec.srgb8 = false;
  const EdgeImage img = Render(spec);
  const ModelFit fit = MeasureEdgeModel(img.linear, img.segment);
  EXPECT_FALSE(fit.ok);
  EXPECT_TRUE(HasFlag(fit, "low_contrast")) << Describe(fit);
}

TEST(EdgeModel, SaturatedWhiteIsFlagged) {
  EdgeSpec spec;
  spec.white = 1.3;  // clipped at 1 by the render
  const EdgeImage img = Render(spec);
  const ModelFit fit = MeasureEdgeModel(img.linear, img.segment);
  EXPECT_FALSE(fit.ok);
  EXPECT_TRUE(HasFlag(fit, "saturated")) << Describe(fit);
}

TEST(EdgeModel, BlurWiderThanTheWindowIsCrowded) {
  EdgeSpec spec;
  spec.r_px = 16;
  spec.half_window_px = 20;
  const EdgeImage img = Render(spec);
  const ModelFit fit = MeasureEdgeModel(img.linear, img.segment);
  EXPECT_FALSE(fit.ok);
  EXPECT_TRUE(HasFlag(fit, "crowded")) << Describe(fit);
}

// A 30 px section of a board keeps its central half only 7.5 px from the X-junctions, and even a fifth of it only
// 12 px: a Gaussian of r = 12 px (std 6) reaches past them into the squares of the other colour. It was refused
// `crowded`; the crossing lines now join the profile model (edge_junction.h) and it is measured (flag `junctions`).
// Truth: the Gaussian is separable, so the blurred checkerboard is the product of the blurred steps (Render).
TEST(EdgeModel, SectionTooShortForItsBlurMeasuredWithItsXJunctionsModelled) {
  for (double angle : {7.0, 30.0}) {
    EdgeSpec spec;
    spec.psf = "gaussian";
    spec.r_px = 12;
    spec.length_px = spec.checker_px = 30;
    spec.angle_deg = angle;
    spec.noise = 0.003;
    const EdgeImage img = Render(spec);
    const ModelFit fit = MeasureEdgeModel(img.linear, img.segment);
    EXPECT_TRUE(fit.ok) << angle << ": " << Describe(fit);
    EXPECT_TRUE(HasFlag(fit, "junctions")) << angle << ": " << Describe(fit);
    std::printf("angle %.0f deg: r %.3f px for 12 (%s)\n", angle, fit.r_px, Describe(fit).c_str());
    EXPECT_NEAR(fit.r_px, spec.r_px, Tolerance(spec.r_px)) << angle << ": " << Describe(fit);
  }
}

// The segment with its parallel neighbours `gap_px` either side (a stripe pattern's, as calibrate gives a board's),
// the image free of other edges half a gap past them.
// The neighbouring parallel edges gap_px away on the given sides of the normal (-1, +1; both by default).
EdgeSegment WithNeighbours(EdgeSegment segment, double gap_px, std::initializer_list<double> sides = {-1.0, 1.0}) {
  const cv::Point2d dir = (segment.b - segment.a) / cv::norm(segment.b - segment.a), n(-dir.y, dir.x);
  for (double side : sides)
    segment.neighbours.push_back({segment.a + side * gap_px * n, segment.b + side * gap_px * n, 0.5 * gap_px});
  return segment;
}

// Parallel edges closer than 3 r (a board's squares at strong blur: each edge's spread reaches the next). Without
// their places the section is refused as crowded, saying why; with them (as calibrate gives them from the pose) the
// window reaches across the neighbours, their steps join the profile model, and r is within 2 % of the truth: a
// Gaussian's 2 s, a disc's R, a disc x floor's sqrt(R^2 + 4 f^2) (DESIGN.md).
TEST(EdgeModel, ParallelEdgesCloserThanThreeRadiiMeasuredAcrossEachOther) {
  struct Case {
    const char* psf;
    double r_px, floor_px, gap_px, truth_px;
  };
  const Case cases[] = {{"gaussian", 6, 0, 15, 6},
                        {"disc", 8, 0, 20, 8},
                        {"disc x gaussian", 8, 0.6, 22, std::sqrt(64 + 4 * 0.36)}};
  unsigned seed = 40;
  for (const Case& c : cases) {
    ASSERT_LT(c.gap_px, 3 * c.truth_px);
    EdgeSpec spec;
    spec.psf = c.psf;
    spec.r_px = c.r_px;
    spec.floor_px = c.floor_px;
    spec.stripe_px = c.gap_px;
    spec.half_window_px = 0.5 * c.gap_px;  // half way to the next edge, as calibrate sets it
    spec.noise = 0.003;
    spec.seed = seed++;
    const EdgeImage img = Render(spec);
    const ModelFit alone = MeasureEdgeModel(img.linear, img.segment);
    EXPECT_FALSE(alone.ok) << c.psf << ": " << Describe(alone);
    EXPECT_TRUE(HasFlag(alone, "crowded")) << c.psf << ": " << Describe(alone);
    EXPECT_NE(alone.crowded_why.find("next edge"), std::string::npos) << alone.crowded_why;

    const ModelFit fit = MeasureEdgeModel(img.linear, WithNeighbours(img.segment, c.gap_px));
    EXPECT_TRUE(fit.ok) << c.psf << ": " << Describe(fit) << " " << fit.crowded_why;
    EXPECT_TRUE(HasFlag(fit, "neighbours")) << c.psf << ": " << Describe(fit);
    EXPECT_NEAR(fit.r_px, c.truth_px, 0.02 * c.truth_px) << c.psf << ": " << Describe(fit);
  }
}

// Edges 7 px apart under a blur of r = 8 px: the neighbours lie inside the blur and the edges after them within
// its reach; the section stays refused, with the reason in words.
TEST(EdgeModel, NeighboursWithinTheBlurAreCrowdedSayingWhy) {
  EdgeSpec spec;
  spec.psf = "gaussian";
  spec.r_px = 8;
  spec.stripe_px = 7;
  spec.half_window_px = 3.5;
  spec.srgb8 = false;
  const EdgeImage img = Render(spec);
  const ModelFit fit = MeasureEdgeModel(img.linear, WithNeighbours(img.segment, 7));
  EXPECT_FALSE(fit.ok) << Describe(fit);
  EXPECT_TRUE(HasFlag(fit, "crowded")) << Describe(fit);
  EXPECT_NE(fit.crowded_why.find("within reach of its blur"), std::string::npos) << fit.crowded_why;
}

// The board's outer edge: a neighbouring edge on one side only, and beyond the edge on the other side the table,
// which the board does not describe. Where the photo there is flat for as far as the blur reaches (a Gaussian of
// r = 8 px reaches 14 px, past the 12.5 px half gap), the window widens on that side and r is within 2 %; where
// another edge lies there (18 px away, inside that reach), the section stays refused, saying why.
TEST(EdgeModel, OuterEdgeMeasuredWhereThePhotoBeyondIsFlatRefusedWhereAnEdgeLiesThere) {
  EdgeSpec spec;
  spec.psf = "gaussian";
  spec.r_px = 8;
  spec.half_window_px = 12.5;
  spec.srgb8 = false;
  spec.noise = 0.003;
  const EdgeImage flat = Render(spec);
  const ModelFit fit = MeasureEdgeModel(flat.linear, WithNeighbours(flat.segment, 25, {-1.0}));
  EXPECT_TRUE(fit.ok) << Describe(fit) << " " << fit.crowded_why;
  EXPECT_NEAR(fit.r_px, 8, 0.02 * 8) << Describe(fit);

  spec.stripe_px = 18;
  spec.half_window_px = 9;
  const EdgeImage striped = Render(spec);
  const ModelFit refused = MeasureEdgeModel(striped.linear, WithNeighbours(striped.segment, 18, {-1.0}));
  EXPECT_FALSE(refused.ok) << Describe(refused);
  EXPECT_NE(refused.crowded_why.find("free of other edges"), std::string::npos) << refused.crowded_why;
}

// A NaN or infinite fit (offset, reach, step) never widens a window: its end would become NaN.
TEST(EdgeModel, WideningIgnoresNonFiniteFits) {
  EdgeSpec spec;
  spec.half_window_px = 12.5;
  spec.srgb8 = false;
  const EdgeImage img = Render(spec);
  const EdgeSegment segment = WithNeighbours(img.segment, 25, {-1.0});
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  for (const auto& [reach, offset, step] : std::vector<std::array<double, 3>>{
           {14, nan, 0.7}, {nan, 0, 0.7}, {inf, 0, 0.7}, {14, 0, nan}, {14, 1e308, 0.7}, {-1, 0, 0.7}}) {
    EdgeWindow w = NeighbourWindow(segment, 14);
    const double before = w.plus.end_px;
    WidenFreeSides(img.linear, segment, reach, offset, step, &w);
    EXPECT_TRUE(std::isfinite(w.plus.end_px)) << reach << " " << offset << " " << step;
    EXPECT_LE(w.plus.end_px, 2 * before + 1) << reach << " " << offset << " " << step;
  }
}

// Noise clipped at 0 on a near-black square is not clipped signal: the bin medians are unbiased.
TEST(EdgeModel, ClippedNoiseTailsAreNotSaturation) {
  EdgeSpec spec;
  spec.black = 0.01;
  spec.noise = 0.02;
  const EdgeImage img = Render(spec);
  const ModelFit fit = MeasureEdgeModel(img.linear, img.segment);
  EXPECT_TRUE(fit.ok) << Describe(fit);
  EXPECT_FALSE(HasFlag(fit, "saturated")) << Describe(fit);
  EXPECT_NEAR(fit.r_px, spec.r_px, Tolerance(spec.r_px)) << Describe(fit);
}

// 5 % Michelson contrast in 8-bit sRGB spans ~8 code values: bin medians would snap to codes and widen the edge;
// the bins' trimmed means do not.
TEST(EdgeModel, LowContrastEightBitEdgeStillAccurate) {
  for (double r : {0.5, 1.0, 3.0, 8.0}) {
    EdgeSpec spec;
    spec.psf = "gaussian";
    spec.r_px = r;
    spec.angle_deg = 43;
    spec.black = 0.42 * 0.95;
    spec.white = 0.42 * 1.05;
    spec.noise = 0.004;
    const EdgeImage img = Render(spec);
    const ModelFit fit = MeasureEdgeModel(img.linear, img.segment);
    EXPECT_TRUE(fit.ok) << Describe(fit);
    EXPECT_NEAR(fit.r_px, r, LowContrastTolerance(r)) << Describe(fit);
  }
}

// Two edges in one window (a stripe) are not one step.
TEST(EdgeModel, StripeIsAPoorFit) {
  EdgeSpec spec;
  spec.r_px = 2;
  spec.srgb8 = false;
  EdgeImage img = Render(spec);
  const double th = spec.angle_deg * kPi / 180;
  const cv::Point2d t(std::cos(th), std::sin(th)), n(-t.y, t.x), c(79.5, 79.5);
  for (int y = 0; y < img.linear.rows; ++y)
    for (int x = 0; x < img.linear.cols; ++x)
      if ((x - c.x) * n.x + (y - c.y) * n.y > 15) img.linear.at<float>(y, x) = 0.04f;
  const ModelFit fit = MeasureEdgeModel(img.linear, img.segment);
  EXPECT_FALSE(fit.ok);
  EXPECT_TRUE(HasFlag(fit, "poor_fit")) << Describe(fit);
}

TEST(EdgeModel, DegenerateInputsGiveFlagsNotNaN) {
  const EdgeImage img = Render(EdgeSpec{});
  const EdgeSegment inputs[] = {
      {{80, 80}, {80, 80}, 40},        // no length
      {{80, 20}, {80, 140}, 0},        // no window
      {{500, 500}, {600, 500}, 40},    // outside the image
      {{2, -100}, {2, 300}, 40},       // mostly outside
  };
  for (const EdgeSegment& seg : inputs) {
    const ModelFit fit = MeasureEdgeModel(img.linear, seg);
    EXPECT_FALSE(fit.ok);
    EXPECT_FALSE(fit.flags.empty());
    EXPECT_TRUE(std::isfinite(fit.r_px) && std::isfinite(fit.step) && std::isfinite(fit.offset_px) &&
                std::isfinite(fit.rms_rel));
  }
  const cv::Mat flat(160, 160, CV_32F, cv::Scalar(0.5));
  const ModelFit fit = MeasureEdgeModel(flat, img.segment);
  EXPECT_FALSE(fit.ok);
  EXPECT_TRUE(HasFlag(fit, "low_contrast"));
  EXPECT_TRUE(std::isfinite(fit.r_px) && std::isfinite(fit.rms_rel));
}

// A vertical linear ramp of `slope` grey levels per pixel over 20 pixels, profile sampled at whole pixels.
cv::Mat Ramp(int slope) {
  cv::Mat grey(100, 100, CV_8U);
  for (int y = 0; y < 100; ++y)
    for (int x = 0; x < 100; ++x) grey.at<uint8_t>(y, x) = static_cast<uint8_t>(50 + slope * std::clamp(x - 40, 0, 20));
  return grey;
}

// By hand, SMA of n = 5 then forward difference: the 20 ramp increments of `slope` become 20 - 4 = 16 samples of
// full slope plus 4 on each side at slope * k / 5, k = 1..4. Slope 10: all 4 exceed 1 -> 24 -> r = 12.
// Slope 2: only k = 3, 4 (1.2, 1.6) exceed 1 -> 16 + 4 = 20 -> r = 10.
TEST(ThesisMethod, LinearRampCountMatchesHandCount) {
  const EdgeSegment seg{{50, 10}, {50, 90}, 45};
  const ThesisMeasure steep = MeasureEdgeThesis(Ramp(10), seg);
  EXPECT_TRUE(steep.ok);
  EXPECT_EQ(steep.count, 24);
  EXPECT_DOUBLE_EQ(steep.r_px, 12);
  const ThesisMeasure shallow = MeasureEdgeThesis(Ramp(2), seg);
  EXPECT_EQ(shallow.count, 20);
  EXPECT_DOUBLE_EQ(shallow.r_px, 10);
  ThesisOptions no_smoothing;
  no_smoothing.sma_n = 1;
  EXPECT_EQ(MeasureEdgeThesis(Ramp(2), seg, no_smoothing).count, 20);
}

TEST(ThesisMethod, NothingAboveThresholdIsNotOk) {
  const EdgeSegment seg{{50, 10}, {50, 90}, 45};
  const ThesisMeasure m = MeasureEdgeThesis(Ramp(1), seg);  // 1 grey level per pixel does not exceed 1
  EXPECT_FALSE(m.ok);
  EXPECT_EQ(m.count, 0);
  EXPECT_FALSE(MeasureEdgeThesis(cv::Mat(100, 100, CV_8U, cv::Scalar(128)), seg).ok);
}

// The thesis's known weakness, documented: the threshold is in grey levels, so the same blur reads larger at
// higher contrast. The model fit does not move.
TEST(ThesisMethod, SameBlurHigherContrastReadsLarger) {
  EdgeSpec low, high;
  low.psf = high.psf = "gaussian";
  low.r_px = high.r_px = 6;
  low.black = 0.20, low.white = 0.30;
  high.black = 0.04, high.white = 0.80;
  const EdgeImage a = Render(low), b = Render(high);
  const ThesisMeasure ta = MeasureEdgeThesis(a.grey8, a.segment), tb = MeasureEdgeThesis(b.grey8, b.segment);
  ASSERT_TRUE(ta.ok && tb.ok);
  EXPECT_GT(tb.r_px, ta.r_px + 2);
  const ModelFit ma = MeasureEdgeModel(a.linear, a.segment), mb = MeasureEdgeModel(b.linear, b.segment);
  EXPECT_NEAR(ma.r_px, 6, LowContrastTolerance(6));  // 10 % contrast in 8 bits
  EXPECT_NEAR(mb.r_px, 6, Tolerance(6));
  std::cout << "thesis r at contrast 0.20->0.30: " << ta.r_px << ", at 0.04->0.80: " << tb.r_px
            << "; model r: " << ma.r_px << ", " << mb.r_px << " (true 6)\n";
}

// Side by side, for the log: true r vs the model fit vs the thesis count (7 degrees, noise 0.01, 8-bit sRGB).
// The model against the thesis's measure (section 4.3) on the same edges: the model within Tolerance at every radius,
// the thesis's count-of-steep-pixels reading high (its threshold of 1 grey level per pixel counts the blur's tails)
// and further from the truth than the model everywhere. Printed as a table too.
TEST(EdgeBlurReport, TrueVsModelVsThesis) {
  std::printf("%-9s %7s %9s %9s %9s %9s\n", "psf", "true r", "model r", "err", "thesis r", "err");
  for (const std::string psf : {"disc", "gaussian"})
    for (double r : kRadii) {
      EdgeSpec spec;
      spec.psf = psf;
      spec.r_px = r;
      spec.noise = 0.01;
      const EdgeImage img = Render(spec);
      const ModelFit fit = MeasureEdgeModel(img.linear, img.segment);
      const ThesisMeasure th = MeasureEdgeThesis(img.grey8, img.segment);
      std::printf("%-9s %7.2f %9.3f %+9.3f %9.1f %+9.1f\n", psf.c_str(), r, fit.r_px, fit.r_px - r, th.r_px,
                  th.r_px - r);
      EXPECT_NEAR(fit.r_px, r, Tolerance(r)) << psf << " r=" << r;
      ASSERT_TRUE(th.ok) << psf << " r=" << r;
      EXPECT_GE(th.r_px, r) << psf << " r=" << r << ": the thesis's measure reads high";
      EXPECT_LT(std::abs(fit.r_px - r), std::abs(th.r_px - r)) << psf << " r=" << r;
    }
}

}  // namespace
}  // namespace blurcue::calib

namespace blurcue::calib {
namespace {

// Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_n): a pixel's exact average of a smooth ESF.
void GaussLegendre(int n, std::vector<double>* x, std::vector<double>* w) {
  x->resize(n), w->resize(n);
  for (int i = 0; i < n; ++i) {
    double z = std::cos(kPi * (i + 0.75) / (n + 0.5)), dp = 0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = z;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
        p0 = p1, p1 = p2;
      }
      dp = n * (z * p1 - p0) / (z * z - 1);
      const double dz = p1 / dp;
      z -= dz;
      if (std::abs(dz) < 1e-15) break;
    }
    (*x)[i] = z, (*w)[i] = 2 / ((1 - z * z) * dp * dp);
  }
}

// Issue 25 (a): a Gaussian edge (std r / 2) at angle theta, each pixel the exact mean of erf over its unit square
// (16 x 16 Gauss-Legendre nodes; no supersampled grid, no closed form shared with the code), 8-bit sRGB, noise
// 0.002. The pixel's aperture across a diagonal edge is a trapezoid, not a box (the fit models it so); r is within
// 1 % at 0, 4, +-20, 30, 45 and 60 degrees for r 1.5-6 px, and within 2.5 % at the floor (0.7 px).
TEST(EdgeModel, SlantedGaussianEdgeWithExactPixelIntegrationWithinOnePercent) {
  std::vector<double> gx, gw;
  GaussLegendre(16, &gx, &gw);
  const int N = 160;
  const cv::Point2d c(0.5 * (N - 1), 0.5 * (N - 1));
  unsigned seed = 5;
  for (double r : {0.7, 1.5, 3.0, 6.0})
    for (double angle : {0.0, 4.0, 20.0, -20.0, 30.0, -30.0, 45.0, -45.0, 60.0}) {
      const double th = angle * kPi / 180, s = r / 2;
      const cv::Point2d t(std::cos(th), std::sin(th)), n(-t.y, t.x);
      cv::Mat linear(N, N, CV_32F);
      for (int y = 0; y < N; ++y)
        for (int x = 0; x < N; ++x) {
          const double d0 = (x - c.x) * n.x + (y - c.y) * n.y;
          double v = 0;
          if (d0 < -(6 * s + 1)) v = 0;
          else if (d0 > 6 * s + 1) v = 1;
          else
            for (int i = 0; i < 16; ++i)
              for (int j = 0; j < 16; ++j) {
                const double d = d0 + 0.5 * gx[i] * n.x + 0.5 * gx[j] * n.y;
                v += 0.25 * gw[i] * gw[j] * 0.5 * std::erfc(-d / (s * std::sqrt(2.0)));
              }
          linear.at<float>(y, x) = static_cast<float>(0.04 + 0.76 * v);
        }
      cv::Mat noise(linear.size(), CV_32F);
      cv::RNG rng(seed++);
      rng.fill(noise, cv::RNG::NORMAL, 0, 0.002);
      linear += noise;
      cv::min(cv::max(linear, 0.0), 1.0, linear);
      const EdgeSegment seg{c - 60.0 * t, c + 60.0 * t, 50};
      const ModelFit fit = MeasureEdgeModel(DecodeSrgb8(EncodeSrgb8(linear)), seg);
      EXPECT_TRUE(fit.ok) << "r " << r << " angle " << angle << ": " << Describe(fit);
      // At the floor (0.7 px) the fit reads 1-2 % high at every angle, a slight one included (4 degrees): not a
      // slant effect; the issue's 2 % median holds there, the 1 % this test asks elsewhere does not.
      EXPECT_NEAR(fit.r_px, r, (r < 1 ? 0.025 : 0.01) * r) << "angle " << angle << ": " << Describe(fit);
    }
}

// Issue 25 (a), the cause: squares seen as parallelograms (a board turned about the table normal). Cells 48 px a
// side, the crossing lines 50 degrees off the edge, Gaussian blur r = 4 px (cv::GaussianBlur of a sharp pattern on
// an 8x grid, area-averaged to pixels). The window is half the cell (24 px) across the edge; the section's central
// half starts 12 px from the corner, and a crossing line at 50 degrees leans 24 x cot 50 = 20 px along the edge at
// the window's reach: a rectangle's corners take in the next square. With the crossing lines given (as calibrate
// gives them) the window's ends follow them and r is within 1 %; without them it reads more than 1 % high.
TEST(EdgeModel, ParallelogramSquaresMeasuredAlongTheirCrossingLines) {
  const int S = 8, N = 200;
  const double L = 48, beta = 50 * kPi / 180, r = 4;
  for (double angle : {35.0, -40.0}) {
    const double th = angle * kPi / 180;
    const cv::Point2d t(std::cos(th), std::sin(th)), cr(std::cos(th + beta), std::sin(th + beta));
    const cv::Point2d o(0.5 * (N - 1) - 0.5 * L * (t.x + cr.x), 0.5 * (N - 1) - 0.5 * L * (t.y + cr.y));
    // p = o + L (u t + v cr): the square's colour is the parity of floor(u) + floor(v).
    const double det = t.x * cr.y - t.y * cr.x;
    cv::Mat fine(N * S, N * S, CV_32F);
    for (int j = 0; j < N * S; ++j)
      for (int i = 0; i < N * S; ++i) {
        const double px = (i + 0.5) / S - 0.5 - o.x, py = (j + 0.5) / S - 0.5 - o.y;
        const double u = (px * cr.y - py * cr.x) / det / L, v = (t.x * py - t.y * px) / det / L;
        const bool white = (static_cast<long>(std::floor(u)) + static_cast<long>(std::floor(v))) % 2 != 0;
        fine.at<float>(j, i) = white ? 0.8f : 0.04f;
      }
    cv::GaussianBlur(fine, fine, cv::Size(0, 0), 0.5 * r * S);
    cv::Mat linear;
    cv::resize(fine, linear, cv::Size(N, N), 0, 0, cv::INTER_AREA);
    EdgeSegment seg{o, o + L * t, 0.5 * L};
    const ModelFit rect = MeasureEdgeModel(linear, seg);
    seg.cross_a = seg.cross_b = cr;
    const ModelFit fit = MeasureEdgeModel(linear, seg);
    std::printf("parallelogram squares, edge at %+.0f deg: r %.4f with the crossing lines, %.4f in a rectangle "
                "(true %.1f)\n", angle, fit.r_px, rect.r_px, r);
    EXPECT_TRUE(fit.ok) << Describe(fit);
    EXPECT_NEAR(fit.r_px, r, 0.01 * r) << angle << ": " << Describe(fit);
    EXPECT_GT(rect.r_px, 1.01 * r) << angle << ": the rectangle no longer reads high; " << Describe(rect);
  }
}

}  // namespace
}  // namespace blurcue::calib
