// Ground-truth scenes checked against truth computed another way: the tilted-plane geometry by hand, the thin
// lens written out here, OpenCV's own board detector and projection, and edge moments measured in the image.
#include "synth/scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/image.h"
#include "synth/edge_profile_test_util.h"

namespace blurcue::synth {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The thesis set-up at an eighth of its resolution: quick to render, big enough for OpenCV to find the board.
SceneOptions Small() {
  SceneOptions o;
  o.camera = ThesisCamera().Resized(574, 382);
  o.supersample = 2;
  return o;
}

// A steep view of a small board with big squares, one blur radius everywhere: room for wide edge profiles.
SceneOptions FixedBlur(double r, Psf psf) {
  SceneOptions o;
  o.camera = ThesisCamera().Resized(600, 400);
  o.board = Board{5, 4, 25};
  o.tilt_deg = 75;
  o.edge1_u_mm = 300;
  o.fixed_r_px = r;
  o.psf = psf;
  o.supersample = r < 2 ? 4 : 2;
  return o;
}

cv::Mat Linear(const cv::Mat& bgr8) { return DecodeSrgb8(ToGrey8(bgr8)); }

cv::Point2d Project(const Scene& s, double x, double y) {
  std::vector<cv::Point3d> p{{x, y, 0}};
  std::vector<cv::Point2d> q;
  const auto k = s.camera.Intrinsics();
  cv::projectPoints(p, s.rvec, s.tvec, cv::Matx33d(k.data()), cv::noArray(), q);
  return q[0];
}

// The profile across edge `edge` at the middle of section `section`: linear light, averaged over the middle half
// of the section's columns, rows within half the distance to the neighbouring edges. At yaw 0 the edges of
// constant board y are image rows, so every column crosses the edge at the same row.
struct Profile {
  double edge_row = 0;       // where the pose puts the edge line (pixel centres at integers)
  int first_row = 0;         // image row of values[0]
  std::vector<double> values;
};

Profile EdgeProfile(const Scene& s, int edge, int section) {
  const cv::Mat lin = Linear(s.image);
  const double sq = s.board.square_mm, y = (edge - 1) * sq, xm = (section - 0.5) * sq;
  const cv::Point2d a = Project(s, (section - 1) * sq, y), c = Project(s, section * sq, y);
  EXPECT_NEAR(a.y, c.y, 1e-6) << "edges of constant board y must be image rows at yaw 0";
  const double spacing = std::min(Project(s, xm, y - sq).y - a.y, a.y - Project(s, xm, y + sq).y);
  const int half = static_cast<int>(spacing / 2) - 1;
  const int centre = static_cast<int>(std::lround(a.y));
  const int x0 = static_cast<int>(a.x + (c.x - a.x) / 4), x1 = static_cast<int>(c.x - (c.x - a.x) / 4);
  Profile p;
  p.edge_row = a.y;
  p.first_row = centre - half;
  for (int row = centre - half; row <= centre + half; ++row) {
    double sum = 0;
    for (int x = x0; x <= x1; ++x) sum += lin.at<float>(row, x);
    p.values.push_back(sum / (x1 - x0 + 1));
  }
  return p;
}

// The profile across the board line x = 50 mm between edges 2 and 3 (black left, white right) of FixedBlur's
// board shifted so that line lies (nearly) on the optical axis, where it is an image column.
Profile ColumnProfile(const Scene& s) {
  const cv::Mat lin = Linear(s.image);
  const cv::Point2d top = Project(s, 50, 50 - 25 / 4.0), bottom = Project(s, 50, 25 + 25 / 4.0);
  EXPECT_NEAR(top.x, bottom.x, 0.1);
  const int centre = static_cast<int>(std::lround(top.x)), half = 20;
  Profile p;
  p.edge_row = 0.5 * (top.x + bottom.x);
  p.first_row = centre - half;
  for (int col = centre - half; col <= centre + half; ++col) {
    double sum = 0;
    for (int y = static_cast<int>(top.y) + 1; y < static_cast<int>(bottom.y); ++y) sum += lin.at<float>(y, col);
    p.values.push_back(sum / (static_cast<int>(bottom.y) - static_cast<int>(top.y) - 1));
  }
  return p;
}

// Fraction of a unit step's light that a PSF of radius r has spread past offset t (the edge spread function).
double EdgeSpread(double t, double r, Psf psf) {
  if (r <= 0) return t >= 0 ? 1 : 0;
  if (psf == Psf::kGaussian) return 0.5 * std::erfc(-t / (r / 2) / std::sqrt(2.0));
  if (t <= -r) return 0;
  if (t >= r) return 1;
  return 0.5 + (t * std::sqrt(r * r - t * t) + r * r * std::asin(t / r)) / (kPi * r * r);
}

// What a camera pixel sees across an edge from `before` (rows above) to `after`: the edge spread function
// averaged over the pixel's area, written from scratch (numerical integration), independent of the renderer.
std::vector<double> ExpectedProfile(const Profile& p, double r, Psf psf, double before, double after) {
  std::vector<double> out;
  for (size_t i = 0; i < p.values.size(); ++i) {
    const double row = p.first_row + static_cast<double>(i);
    double sum = 0;
    constexpr int kSteps = 200;
    for (int k = 0; k < kSteps; ++k) sum += EdgeSpread(row - 0.5 + (k + 0.5) / kSteps - p.edge_row, r, psf);
    out.push_back(before + (after - before) * sum / kSteps);
  }
  return out;
}

double RmsDifference(const std::vector<double>& a, const std::vector<double>& b) {
  double sum = 0;
  for (size_t i = 0; i < a.size(); ++i) sum += (a[i] - b[i]) * (a[i] - b[i]);
  return std::sqrt(sum / a.size());
}

// Edge 3, section 3 of the 5x4 board in FixedBlur: black square above (farther), white below.
constexpr double kBlack = 0.04, kWhite = 0.80;

// The radius whose expected profile fits the rendered one best (golden-section search).
double FittedRadius(const Profile& p, Psf psf, double r_hi) {
  auto cost = [&](double r) { return RmsDifference(p.values, ExpectedProfile(p, r, psf, kBlack, kWhite)); };
  double lo = 0, hi = r_hi;
  const double g = (std::sqrt(5.0) - 1) / 2;
  for (int it = 0; it < 40; ++it) {
    const double a = hi - g * (hi - lo), b = lo + g * (hi - lo);
    (cost(a) < cost(b) ? hi : lo) = (cost(a) < cost(b) ? b : a);
  }
  return 0.5 * (lo + hi);
}

TEST(SynthScene, SectionDepthsFollowTheTiltedBoard) {
  const SceneOptions o = Small();
  const Scene s = RenderScene(o);
  ASSERT_EQ(s.sections.size(), 77u);
  const double c = std::cos(38 * kPi / 180);
  for (const SectionTruth& t : s.sections) {
    EXPECT_NEAR(t.u_mm, 342.3 + (t.edge - 1) * 25 * c, 1e-9) << "edge " << t.edge << " section " << t.section;
    // The pose says the same: the section midpoint's camera z.
    cv::Matx33d R;
    cv::Rodrigues(s.rvec, R);
    const cv::Vec3d p = R * cv::Vec3d((t.section - 0.5) * 25, (t.edge - 1) * 25, 0) + s.tvec;
    EXPECT_NEAR(p[2], t.u_mm, 1e-9);
  }
  EXPECT_EQ(s.sections.front().edge, 1);
  EXPECT_EQ(s.sections[7].edge, 2);  // edge-major
  EXPECT_EQ(s.sections[7].section, 1);
  EXPECT_NEAR(s.focus_mm, 342.3, 1e-9);
}

TEST(SynthScene, RadiusIsTheThinLensWrittenOut) {
  SceneOptions o = Small();
  o.focus_mm = 300;
  o.blur_gain = 1.5;
  const Scene s = RenderScene(o);
  const double f = 21, D = 21 / 5.6, pitch = 23.4 / 574;
  const double v0 = 1 / (1 / f - 1 / 300.0);
  for (const SectionTruth& t : s.sections) {
    const double v = 1 / (1 / f - 1 / t.u_mm);
    const double R = D / 2 * std::abs(v0 - v) / v;  // blur-circle radius on the sensor
    EXPECT_NEAR(t.r_px, 1.5 * R / pitch, 1e-9);
  }
  EXPECT_GT(s.sections.back().r_px, s.sections.front().r_px);
}

TEST(SynthScene, OpenCvFindsTheBoardWhereThePoseSays) {
  SceneOptions o = Small();
  o.noise_std = 0.003;
  const Scene s = RenderScene(o);
  std::vector<cv::Point2f> corners;
  const cv::Size pattern(s.board.InnerCornersX(), s.board.InnerCornersY());
  const cv::Mat grey = ToGrey8(s.image);
  ASSERT_TRUE(cv::findChessboardCornersSB(grey, pattern, corners));
  ASSERT_EQ(corners.size(), 54u);
  cv::cornerSubPix(grey, corners, cv::Size(3, 3), cv::Size(-1, -1), {cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-4});
  for (const cv::Point2f& c : corners) {
    double best = 1e9;
    for (int i = 1; i < s.board.cols; ++i)
      for (int j = 1; j < s.board.rows; ++j)
        best = std::min(best, cv::norm(Project(s, i * 25.0, j * 25.0) - cv::Point2d(c)));
    EXPECT_LT(best, 0.3) << c;
  }
  EXPECT_FALSE(cv::findChessboardCornersSB(ToGrey8(s.image_no_board), pattern, corners));
}

TEST(SynthScene, TurnedAndShiftedBoardIsWhereThePoseSays) {
  SceneOptions o = Small();
  o.yaw_deg = 12;
  o.lateral_mm = 20;
  o.edge1_u_mm = 400;
  const Scene s = RenderScene(o);
  std::vector<cv::Point2f> corners;
  const cv::Mat grey = ToGrey8(s.image);
  ASSERT_TRUE(cv::findChessboardCornersSB(grey, cv::Size(6, 9), corners));
  // The detector's own estimate leans ~0.1 px on slanted lines; its usual refinement removes that.
  cv::cornerSubPix(grey, corners, cv::Size(3, 3), cv::Size(-1, -1), {cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-4});
  for (const cv::Point2f& c : corners) {
    double best = 1e9;
    for (int i = 1; i < 7; ++i)
      for (int j = 1; j < 10; ++j) best = std::min(best, cv::norm(Project(s, i * 25.0, j * 25.0) - cv::Point2d(c)));
    EXPECT_LT(best, 0.3) << c;
  }
  // Edge 1's midpoint stays at the requested depth; the turned edge is deeper at one end than the other.
  cv::Matx33d R;
  cv::Rodrigues(s.rvec, R);
  EXPECT_NEAR((R * cv::Vec3d(87.5, 0, 0) + s.tvec)[2], 400, 1e-9);
  EXPECT_NEAR(s.sections[6].u_mm - s.sections[0].u_mm, 6 * 25 * std::sin(12 * kPi / 180) * std::cos(38 * kPi / 180), 1e-9);
}

// A lens floor: the truth is the defocus and floor kernels' second moments added (r^2 = R^2 + 4 f^2 for the floor
// asked, within the taps' discretisation), and the rendered edge's own second moment (the differenced profile,
// less the pixel's area and the difference's unit box) finds it, for a disc and a Gaussian under the floor.
TEST(SynthScene, FloorAddsItsSecondMomentToTheTruthAndTheImage) {
  for (Psf psf : {Psf::kDisc, Psf::kGaussian}) {
    SceneOptions o = FixedBlur(3, psf);
    o.floor_sigma_px = 0.8;
    const Scene s = RenderScene(o);
    const SectionTruth& t = s.sections[2 * 5 + 2];  // edge 3, section 3
    EXPECT_NEAR(t.defocus_r_px, 3, 1e-12);
    EXPECT_NEAR(t.r_px, std::hypot(3, 1.6), 0.01 * std::hypot(3, 1.6));
    const Profile p = EdgeProfile(s, 3, 3);
    double m0 = 0, m1 = 0, m2 = 0;
    for (size_t i = 0; i + 1 < p.values.size(); ++i) {
      const double g = p.values[i + 1] - p.values[i], x = i + 0.5;
      m0 += g, m1 += g * x, m2 += g * x * x;
    }
    const double var = m2 / m0 - (m1 / m0) * (m1 / m0);
    EXPECT_NEAR(2 * std::sqrt(var - 1.0 / 6), t.r_px, 0.03 * t.r_px) << "variance " << var;
    // The whole view's range has the floor in it: nothing is sharper than it (it printed the defocus alone, 0 px).
    const double floor_r = 2 * s.truth["floor_sigma_applied_px"].get<double>();
    EXPECT_NEAR(floor_r, 1.6, 0.05);
    EXPECT_GE(s.truth["r_range_px"][0].get<double>(), floor_r);
    for (const SectionTruth& any : s.sections) EXPECT_GE(any.r_px, s.truth["r_range_px"][0].get<double>() - 1e-9);
  }
}

// A filter on the sampled image: truth.json holds its taps and their second moment, computed here from the Gaussian
// written out (not from synth's arrays), every section's r_px adds it, and the image's edge profile carries it.
TEST(SynthScene, PostFilterAddsItsTapsSecondMomentToTheTruthAndTheImage) {
  const double sigma = 0.8, amount = 0.4;
  double g_sum = 0, g_second = 0;
  for (int k = -4; k <= 4; ++k) {  // 4 sigma = 3.2 px: taps out to 4
    const double g = std::exp(-0.5 * k * k / (sigma * sigma));
    g_sum += g, g_second += k * k * g;
  }
  const double gauss_var = g_second / g_sum;
  for (const PostFilter kind : {PostFilter::kGaussian, PostFilter::kSharpen}) {
    SceneOptions o = FixedBlur(3, Psf::kGaussian);
    o.post_filter = {kind, sigma, kind == PostFilter::kSharpen ? amount : 0};
    const Scene s = RenderScene(o);
    const double var = kind == PostFilter::kGaussian ? gauss_var : -amount * gauss_var;
    EXPECT_NEAR(s.truth["post_filter"]["variance_px2"].get<double>(), var, 1e-6);
    EXPECT_EQ(s.truth["post_filter"]["taps"].size(), 9u);
    EXPECT_EQ(s.truth["options"]["post_filter"], Name(kind));
    const SectionTruth& t = s.sections[2 * 5 + 2];  // edge 3, section 3
    EXPECT_NEAR(t.r_optical_px, 3, 0.01 * 3);
    EXPECT_NEAR(t.r_px, std::sqrt(t.r_optical_px * t.r_optical_px + 4 * var), 1e-6);  // taps applied as float
    const Profile p = EdgeProfile(s, 3, 3);
    double m0 = 0, m1 = 0, m2 = 0;
    for (size_t i = 0; i + 1 < p.values.size(); ++i) {
      const double g = p.values[i + 1] - p.values[i], x = i + 0.5;
      m0 += g, m1 += g * x, m2 += g * x * x;
    }
    const double measured = m2 / m0 - (m1 / m0) * (m1 / m0);
    EXPECT_NEAR(2 * std::sqrt(measured - 1.0 / 6), t.r_px, 0.03 * t.r_px) << Name(kind) << " variance " << measured;
  }
  // Without a filter truth.json has no post_filter block and r_px is the optics' alone.
  const Scene plain = RenderScene(FixedBlur(3, Psf::kGaussian));
  EXPECT_FALSE(plain.truth.contains("post_filter"));
  EXPECT_DOUBLE_EQ(plain.sections[0].r_px, plain.sections[0].r_optical_px);
}

// The filter's word and its options are checked where they are read.
TEST(SynthScene, PostFilterWordsAndOptionsAreChecked) {
  EXPECT_EQ(ParsePostFilter("sharpen"), PostFilter::kSharpen);
  EXPECT_THROW(ParsePostFilter("unsharp"), Error);
  SceneOptions o = Small();
  o.post_filter = {PostFilter::kGaussian, 0, 0};
  EXPECT_THROW(CheckSceneOptions(o), Error);
  o.post_filter = {PostFilter::kSharpen, 0.6, 0};
  EXPECT_THROW(CheckSceneOptions(o), Error);
}

// Vignetting darkens the corners by the fraction asked and leaves the centre as it was.
TEST(SynthScene, VignettingDarkensTheCornersByTheFractionAsked) {
  SceneOptions o = FixedBlur(1, Psf::kDisc);
  const cv::Mat plain = Linear(RenderScene(o).image_no_board);
  o.vignetting = 0.35;
  const cv::Mat vign = Linear(RenderScene(o).image_no_board);
  const auto ratio = [&](int x, int y) {
    const cv::Rect box(x - 2, y - 2, 5, 5);
    return cv::mean(vign(box))[0] / cv::mean(plain(box))[0];
  };
  EXPECT_NEAR(ratio(300, 200), 1.0, 0.01);
  EXPECT_NEAR(ratio(2, 2), 0.65, 0.02);
  EXPECT_NEAR(ratio(597, 397), 0.65, 0.02);
}

struct BlurCase {
  double r;
  Psf psf;
};
void PrintTo(const BlurCase& c, std::ostream* os) { *os << (c.psf == Psf::kDisc ? "disc" : "gaussian") << " r=" << c.r; }

class RenderedBlur : public ::testing::TestWithParam<BlurCase> {};

// The rendered edge is the requested PSF's edge spread averaged over the pixel: point by point within 1 % of the
// step, and the best-fitting radius within 3 % (plus 0.02 px) of the requested one.
TEST_P(RenderedBlur, EdgeProfileIsTheRequestedPsfOverThePixel) {
  const BlurCase c = GetParam();
  const Scene s = RenderScene(FixedBlur(c.r, c.psf));
  const Profile p = EdgeProfile(s, 3, 3);
  const std::vector<double> expected = ExpectedProfile(p, c.r, c.psf, kBlack, kWhite);
  EXPECT_LT(RmsDifference(p.values, expected), 0.01 * (kWhite - kBlack));
  // A small blur must still be told from none (and none from a small one): the profile sits at least 3 x nearer its
  // own radius's profile than that of the neighbouring case (r = 0 against 0.3, and 0.3 against 0).
  if (c.r <= 0.3) {
    const double other = c.r > 0 ? 0.0 : 0.3;
    const double own = RmsDifference(p.values, expected);
    const double near = RmsDifference(p.values, ExpectedProfile(p, other, c.psf, kBlack, kWhite));
    EXPECT_GT(near, 3 * own) << "r = " << c.r << " against r = " << other;
  }
  // Below ~0.3 px the blur hardly leaves the pixel the edge falls in, so no profile can tell the radius.
  if (c.r >= 0.3) {
    EXPECT_NEAR(FittedRadius(p, c.psf, 2 * c.r + 2), c.r, 0.03 * c.r + 0.02);
  }
  // Second moment, the DESIGN.md definition: the differenced profile's variance is r^2/4 plus the pixel's area
  // (1/12 px^2) plus the difference's own unit box (1/12 px^2). From a pixel of blur up; below that it depends on
  // where the edge falls within its pixel.
  if (c.r >= 1) {
    double m0 = 0, m1 = 0, m2 = 0;
    for (size_t i = 0; i + 1 < p.values.size(); ++i) {
      const double g = p.values[i + 1] - p.values[i], t = i + 0.5;
      m0 += g, m1 += g * t, m2 += g * t * t;
    }
    const double var = m2 / m0 - (m1 / m0) * (m1 / m0);
    EXPECT_NEAR(2 * std::sqrt(var - 1.0 / 6), c.r, 0.03 * c.r) << "variance " << var;
  }
}

INSTANTIATE_TEST_SUITE_P(SynthScene, RenderedBlur,
                         ::testing::Values(BlurCase{0, Psf::kDisc}, BlurCase{0.3, Psf::kDisc},
                                           BlurCase{0.6, Psf::kGaussian}, BlurCase{1, Psf::kDisc},
                                           BlurCase{1, Psf::kGaussian}, BlurCase{3, Psf::kDisc},
                                           BlurCase{3, Psf::kGaussian}, BlurCase{8, Psf::kDisc},
                                           BlurCase{8, Psf::kGaussian}),
                         // Readable test names: disc_r0_3, gaussian_r8, ...
                         [](const ::testing::TestParamInfo<BlurCase>& info) {
                           std::string r = std::to_string(info.param.r);
                           r.erase(r.find_last_not_of('0') + 1);
                           if (r.back() == '.') r.pop_back();
                           for (char& ch : r) ch = ch == '.' ? '_' : ch;
                           return std::string(info.param.psf == Psf::kDisc ? "disc" : "gaussian") + "_r" + r;
                         });

// The disc is as wide across columns as across rows (isotropic second moment), small kernels included.
TEST(SynthScene, VerticalEdgesBlurLikeHorizontalOnes) {
  for (double r : {0.6, 2.0}) {
    SceneOptions o = FixedBlur(r, Psf::kDisc);
    o.lateral_mm = 12.2;  // the line 0.3 mm off the axis: nearly an image column, off a pixel centre
    const Profile p = ColumnProfile(RenderScene(o));
    EXPECT_LT(RmsDifference(p.values, ExpectedProfile(p, r, Psf::kDisc, kBlack, kWhite)), 0.01 * (kWhite - kBlack));
    EXPECT_NEAR(FittedRadius(p, Psf::kDisc, 2 * r + 2), r, 0.03 * r + 0.02) << "r " << r;
  }
}

TEST(SynthScene, BlurKeepsTheLight) {
  const Scene sharp = RenderScene(FixedBlur(0, Psf::kDisc));
  const Scene blurred = RenderScene(FixedBlur(6, Psf::kDisc));
  const cv::Mat a = Linear(sharp.image), b = Linear(blurred.image);
  // A large area holding whole squares and edges: the mean is unchanged.
  const cv::Rect area(100, 80, 400, 240);
  EXPECT_NEAR(cv::mean(b(area))[0], cv::mean(a(area))[0], 0.003);
  // The middle of a white square (column 1, row 2 of a 5x4 board) is still exactly white.
  const cv::Point2d centre = Project(blurred, 1.5 * 25, 2.5 * 25);
  const cv::Rect mid(int(centre.x) - 5, int(centre.y) - 5, 11, 11);
  EXPECT_NEAR(cv::mean(b(mid))[0], 0.80, 0.005);
  EXPECT_NEAR(cv::mean(a(mid))[0], 0.80, 0.005);
}

TEST(SynthScene, BlurGrowsWithDistanceBeyondFocus) {
  const Scene s = RenderScene(Small());
  EXPECT_NEAR(s.sections.front().r_px, 0, 1e-9);  // focused on edge 1
  for (size_t i = 7; i < s.sections.size(); ++i) EXPECT_GT(s.sections[i].r_px, s.sections[i - 7].r_px);
  // Rendered: each edge's profile fits the thin lens's radius at that depth (black beyond, white nearer).
  // (Edges nearer than 6 blur by under half a pixel: a blur that stays inside one pixel does not change it.)
  double previous = 0;
  for (int edge : {6, 8, 10}) {
    const double truth = s.sections[(edge - 1) * 7 + 3].r_px;
    const double fitted = FittedRadius(EdgeProfile(s, edge, 4), Psf::kDisc, 4);
    EXPECT_NEAR(fitted, truth, 0.05 + 0.03 * truth) << "edge " << edge;
    EXPECT_GT(fitted, previous);
    previous = fitted;
  }
}

TEST(SynthScene, SameSeedSameBytes) {
  SceneOptions o = Small();
  o.noise_std = 0.01;
  o.flaws = 4;
  o.jpeg_quality = 80;
  const Scene a = RenderScene(o), b = RenderScene(o);
  EXPECT_EQ(cv::norm(a.image, b.image, cv::NORM_INF), 0);
  EXPECT_EQ(cv::norm(a.image_no_board, b.image_no_board, cv::NORM_INF), 0);
  EXPECT_EQ(a.truth.dump(), b.truth.dump());
}

TEST(SynthScene, DifferentSeedWithNoiseDifferentImage) {
  SceneOptions o = Small();
  o.noise_std = 0.01;
  const Scene a = RenderScene(o);
  o.seed = 2;
  const Scene b = RenderScene(o);
  EXPECT_GT(cv::norm(a.image, b.image, cv::NORM_L1) / a.image.total(), 1.0);
}

TEST(SynthScene, FlawsAreRecordedAndDarkenTheirSections) {
  SceneOptions o = Small();
  o.camera = ThesisCamera().Resized(1148, 764);  // spots of ~3 mm need a few pixels
  const Scene clean = RenderScene(o);
  o.flaws = 5;
  const Scene flawed = RenderScene(o);
  ASSERT_EQ(flawed.truth["flaws"].size(), 5u);
  int flawed_sections = 0;
  cv::Mat clean_g = ToGrey8(clean.image), flawed_g = ToGrey8(flawed.image), diff;
  cv::subtract(clean_g, flawed_g, diff, cv::noArray(), CV_32S);
  double min_diff;
  cv::minMaxLoc(diff, &min_diff);
  EXPECT_GE(min_diff, -1) << "flaws only darken";
  for (const SectionTruth& t : flawed.sections) {
    if (!t.flawed) continue;
    ++flawed_sections;
    // The band around the section (half-way to the neighbouring edges) holds clearly darker pixels.
    const cv::Point2d a = Project(flawed, (t.section - 1) * 25.0, (t.edge - 1.5) * 25.0);
    const cv::Point2d b = Project(flawed, t.section * 25.0, (t.edge - 0.5) * 25.0);
    cv::Rect band(cv::Point(int(std::min(a.x, b.x)), int(std::min(a.y, b.y))),
                  cv::Point(int(std::max(a.x, b.x)) + 1, int(std::max(a.y, b.y)) + 1));
    band &= cv::Rect(0, 0, diff.cols, diff.rows);
    double max_diff;
    cv::minMaxLoc(diff(band), nullptr, &max_diff);
    EXPECT_GT(max_diff, 25) << "edge " << t.edge << " section " << t.section;
  }
  EXPECT_GE(flawed_sections, 1);
  EXPECT_LE(flawed_sections, 10);
  for (const SectionTruth& t : clean.sections) EXPECT_FALSE(t.flawed);
}

TEST(SynthScene, TruthJsonHoldsWhatCalibrationReads) {
  const Scene s = RenderScene(Small());
  for (const char* key : {"options", "camera", "board", "pose", "focus_mm", "aperture_mm", "pixel_pitch_mm", "sections"})
    EXPECT_TRUE(s.truth.contains(key)) << key;
  EXPECT_EQ(s.truth["pose"]["rvec"].size(), 3u);
  EXPECT_EQ(s.truth["pose"]["rotation"].size(), 3u);
  EXPECT_EQ(s.truth["sections"].size(), 77u);
  EXPECT_EQ(s.truth["sections"][8]["edge"], 2);
  EXPECT_EQ(s.truth["sections"][8]["section"], 2);
}

TEST(SynthScene, ImpossibleOptionsNameTheOption) {
  auto expect = [](SceneOptions o, const std::string& name) {
    try {
      RenderScene(o);
      ADD_FAILURE() << "no error for " << name;
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::kInput);
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  };
  SceneOptions o = Small();
  o.focus_mm = 21;
  expect(o, "focus_mm");
  o = Small();
  o.edge1_u_mm = 120;  // too near: the board overflows the view
  expect(o, "edge1_u_mm");
  o = Small();
  o.tilt_deg = -5;
  expect(o, "tilt_deg");
  o = Small();
  o.fixed_r_px = -1;
  expect(o, "fixed_r_px");
}

// Through a barrel lens (k1 = -0.3) the photo's blur across an edge is the applied blur times the stretch there.
// Checked on the image by a plain numeric method that shares nothing with the renderer or core/distortion: the
// edge's place and normal in the photo from cv::projectPoints (normal by finite differences), the pixels binned
// by signed distance along that normal, the binned profile differenced, its variance less the pixel's 1/12.
TEST(SynthScene, DistortedBlurIsTheAppliedBlurTimesTheStretchAcrossTheEdge) {
  SceneOptions o = FixedBlur(2.5, Psf::kDisc);
  o.board = Board{5, 8, 25};
  o.tilt_deg = 80;
  o.yaw_deg = 10;  // no edge along a pixel row: the bins across it fill at every 0.1 px
  o.edge1_u_mm = 275;
  o.camera.dist_coeffs = {-0.3, 0, 0, 0};
  const Scene s = RenderScene(o);
  const cv::Mat lin = Linear(s.image);
  const auto k = s.camera.Intrinsics();
  auto project = [&](double x, double y) {
    std::vector<cv::Point2d> q;
    cv::projectPoints(std::vector<cv::Point3d>{{x, y, 0}}, s.rvec, s.tvec, cv::Matx33d(k.data()), s.camera.dist_coeffs,
                      q);
    return q[0];
  };
  double stretch_min = 1;
  for (int edge : {2, 5, 8}) {
    for (int section : {1, 3, 5}) {
      const SectionTruth& t = s.sections[(edge - 1) * 5 + (section - 1)];
      const double sq = s.board.square_mm, y = (edge - 1) * sq, x = (section - 0.5) * sq;
      const cv::Point2d m = project(x, y), along = project(x + 0.01, y) - project(x - 0.01, y);
      cv::Point2d tan = along / cv::norm(along), n(-tan.y, tan.x);
      const double measured = synth::testing::PhotoRadiusAcross(lin, m, n);
      EXPECT_NEAR(measured, t.r_px, 0.01 * t.r_px) << "edge " << edge << " section " << section << ", stretch "
                                                    << t.stretch << ", ideal " << t.r_ideal_px;
      stretch_min = std::min(stretch_min, t.stretch);
    }
  }
  // The check has teeth: the stretch moves r by several times the 1 % tolerance somewhere.
  EXPECT_LT(stretch_min, 0.95);
}

TEST(SynthScene, LowTiltShowsTheBackWall) {
  SceneOptions o = Small();
  o.tilt_deg = 15;  // the view reaches above the horizon
  o.edge1_u_mm = 600;
  const Scene s = RenderScene(o);
  EXPECT_EQ(s.sections.size(), 77u);
  EXPECT_GT(s.truth["r_range_px"][1].get<double>(), s.sections.back().r_px);
  // The top rows see the pale wall (0.55), the bottom rows the table (0.30).
  const cv::Mat lin = Linear(s.image_no_board);
  EXPECT_NEAR(cv::mean(lin.rowRange(0, 5))[0], 0.55, 0.03);
  EXPECT_NEAR(cv::mean(lin.rowRange(lin.rows - 5, lin.rows))[0], 0.30, 0.03);
}

}  // namespace
}  // namespace blurcue::synth
