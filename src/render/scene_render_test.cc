// GL tests (label "gl"): virtual objects in a calibrated scene, on Mesa's llvmpipe through EGL, no display.
#include "render/scene_render.h"

#include <gtest/gtest.h>

#include <cmath>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "render/blur.h"
#include "core/error.h"
#include "render/gl_context.h"
#include "render/gl_objects.h"

namespace blurcue::render {

using scene::Footprint;
using scene::SurfaceTexture;
using scene::VirtualObject;

namespace {

// The thesis's view, built by hand: camera pitched down 38 deg, looking at the board's centre from 440 mm.
struct View {
  Camera camera = ThesisCamera().Resized(1148, 764);
  cv::Vec3d rvec, tvec;
  View() {
    const double a = 38 * M_PI / 180, s = std::sin(a), c = std::cos(a);
    const cv::Matx33d r(1, 0, 0, 0, -s, -c, 0, c, -s);  // rows: camera x, y, z in board coordinates
    const cv::Vec3d forward(0, c, -s), target(87.5, 125, 0);
    const cv::Vec3d centre = target - 440.0 * forward;
    cv::Rodrigues(r, rvec);
    tvec = -(r * centre);
  }
};

class SceneRenderTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { context_ = GlContext::CreateOffscreen().release(); }
  static void TearDownTestSuite() { delete context_; }
  static GlContext* context_;
};
GlContext* SceneRenderTest::context_ = nullptr;

VirtualObject Ball(double y_mm) {
  VirtualObject o;
  o.kind = VirtualObject::Kind::kBall;
  o.size_mm = 10;
  o.center_board_mm = {87.5, y_mm, 10};
  cv::Mat texture(64, 128, CV_8UC3, cv::Scalar(200, 200, 200));
  texture(cv::Rect(0, 0, 64, 32)).setTo(cv::Scalar(30, 30, 30));
  o.texture = SurfaceTexture(texture);
  return o;
}

// A flat card of uniform grey (sRGB `grey`) lying on the table at the board's centre.
VirtualObject FlatCard(double size_mm, int grey) {
  VirtualObject card;
  card.kind = VirtualObject::Kind::kCard;
  card.size_mm = size_mm;
  card.center_board_mm = {87.5, 125, 0};
  card.texture = SurfaceTexture(cv::Mat(32, 32, CV_8UC3, cv::Scalar::all(grey)));
  return card;
}

cv::Point2d AlphaCentroid(const Layer& layer, double* area) {
  cv::Mat alpha;
  cv::extractChannel(layer.bgra, alpha, 3);
  const cv::Moments m = cv::moments(alpha);
  *area = m.m00;
  return {layer.roi.x + m.m10 / m.m00 - 0.5, layer.roi.y + m.m01 / m.m00 - 0.5};
}

// Textures are kept by their SurfaceTexture's identity, not by the image's address: a new texture whose pixels land
// where a freed one's were is drawn as itself, and copies of one SurfaceTexture share its id.
TEST_F(SceneRenderTest, TexturesAreKeptByIdentityNotByAddress) {
  const View v;
  SceneRenderer renderer(v.camera, v.rvec, v.tvec);
  auto mean_blue = [&](const VirtualObject& card) { return cv::mean(renderer.Draw(card, 2).bgra)[0]; };
  VirtualObject card = FlatCard(50, 0);
  cv::Mat pixels(32, 32, CV_8UC3, cv::Scalar::all(40));
  card.texture = SurfaceTexture(pixels);
  const double dark = mean_blue(card);
  pixels.setTo(cv::Scalar::all(220));  // the same pixels, the same address: another image now
  card.texture = SurfaceTexture(pixels);
  const double light = mean_blue(card);
  EXPECT_GT(light, 5 * dark) << dark << " vs " << light << ": the renderer drew the old texture for a new one";
  const SurfaceTexture a(pixels), copy = a, b(pixels);
  EXPECT_EQ(copy.id(), a.id());
  EXPECT_NE(b.id(), a.id());
}

// Layers side by side in one target (the compositor's atlas): a layer past the room reserved is refused, not drawn
// after growing the target - which would silently drop the layers drawn into it before.
TEST_F(SceneRenderTest, ALayerPastItsTargetsReservedRoomIsRefused) {
  const View v;
  SceneRenderer renderer(v.camera, v.rvec, v.tvec);
  const VirtualObject ball = Ball(150);
  const cv::Rect roi = renderer.LayerRoi(ball, 2);
  ASSERT_FALSE(roi.empty());
  GrowingTarget atlas;
  atlas.Reserve(2 * roi.width, roi.height);  // room for two layers in a row
  EXPECT_NO_THROW(renderer.DrawLayerAt(ball, roi, atlas, nullptr, {0, 0}));
  const cv::Mat first = atlas.Download(roi.width, roi.height);
  try {
    renderer.DrawLayerAt(ball, roi, atlas, nullptr, {0, roi.height});  // below the room
    ADD_FAILURE() << "drawn past the reserved room";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInternal) << e.what();
  }
  EXPECT_EQ(cv::norm(atlas.Download(roi.width, roi.height), first, cv::NORM_INF), 0)
      << "the first layer was lost";
}

TEST_F(SceneRenderTest, BallLandsWhereThePoseProjectsIt) {
  const View v;
  SceneRenderer renderer(v.camera, v.rvec, v.tvec);
  for (double y : {0.0, 150.0, 250.0}) {
    const VirtualObject ball = Ball(y);
    const Layer layer = renderer.Draw(ball, 2);
    std::vector<cv::Point2d> px;
    cv::projectPoints(std::vector<cv::Point3d>{cv::Point3d(ball.center_board_mm)}, v.rvec, v.tvec,
                      cv::Matx33d(v.camera.Intrinsics().data()), cv::noArray(), px);
    double area = 0;
    const cv::Point2d c = AlphaCentroid(layer, &area);
    // The silhouette's centroid sits within a pixel of the projected centre (perspective shifts it slightly).
    EXPECT_NEAR(c.x, px[0].x, 1.0) << "y = " << y;
    EXPECT_NEAR(c.y, px[0].y, 1.0) << "y = " << y;
  }
}

// Drawn by GL, a standing, turned, raised card covers the polygon its hand-made corners project to: the same area
// within 2 % and the same centroid within a quarter of a pixel, at three turns.
TEST_F(SceneRenderTest, AStandingTurnedCardCoversItsProjectedCorners) {
  const View v;
  SceneRenderer renderer(v.camera, v.rvec, v.tvec);
  for (double turn : {0.0, 30.0, -60.0}) {
    VirtualObject card = FlatCard(80, 200);
    card.card_height_mm = 60;
    card.standing = true;
    card.rotation_deg = turn;
    card.center_board_mm = {87.5, 125, 15 + 30};  // lowest edge 15 mm above the table
    const double a = turn * M_PI / 180;
    const cv::Vec3d u(40 * std::cos(a), 40 * std::sin(a), 0), up(0, 0, 30), c = card.center_board_mm;
    std::vector<cv::Point3d> hand;
    for (const cv::Vec3d& p : {c - u + up, c + u + up, c + u - up, c - u - up}) hand.emplace_back(p[0], p[1], p[2]);
    std::vector<cv::Point2d> px;
    cv::projectPoints(hand, v.rvec, v.tvec, cv::Matx33d(v.camera.Intrinsics().data()), cv::noArray(), px);
    std::vector<cv::Point2f> polygon(px.begin(), px.end());
    const cv::Moments m = cv::moments(polygon);
    // The layer's coverage (alpha, 0-1) as a density over pixel centres, which sit at integer image coordinates as
    // projectPoints has them.
    const Layer layer = renderer.Draw(card, 2);
    cv::Mat alpha;
    cv::extractChannel(layer.bgra, alpha, 3);
    const cv::Moments drawn = cv::moments(alpha);
    EXPECT_NEAR(drawn.m00, std::abs(m.m00), 0.02 * std::abs(m.m00)) << turn;
    EXPECT_NEAR(layer.roi.x + drawn.m10 / drawn.m00, m.m10 / m.m00, 0.25) << turn;
    EXPECT_NEAR(layer.roi.y + drawn.m01 / drawn.m00, m.m01 / m.m00, 0.25) << turn;
  }
}

TEST_F(SceneRenderTest, BallShrinksWithDistance) {
  const View v;
  SceneRenderer renderer(v.camera, v.rvec, v.tvec);
  double near_area = 0, far_area = 0;
  AlphaCentroid(renderer.Draw(Ball(0), 2), &near_area);
  AlphaCentroid(renderer.Draw(Ball(250), 2), &far_area);
  const double z_near = renderer.Measure(Ball(0)).z_center_mm, z_far = renderer.Measure(Ball(250)).z_center_mm;
  // Apparent area of a sphere goes as 1 / depth^2.
  EXPECT_NEAR(far_area / near_area, (z_near * z_near) / (z_far * z_far), 0.05);
}

TEST_F(SceneRenderTest, LayerCoversOnlyTheObjectAndItsMargin) {
  const View v;
  SceneRenderer renderer(v.camera, v.rvec, v.tvec);
  const VirtualObject ball = Ball(150);
  const Footprint f = renderer.Measure(ball);
  const Layer layer = renderer.Draw(ball, 7);
  EXPECT_EQ(layer.roi.width, f.bounds.width + 14);
  EXPECT_LT(layer.roi.area(), 0.01 * v.camera.image_width_px * v.camera.image_height_px);
  // Nothing is drawn in the margin.
  cv::Mat alpha;
  cv::extractChannel(layer.bgra, alpha, 3);
  EXPECT_EQ(cv::countNonZero(alpha.rowRange(0, 6)), 0);
  EXPECT_EQ(cv::countNonZero(alpha.colRange(0, 6)), 0);
}

TEST_F(SceneRenderTest, BlurringTheLayerKeepsTheObjectsLight) {
  const View v;
  SceneRenderer renderer(v.camera, v.rvec, v.tvec);
  GlBlur gl;
  const VirtualObject ball = Ball(150);
  for (const char* method : {"gaussian", "disc"}) {
    Layer layer = renderer.Draw(ball, KernelMarginPx(method, 6) + 1);
    const cv::Scalar before = cv::sum(layer.bgra);
    Layer cpu = layer;
    BlurLayer(layer, method, 6, &gl);
    BlurLayer(cpu, method, 6, nullptr);
    const cv::Scalar after = cv::sum(layer.bgra);
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(after[c], before[c], 1e-3 * before[c] + 1e-3) << method;
    cv::Mat diff;
    cv::absdiff(layer.bgra, cpu.bgra, diff);
    double max = 0;
    cv::minMaxLoc(diff.reshape(1), nullptr, &max);
    EXPECT_LE(max, 3.0 / 255) << method;
  }
}

TEST(Composite, OverIsPremultipliedAndLinear) {
  cv::Mat background(4, 4, CV_32FC3, cv::Scalar(0.5, 0.5, 0.5));
  Layer layer{cv::Rect(1, 1, 2, 2), cv::Mat(2, 2, CV_32FC4, cv::Scalar(0.2, 0.2, 0.2, 0.25)), cv::Mat()};
  CompositeOver(background, layer);
  EXPECT_FLOAT_EQ(background.at<cv::Vec3f>(1, 1)[0], 0.2f + 0.75f * 0.5f);
  EXPECT_FLOAT_EQ(background.at<cv::Vec3f>(0, 0)[0], 0.5f);
}

TEST_F(SceneRenderTest, WhiteBalanceScalesEachChannelInLinearLight) {
  // A flat white card (texture sRGB 200 = 0.578 linear) drawn plain and with gains (red 1, green 0.5, blue 2):
  // covered pixels keep their coverage and carry the texture's linear value times each gain.
  const View v;
  SceneRenderer renderer(v.camera, v.rvec, v.tvec);
  VirtualObject card = FlatCard(50, 200);
  const Layer plain = renderer.Draw(card, 1);
  card.white_balance = {1, 0.5, 2};
  const Layer balanced = renderer.Draw(card, 1);
  const double linear = std::pow((200 / 255.0 + 0.055) / 1.055, 2.4);
  int inside = 0;
  for (int y = 0; y < plain.bgra.rows; ++y)
    for (int x = 0; x < plain.bgra.cols; ++x) {
      const cv::Vec4f p = plain.bgra.at<cv::Vec4f>(y, x), b = balanced.bgra.at<cv::Vec4f>(y, x);
      ASSERT_FLOAT_EQ(p[3], b[3]);
      if (p[3] < 1) continue;
      ++inside;
      EXPECT_NEAR(p[2], linear, 2e-3);        // red (BGRA order)
      EXPECT_NEAR(b[2], linear, 2e-3);
      EXPECT_NEAR(b[1], 0.5 * linear, 2e-3);  // green
      EXPECT_NEAR(b[0], 2 * linear, 4e-3);    // blue
    }
  EXPECT_GT(inside, 500);
}

}  // namespace
}  // namespace blurcue::render

#include "core/image.h"
#include "render/frame_compositor.h"
#include "scene/frame.h"

namespace blurcue::render {

using scene::BlurredObject;

namespace {

cv::Mat Photo(const Camera& c) {
  cv::Mat photo(c.image_height_px, c.image_width_px, CV_8UC3);
  cv::randu(photo, 60, 200);
  cv::GaussianBlur(photo, photo, cv::Size(0, 0), 3);
  return photo;
}

// The CPU path: draw, blur on the CPU, composite in linear light, encode.
cv::Mat CpuFrame(SceneRenderer& renderer, const cv::Mat& photo, const std::vector<BlurredObject>& objects) {
  cv::Mat linear = DecodeSrgb8(photo);
  for (const auto& o : objects) {
    Layer layer = renderer.Draw(o.object, KernelMarginPx(o.method, o.r_px) + 1);
    BlurLayer(layer, o.method, o.r_px, nullptr);
    CompositeOver(linear, layer);
  }
  return EncodeSrgb8(linear);
}

void ExpectClose(const cv::Mat& a, const cv::Mat& b, const char* what) {
  cv::Mat diff;
  cv::absdiff(a, b, diff);
  const cv::Scalar mean = cv::mean(diff);
  double max = 0;
  cv::minMaxLoc(diff.reshape(1), nullptr, &max);
  EXPECT_LE((mean[0] + mean[1] + mean[2]) / 3, 0.5) << what;
  EXPECT_LE(max, 3) << what;
}

TEST_F(SceneRenderTest, FramesBlurPerPixelByDepthWhenTheObjectCarriesThatPlan) {
  // The compositor's per-pixel plan equals the CPU reference (draw, BlurLayerVarying, composite) and differs from one
  // radius at the centre.
  const View v;
  const cv::Mat photo = Photo(v.camera);
  FrameCompositor gpu(v.camera, v.rvec, v.tvec, photo);
  BlurredObject card;
  card.object = FlatCard(60, 230);
  const Footprint f = gpu.renderer().Measure(card.object);
  const double z0 = f.z_min_mm, z1 = f.z_max_mm;
  card.r_px = 3.5;
  card.r_of_depth_px = [&](double z) { return 1.5 + 4.0 * (z - z0) / (z1 - z0); };
  gpu.Compose({card});
  const cv::Mat varying = gpu.Read();
  Layer layer = gpu.renderer().Draw(card.object, KernelMarginPx("gaussian", 5.5) + 1);
  BlurLayerVarying(layer, "gaussian", card.r_of_depth_px, nullptr);
  cv::Mat linear = DecodeSrgb8(photo);
  CompositeOver(linear, layer);
  ExpectClose(varying, EncodeSrgb8(linear), "per pixel: compositor vs CPU");
  BlurredObject one = card;
  one.r_of_depth_px = nullptr;
  gpu.Compose({one});
  EXPECT_GT(cv::norm(gpu.Read(), varying, cv::NORM_L1), 2000) << "per pixel looks like one radius";
}

TEST_F(SceneRenderTest, GpuFrameMatchesCpuReferenceAndWholeFrameApproach) {
  const View v;
  const cv::Mat photo = Photo(v.camera);
  FrameCompositor gpu(v.camera, v.rvec, v.tvec, photo);
  std::vector<BlurredObject> balls = {{Ball(150), "gaussian", 3.0, 0, {0, 0}, {}}, {Ball(200), "disc", 5.0, 0, {0, 0}, {}}};
  balls[1].object.center_board_mm[0] = 137.5;
  gpu.Compose(balls);
  const cv::Mat region = gpu.Read();
  gpu.ComposeWholeFrame(balls);
  const cv::Mat whole = gpu.Read();
  const cv::Mat cpu = CpuFrame(gpu.renderer(), photo, balls);
  ExpectClose(region, cpu, "region vs CPU");
  ExpectClose(region, whole, "region vs whole frame");
  // Something was drawn: the frame differs from the photo around the balls.
  EXPECT_GT(cv::norm(region, photo, cv::NORM_L1), 1000);
}

}  // namespace
}  // namespace blurcue::render

#include "calib/edge_blur.h"

namespace blurcue::render {
namespace {

// A white card lying on the table spans depth; with a radius that grows steeply with depth its near edge must
// measure as r(z_near) and its far edge as r(z_far), each by the calibration's own measurement.
TEST_F(SceneRenderTest, AFrameWithoutObjectsIsThePhotoExactlyAfterFramesWithThem) {
  // What the last frame drew is put back from the photo byte for byte before the next: a frame with no objects
  // after frames with balls (blurred by either kernel, and the whole-frame approach's full-frame layers) shows the
  // photo itself, not a re-encoded copy of it.
  const View v;
  const cv::Mat photo = Photo(v.camera);
  FrameCompositor gpu(v.camera, v.rvec, v.tvec, photo);
  std::vector<BlurredObject> balls = {{Ball(150), "gaussian", 3.0, 0, {0, 0}, {}}, {Ball(200), "disc", 5.0, 0, {0, 0}, {}}};
  balls[1].object.center_board_mm[0] = 137.5;
  gpu.Compose({});
  const cv::Mat empty = gpu.Read();
  EXPECT_EQ(cv::norm(empty, photo, cv::NORM_INF), 0);
  gpu.Compose(balls);
  gpu.ComposeWholeFrame(balls);
  gpu.Compose(balls);
  EXPECT_GT(cv::norm(gpu.Read(), photo, cv::NORM_INF), 10);
  gpu.Compose({});
  EXPECT_EQ(cv::norm(gpu.Read(), photo, cv::NORM_INF), 0);
}

// A live view composes each photo once and uploads it straight into the frame (SetFrame's compose_once): the frame
// is the one the base-frame path composes, byte for byte, with photos that change between frames; composing the same
// photo again, which would need the base it skipped, is refused.
TEST_F(SceneRenderTest, AFrameComposedOnceIsTheFrameTheBasePathComposes) {
  const View v;
  const cv::Mat first = Photo(v.camera);
  cv::Mat second;
  cv::flip(first, second, 1);  // another photo: the objects of the frame before must leave no trace
  std::vector<BlurredObject> balls = {{Ball(150), "gaussian", 3.0, 0, {0, 0}, {}}, {Ball(200), "disc", 5.0, 0, {0, 0}, {}}};
  balls[1].object.center_board_mm[0] = 137.5;
  FrameCompositor base(v.camera, v.rvec, v.tvec, first), once(v.camera, v.rvec, v.tvec, first);
  for (const cv::Mat* photo : std::vector<const cv::Mat*>{&first, &second, &first}) {
    base.SetFrame(v.rvec, v.tvec, *photo);
    base.Compose(balls);
    once.SetFrame(v.rvec, v.tvec, *photo, true);
    once.Compose(balls);
    const cv::Mat want = base.Read();
    EXPECT_GT(cv::norm(want, *photo, cv::NORM_INF), 10);  // the balls are drawn
    EXPECT_EQ(cv::norm(once.Read(), want, cv::NORM_INF), 0);
  }
  EXPECT_THROW(once.Compose(balls), Error);
  EXPECT_THROW(once.Place(1, 0), Error);
  once.SetFrame(v.rvec, v.tvec, second);  // the base path again: composed as often as asked
  once.Compose({});
  EXPECT_EQ(cv::norm(once.Read(), second, cv::NORM_INF), 0);
}

TEST_F(SceneRenderTest, DepthVaryingBlurFollowsEachEdgesDepth) {
  const View v;
  SceneRenderer renderer(v.camera, v.rvec, v.tvec);
  const VirtualObject card = FlatCard(60, 230);
  const Footprint f = renderer.Measure(card);
  const double z0 = f.z_min_mm, z1 = f.z_max_mm;
  auto r_of_depth = [&](double z) { return 1.5 + 4.0 * (z - z0) / (z1 - z0); };  // 1.5 px near .. 5.5 px far
  Layer layer = renderer.Draw(card, KernelMarginPx("gaussian", 6) + 2);
  ASSERT_GT(cv::countNonZero(layer.depth_mm > 0), 100);
  BlurLayerVarying(layer, "gaussian", r_of_depth, nullptr);
  // The layer over a grey table, as linear grey (pure black would read as clipped).
  cv::Mat table(layer.roi.size(), CV_32FC3, cv::Scalar(0.1, 0.1, 0.1));
  Layer at_origin = layer;
  at_origin.roi = cv::Rect(cv::Point(0, 0), layer.roi.size());
  CompositeOver(table, at_origin);
  cv::Mat grey;
  cv::extractChannel(table, grey, 0);
  auto project = [&](double x, double y) {
    std::vector<cv::Point2d> px;
    cv::projectPoints(std::vector<cv::Point3d>{{x, y, 0}}, v.rvec, v.tvec, cv::Matx33d(v.camera.Intrinsics().data()),
                      cv::noArray(), px);
    return px[0] - cv::Point2d(layer.roi.x, layer.roi.y);
  };
  const double h = card.size_mm / 2, cx = card.center_board_mm[0], cy = card.center_board_mm[1];
  cv::Matx33d rot;
  cv::Rodrigues(v.rvec, rot);
  for (double y : {cy - h, cy + h}) {
    const double z = (rot * cv::Vec3d(cx, y, 0) + v.tvec)[2];
    const calib::EdgeSegment seg{project(cx - 0.6 * h, y), project(cx + 0.6 * h, y), 14};
    const calib::ModelFit fit = calib::MeasureEdgeModel(grey, seg);
    ASSERT_TRUE(fit.ok) << "edge at y = " << y << ": " << (fit.flags.empty() ? std::string() : fit.flags[0]) << " r " << fit.r_px << " roi " << layer.roi;
    EXPECT_NEAR(fit.r_px, r_of_depth(z), 0.1 * r_of_depth(z)) << "edge at y = " << y;
  }
}

}  // namespace
}  // namespace blurcue::render
