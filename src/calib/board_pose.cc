#include "calib/board_pose.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"

namespace blurcue::calib {

cv::Matx33d CameraMatrix(const Camera& camera) {
  const auto k = camera.Intrinsics();
  return cv::Matx33d(k.data());
}

cv::Vec3d ToCamera(const BoardPose& pose, const std::array<double, 3>& p) {
  cv::Matx33d rot;
  cv::Rodrigues(pose.rvec, rot);
  return rot * cv::Vec3d(p[0], p[1], p[2]) + pose.tvec;
}

std::vector<cv::Point2d> Project(const BoardPose& pose, const Camera& camera,
                                 const std::vector<std::array<double, 3>>& board_mm) {
  std::vector<cv::Point3d> object;
  object.reserve(board_mm.size());
  for (const auto& p : board_mm) object.emplace_back(p[0], p[1], p[2]);
  std::vector<cv::Point2d> image;
  if (object.empty()) return image;
  cv::projectPoints(object, pose.rvec, pose.tvec, CameraMatrix(camera), camera.dist_coeffs, image);
  return image;
}

namespace {

// Solves the pose for inner corners given in board order; returns the RMS reprojection error.
double SolvePose(const std::vector<cv::Point2f>& corners, const Board& board, const Camera& camera,
                 cv::Vec3d& rvec, cv::Vec3d& tvec) {
  std::vector<cv::Point3f> object;
  for (int iy = 0; iy < board.InnerCornersY(); ++iy)
    for (int ix = 0; ix < board.InnerCornersX(); ++ix)
      object.emplace_back(float((ix + 1) * board.square_mm), float((iy + 1) * board.square_mm), 0.f);
  const cv::Matx33d k = CameraMatrix(camera);
  // IPPE is the closed-form solver for planar targets; LM then polishes it.
  cv::solvePnP(object, corners, k, camera.dist_coeffs, rvec, tvec, false, cv::SOLVEPNP_IPPE);
  cv::solvePnPRefineLM(object, corners, k, camera.dist_coeffs, rvec, tvec);
  std::vector<cv::Point2f> reprojected;
  cv::projectPoints(object, rvec, tvec, k, camera.dist_coeffs, reprojected);
  double sum = 0;
  for (size_t i = 0; i < corners.size(); ++i) {
    const cv::Point2f d = corners[i] - reprojected[i];
    sum += d.dot(d);
  }
  return std::sqrt(sum / corners.size());
}

// A board whose edges run into depth: its corners are the grid of a board of the size given, but turned a quarter -
// a 7x10 board read as 10x7 is found all the same (OpenCV's pattern of 9x6 inner corners matches the 6x9 grid turned),
// and then every edge lies at one depth and the calibration charts nothing against depth. No picture tells a 7x10
// board turned 90 deg from a 10x7 one lying straight, so the refusal names both readings.
void RefuseEdgesIntoDepth(const BoardPose& pose, const Board& board, double within_deg) {
  const double turn = EdgeTurnFromAcrossDeg(pose);
  if (!(turn > 90 - within_deg)) return;  // NaN (facing the camera) passes
  const double s = board.square_mm, mid_x = 0.5 * board.cols * s, mid_y = 0.5 * board.rows * s;
  const double across = std::abs(ToCamera(pose, {mid_x, board.rows * s, 0})[2] - ToCamera(pose, {mid_x, 0, 0})[2]);
  const double along = std::abs(ToCamera(pose, {board.cols * s, mid_y, 0})[2] - ToCamera(pose, {0, mid_y, 0})[2]);
  const std::string turned = std::to_string(board.rows) + "x" + std::to_string(board.cols);
  auto mm = [](double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f", v);
    return std::string(text);
  };
  throw Error(ErrorKind::kUsage,
              "board " + board.Name() + " found with its edges running into depth (" + mm(turn) +
                  " deg from across the view: its " + std::to_string(board.EdgeCount()) + " edges within " +
                  mm(across) + " mm of one depth, each spanning " + mm(along) +
                  " mm): a " + turned + " board read a quarter turned? give --board " + turned +
                  " (or --board-turned for a board lying that far turned on purpose)");
}

}  // namespace

double EdgeTurnFromAcrossDeg(const BoardPose& pose) {
  cv::Matx33d rotation;
  cv::Rodrigues(pose.rvec, rotation);
  // Camera depth z of a board point (x, y, 0) changes by R20 per mm along x (an edge) and R21 per mm along y.
  const double along = std::abs(rotation(2, 0)), across = std::abs(rotation(2, 1));
  if (std::hypot(along, across) < std::sin(5 * M_PI / 180)) return std::numeric_limits<double>::quiet_NaN();
  return std::atan2(along, across) * 180 / M_PI;
}

void RefineCorners(const cv::Mat& grey8, const Board& board, std::vector<cv::Point2f>& corners) {
  const int nx = board.InnerCornersX(), ny = board.InnerCornersY();
  CV_Assert(int(corners.size()) == nx * ny);
  // Wide enough for blurred corners, narrow enough not to reach the next corner.
  double spacing = 1e9;
  for (int iy = 0; iy < ny; ++iy)
    for (int ix = 0; ix + 1 < nx; ++ix)
      spacing = std::min(spacing, double(cv::norm(corners[iy * nx + ix + 1] - corners[iy * nx + ix])));
  const int half = std::clamp(int(spacing / 4), 2, 40);
  cv::cornerSubPix(grey8, corners, cv::Size(half, half), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 40, 0.01));
}

BoardPose PoseFromCorners(std::vector<cv::Point2f> corners, const Camera& camera, const Board& board) {
  BoardPose pose;
  pose.corners = std::move(corners);
  pose.reprojection_error_px = SolvePose(pose.corners, board, camera, pose.rvec, pose.tvec);
  return pose;
}

BoardPose FindBoardPose(const cv::Mat& grey8, const Camera& camera, const Board& board,
                        const DetectOptions& options) {
  CV_Assert(grey8.type() == CV_8UC1);
  const int nx = board.InnerCornersX(), ny = board.InnerCornersY();
  const cv::Size pattern(nx, ny);

  // Detection cost grows with pixels, and the corners' rough places do not need them all: try small copies first
  // (a few ms each) and larger ones only when the board is too small to be found there. Each size gets the classic
  // detector (fast check first) and then the sector-based one, which copes better with blur; their successes
  // differ from image to image, so both are tried.
  std::vector<cv::Point2f> found;
  double scale = 1.0;
  bool ok = false;
  const int longest = std::max(grey8.cols, grey8.rows);
  for (int side : {480, 800, 1200, options.detect_max_side_px}) {
    scale = std::min(1.0, double(side) / longest);
    cv::Mat small = grey8;
    if (scale < 1.0) cv::resize(grey8, small, cv::Size(), scale, scale, cv::INTER_AREA);
    ok = cv::findChessboardCorners(small, pattern, found, cv::CALIB_CB_ADAPTIVE_THRESH |
                                                              cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK) ||
         cv::findChessboardCornersSB(small, pattern, found, cv::CALIB_CB_NORMALIZE_IMAGE);
    if (ok || scale == 1.0) break;
  }
  if (!ok || int(found.size()) != nx * ny)
    throw Error(ErrorKind::kNotFound, "no " + board.Name() + " checkerboard found (looked for " +
                                          std::to_string(nx) + "x" + std::to_string(ny) + " inner corners)");
  for (auto& p : found) p *= 1.0 / scale;

  RefineCorners(grey8, board, found);

  // OpenCV returns ny rows of nx corners in one of four orders; put them in the board frame with z = x cross y up
  // (towards the camera) and edge 1 the nearest. The two orders with z up are a half turn apart (the board looks
  // the same turned half a turn); of those, edge 1 is the one whose first row is nearer at the board's middle. (Its
  // x = 0 end, or "x left to right in the image", picks the wrong one on a board turned past about 75 deg.)
  auto at = [&](int ix, int iy, bool flip_x, bool flip_y) {
    return found[(flip_y ? ny - 1 - iy : iy) * nx + (flip_x ? nx - 1 - ix : ix)];
  };
  auto ordered = [&](bool flip_x, bool flip_y) {
    std::vector<cv::Point2f> c;
    for (int iy = 0; iy < ny; ++iy)
      for (int ix = 0; ix < nx; ++ix) c.push_back(at(ix, iy, flip_x, flip_y));
    return c;
  };
  bool flip_x = at(nx - 1, 0, false, false).x < at(0, 0, false, false).x, flip_y = false;
  BoardPose pose;
  auto solve = [&] {
    pose.corners = ordered(flip_x, flip_y);
    SolvePose(pose.corners, board, camera, pose.rvec, pose.tvec);
  };
  solve();
  cv::Matx33d rotation;
  cv::Rodrigues(pose.rvec, rotation);
  // Mirroring the rows mirrors the frame: the solved board's normal turns over.
  if (cv::Vec3d(rotation(0, 2), rotation(1, 2), rotation(2, 2)).dot(pose.tvec) > 0) {
    flip_y = true;
    solve();
  }
  const double middle_mm = 0.5 * (nx + 1) * board.square_mm;
  const double z_first = ToCamera(pose, {middle_mm, board.square_mm, 0})[2];
  const double z_last = ToCamera(pose, {middle_mm, ny * board.square_mm, 0})[2];
  if (z_last < z_first) flip_x = !flip_x, flip_y = !flip_y;
  pose.corners = ordered(flip_x, flip_y);
  pose.reprojection_error_px = SolvePose(pose.corners, board, camera, pose.rvec, pose.tvec);
  if (options.refuse_edges_into_depth_deg > 0) RefuseEdgesIntoDepth(pose, board, options.refuse_edges_into_depth_deg);
  return pose;
}

}  // namespace blurcue::calib
