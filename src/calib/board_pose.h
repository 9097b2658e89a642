#pragma once
// Finding the printed checkerboard in a photo and solving the camera pose (thesis section 4.2).
#include <array>
#include <vector>

#include <opencv2/core.hpp>

#include "core/board.h"
#include "core/camera.h"

namespace blurcue::calib {

struct BoardPose {
  cv::Vec3d rvec, tvec;               // board frame (core/board.h) -> camera, mm
  double reprojection_error_px = 0;   // RMS over the inner corners
  // Inner corners in board order: index iy * (cols - 1) + ix is the corner at ((ix + 1) s, (iy + 1) s).
  std::vector<cv::Point2f> corners;
};

struct DetectOptions {
  int detect_max_side_px = 1600;  // the largest copy detection tries (480, 800, 1200 px first); refined at full size
  // A board found with its edges within this angle of the depth direction on its plane is refused (Error kUsage): a
  // board given as 10x7 that lies as a 7x10 one is found all the same (its corners are the same grid turned a
  // quarter), and all its edges then lie at one depth. 0: never refused (track's default); calibrate: 10 deg.
  double refuse_edges_into_depth_deg = 0;
};

// Finds the board in an 8-bit grey photo, orders its corners in the board frame (edge 1 = nearest the camera)
// and solves the pose with the camera's intrinsics. Throws Error(kNotFound) when no board of this size is seen, and
// Error(kUsage) for one whose edges run into depth (options.refuse_edges_into_depth_deg).
BoardPose FindBoardPose(const cv::Mat& grey8, const Camera& camera, const Board& board,
                        const DetectOptions& options = {});

// Refines inner corners (board order, in place) at full resolution with a window a quarter of their closest spacing:
// from a detector's rough places or a tracker's prediction.
void RefineCorners(const cv::Mat& grey8, const Board& board, std::vector<cv::Point2f>& corners);

// The pose from inner corners already in board order (a tracker's), with its RMS reprojection error.
BoardPose PoseFromCorners(std::vector<cv::Point2f> corners, const Camera& camera, const Board& board);

// The angle (deg) between the board's edges and the line of constant depth on its plane: 0 when the edges run across
// the view (each at one depth, edge 1 the nearest), 90 when they run straight away from the camera; NaN when the
// board faces the camera within 5 deg (its depth barely changes: there is no direction to tell).
double EdgeTurnFromAcrossDeg(const BoardPose& pose);

cv::Matx33d CameraMatrix(const Camera& camera);
// Board-frame point (mm) -> camera frame (mm).
cv::Vec3d ToCamera(const BoardPose& pose, const std::array<double, 3>& board_mm);
// Board-frame points (mm) -> image pixels, with the camera's distortion.
std::vector<cv::Point2d> Project(const BoardPose& pose, const Camera& camera,
                                 const std::vector<std::array<double, 3>>& board_mm);

}  // namespace blurcue::calib
