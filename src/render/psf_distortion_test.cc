// A virtual object's lens floor under distortion (issue 42, item 4): the floor an object is drawn with at a place,
// across a vertical and a horizontal edge, against the photo's floor across such edges there. The photo is synth's
// (a barrel lens, k1 = -0.3, the floor alone: no defocus), its truth the applied floor's second moment
// (floor_sigma_applied_px) times the stretch across the edge from OpenCV's own distortion (cv::projectPoints), and
// the photo itself read by a plain differenced profile (no code of calib's or render's). The object's side: the
// scene's floor and shape at the place (calib::FloorSigmaPx, calib::ShapeAt) drawn into a kernel (render::PsfKernel)
// whose second moment across each edge is taken from its taps.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include <opencv2/calib3d.hpp>

#include "calib/scene_blur.h"
#include "core/image.h"
#include "render/psf.h"
#include "synth/edge_profile_test_util.h"
#include "synth/scene.h"

namespace blurcue::render {
namespace {

struct Place {
  const char* name;
  double x_mm, y_mm;  // the edge's midpoint on the board
  bool column;        // a column line (board x constant: near vertical in the photo); else a row edge (near horizontal)
};

cv::Point2d Project(const synth::Scene& s, const cv::Point3d& p, bool distorted) {
  std::vector<cv::Point2d> q;
  const auto k = s.camera.Intrinsics();
  cv::projectPoints(std::vector<cv::Point3d>{p}, s.rvec, s.tvec, cv::Matx33d(k.data()),
                    distorted ? cv::Mat(s.camera.dist_coeffs) : cv::Mat(), q);
  return q[0];
}

using synth::testing::PhotoRadiusAcross;

// A drawn kernel's std across unit normal n, from its taps.
double KernelStdAcross(const cv::Mat& k, const cv::Point2d& n) {
  const int h = k.rows / 2;
  double sum = 0, mean = 0, second = 0;
  for (int y = 0; y < k.rows; ++y)
    for (int x = 0; x < k.cols; ++x) {
      const double w = k.at<float>(y, x), d = (x - h) * n.x + (y - h) * n.y;
      sum += w, mean += w * d, second += w * d * d;
    }
  mean /= sum;
  return std::sqrt(second / sum - mean * mean);
}

TEST(DistortedFloor, DrawnAcrossVerticalAndHorizontalEdgesIsThePhotosFloorThere) {
  // A near top-down view of a 5 x 8 board shifted right, so its right corners sit near the photo's top and bottom
  // right corners, through a barrel lens (stretch 0.83-0.95 across these edges); the floor alone (std 1 px: r = 2
  // px, well above the pixel).
  synth::SceneOptions o;
  o.camera = ThesisCamera().Resized(600, 399);
  o.camera.dist_coeffs = {-0.3, 0, 0, 0};
  o.board = Board{5, 8, 25};
  o.tilt_deg = 80, o.yaw_deg = 10, o.edge1_u_mm = 275, o.lateral_mm = 70;
  o.fixed_r_px = 0;
  o.floor_sigma_px = 1.0;
  o.supersample = 4;
  const synth::Scene s = synth::RenderScene(o);
  const cv::Mat lin = DecodeSrgb8(ToGrey8(s.image));
  const double floor_applied = s.truth.at("floor_sigma_applied_px").get<double>();

  // The calibration an ideal fit gives: the scene's camera and pose, the model's floor the applied one (ideal px;
  // how well calibrate finds it is Calibrate.*Floor*'s business).
  calib::SceneCalib scene;
  scene.camera = s.camera, scene.board = s.board, scene.rvec = s.rvec, scene.tvec = s.tvec;
  scene.model.kind = "thin_lens+floor";
  scene.model.floor_px = 2 * floor_applied;
  cv::Matx33d rot;
  cv::Rodrigues(s.rvec, rot);

  const double q = 25;  // mm
  // Inner edges only (the table's texture lies beyond the outer ones): the board's top right and bottom right
  // corner cells (their column line between sections 4 and 5 and their row edge), where the photo's radial direction
  // runs diagonally and the two stretches come close; and the middle of its right side and of its top, where the
  // radial direction is x and y and a round floor misses both.
  const Place places[] = {{"top right corner, column line", 4 * q, 7.5 * q, true},
                          {"top right corner, row edge 8", 4.5 * q, 7 * q, false},
                          {"bottom right corner, column line", 4 * q, 0.5 * q, true},
                          {"bottom right corner, row edge 2", 4.5 * q, 1 * q, false},
                          {"right side, column line", 4 * q, 4.5 * q, true},
                          {"right side, row edge 5", 4.5 * q, 4 * q, false},
                          {"top, column line", 3 * q, 7.5 * q, true},
                          {"top, row edge 8", 2.5 * q, 7 * q, false}};
  double round_off_max = 0;
  for (const Place& p : places) {
    const cv::Point3d mid(p.x_mm, p.y_mm, 0);
    const cv::Point3d step = p.column ? cv::Point3d(0, 0.01, 0) : cv::Point3d(0.01, 0, 0);    // along the edge
    const cv::Point3d across = p.column ? cv::Point3d(0.01, 0, 0) : cv::Point3d(0, 0.01, 0);  // across it
    const cv::Point2d m = Project(s, mid, true);
    cv::Point2d t = Project(s, mid + step, true) - Project(s, mid - step, true);
    t /= cv::norm(t);
    const cv::Point2d n(-t.y, t.x);
    // Truth: the applied floor times the stretch across the edge, 1 / |J^-T n_ideal|, from cv::projectPoints: the
    // width across the edge of a small step perpendicular to it on the board, distorted over pinhole.
    auto width = [&](bool distorted) {
      const cv::Point2d a = Project(s, mid, distorted), b = Project(s, mid + step, distorted),
                        c = Project(s, mid + across, distorted);
      const cv::Point2d e = b - a, d = c - a;
      return std::abs(e.x * d.y - e.y * d.x) / std::hypot(e.x, e.y);
    };
    const double stretch = width(true) / width(false);
    const double truth = floor_applied * stretch;
    const double photo = 0.5 * PhotoRadiusAcross(lin, m, n);

    // The object there: the scene's floor and shape at that place, the floor alone (an object at the focus depth).
    const cv::Vec3d camera_mm = rot * cv::Vec3d(mid.x, mid.y, mid.z) + s.tvec;
    Psf psf;
    psf.method = "disc";
    psf.floor_sigma_px = calib::FloorSigmaPx(scene, calib::BlurSource::kFitted, camera_mm);
    psf.r_px = 2 * psf.floor_sigma_px;
    psf.shape = calib::ShapeAt(scene, calib::BlurSource::kFitted, camera_mm);
    const double drawn = KernelStdAcross(PsfKernel(psf), n);
    const double stated = psf.FloorAcrossPx({n.x, n.y});
    const double round = psf.floor_sigma_px;
    std::printf("%s: photo px (%.1f, %.1f), normal (%.3f, %.3f); photo's floor %.4f px (image) %.4f px (truth, stretch "
                "%.4f); object's floor drawn %.4f px, stated %.4f px, round %.4f px\n",
                p.name, m.x, m.y, n.x, n.y, photo, truth, stretch, drawn, stated, round);
    // The image agrees with the truth (what the check stands on) ...
    EXPECT_NEAR(photo, truth, 0.015 * truth) << p.name;
    // ... the object's floor across the edge is the photo's there, drawn and as the capture states it ...
    EXPECT_NEAR(drawn, truth, 0.01 * truth) << p.name;
    EXPECT_NEAR(drawn, photo, 0.015 * photo) << p.name;
    EXPECT_NEAR(stated, drawn, 1e-3 * drawn) << p.name;
    round_off_max = std::max(round_off_max, std::abs(round - truth) / truth);
  }
  // ... where the round floor (the record's floor_sigma_*: the model's x sqrt(det J)) is off by three times the
  // photo's tolerance somewhere (5.4 % at the right side's row edge when this was written).
  EXPECT_GT(round_off_max, 0.045);
}

}  // namespace
}  // namespace blurcue::render
