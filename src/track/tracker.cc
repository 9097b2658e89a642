#include "track/tracker.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "calib/board_pose.h"
#include "core/error.h"
#include "core/image.h"
#include "optics/thin_lens.h"

namespace blurcue::track {
namespace {

constexpr int kSmallFactor = 4;  // the copy the frame-to-frame shift is found on: a quarter of each side

double MsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

std::string Fixed(double v, int digits) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, v);
  return text;
}

}  // namespace

const char* Name(FrameStatus status) {
  switch (status) {
    case FrameStatus::kFound: return "found";
    case FrameStatus::kTracked: return "tracked";
    case FrameStatus::kLost: return "lost";
  }
  return "lost";
}

Tracker::Tracker(Camera camera, Board board, TrackOptions options)
    : camera_(std::move(camera)), board_(std::move(board)), options_(std::move(options)) {}

std::optional<calib::BoardPose> Tracker::Track(const cv::Mat& grey8, const cv::Mat& small, double time_s,
                                               std::string* note) const {
  if (last_.empty()) return std::nullopt;
  // Constant velocity in the image: smooth camera motion moves each corner nearly as it did a frame ago, far more
  // exactly than the refinement window (a quarter of a square) needs. With one frame of history there is no
  // velocity yet: the whole image's shift from that frame (phase correlation at a quarter size) stands in.
  std::vector<cv::Point2f> corners = last_;
  if (!before_last_.empty()) {
    // Velocity per second, not per frame: a live view that dropped frames has them unevenly apart (a take's are even,
    // and the factor is 1).
    const double gap = last_time_s_ - before_last_time_s_;
    double k = gap > 0 && time_s > last_time_s_ ? (time_s - last_time_s_) / gap : 1.0;
    if (std::abs(k - 1) < 1e-6) k = 1;  // evenly apart, but for the rounding of index / fps
    const float kf = float(k);
    for (size_t i = 0; i < corners.size(); ++i) corners[i] += kf * (last_[i] - before_last_[i]);
  } else if (!last_small_.empty() && last_small_.size() == small.size()) {
    const cv::Point2d shift = cv::phaseCorrelate(last_small_, small) * double(kSmallFactor);
    for (cv::Point2f& p : corners) p += cv::Point2f(float(shift.x), float(shift.y));
  }
  const cv::Rect2f inside(2, 2, grey8.cols - 5, grey8.rows - 5);
  for (const cv::Point2f& p : corners)
    if (!inside.contains(p)) {
      *note = "not tracked from the frame before (a predicted corner leaves the image): detected anew";
      return std::nullopt;
    }
  // A corner refined farther than a third of the closest spacing from where it was predicted may have slid to its
  // neighbour's place; if all of them did, the pose fits as well as the true one, one square off. So a prediction
  // is trusted only where the refinement confirms it.
  const std::vector<cv::Point2f> predicted = corners;
  const int nx = board_.InnerCornersX();
  double spacing = 1e9;
  for (size_t i = 0; i + 1 < predicted.size(); ++i)
    if (int(i % nx) != nx - 1) spacing = std::min(spacing, double(cv::norm(predicted[i + 1] - predicted[i])));
  for (size_t i = 0; i + nx < predicted.size(); ++i)
    spacing = std::min(spacing, double(cv::norm(predicted[i + nx] - predicted[i])));
  calib::RefineCorners(grey8, board_, corners);
  double moved = 0;
  for (size_t i = 0; i < corners.size(); ++i) moved = std::max(moved, double(cv::norm(corners[i] - predicted[i])));
  if (!(moved <= spacing / 3)) {
    *note = "not tracked from the frame before (a corner refined " + Fixed(moved, 1) + " px from its prediction, more "
            "than a third of the " + Fixed(spacing, 1) + " px spacing): detected anew";
    return std::nullopt;
  }
  calib::BoardPose pose = calib::PoseFromCorners(std::move(corners), camera_, board_);
  // A corner that slid to a neighbour's place, or onto texture, leaves the pose's fit: the rms error shows it.
  if (!(pose.reprojection_error_px <= options_.max_track_error_px)) {
    *note = "not tracked from the frame before (reprojection error " + Fixed(pose.reprojection_error_px, 2) + " px > " +
            Fixed(options_.max_track_error_px, 2) + " px): detected anew";
    return std::nullopt;
  }
  return pose;
}

FrameResult Tracker::Process(const cv::Mat& photo, int index, double time_s) {
  const auto t0 = std::chrono::steady_clock::now();
  FrameResult r;
  r.index = index;
  r.time_s = time_s;
  if (photo.cols != camera_.image_width_px || photo.rows != camera_.image_height_px)
    throw InputError("frame " + std::to_string(index),
                     "is " + std::to_string(photo.cols) + "x" + std::to_string(photo.rows) + " but the camera says " +
                         std::to_string(camera_.image_width_px) + "x" + std::to_string(camera_.image_height_px));
  // The frame's grey and linear-light planes, once, into the buffers of the previous frame: tracking, detection and
  // the measurement all read them.
  // Without the measurement only the grey plane is needed: the linear one is a third of a pose-only frame's time.
  if (options_.measure_blur)
    planes_.Fill(photo);
  else
    ToGrey8(photo, planes_.grey8);
  const cv::Mat& grey8 = planes_.grey8;
  // The quarter-size copy serves only the phase correlation of a history one frame long: made when this frame may
  // start a history (none yet) or is its second frame; a frame tracked at constant velocity needs none.
  cv::Mat small;
  if (!options_.always_detect && before_last_.empty()) {
    cv::resize(grey8, small, cv::Size(), 1.0 / kSmallFactor, 1.0 / kSmallFactor, cv::INTER_AREA);
    small.convertTo(small, CV_32F);
  }
  std::optional<calib::BoardPose> pose;
  if (!options_.always_detect) pose = Track(grey8, small, time_s, &r.note);
  r.status = FrameStatus::kTracked;
  if (!pose) {
    r.status = FrameStatus::kFound;
    try {
      pose = calib::FindBoardPose(grey8, camera_, board_, options_.calibrate.detect);
    } catch (const Error& e) {
      // A board refused as found (its edges running into depth: a transposed --board) is the take's, said with its
      // frame.
      if (e.kind() == ErrorKind::kUsage) throw e.Wrapped(ErrorKind::kUsage, "frame " + std::to_string(index) + ": ");
      if (e.kind() != ErrorKind::kNotFound) throw;
      r.status = FrameStatus::kLost;
      r.note = r.note.empty() ? e.what() : r.note + "; " + e.what();
    }
  }
  r.pose_ms = MsSince(t0);
  if (!pose) {
    before_last_.clear();
    last_.clear();
    last_small_.release();
    r.frame_ms = MsSince(t0);
    return r;
  }
  before_last_ = std::exchange(last_, pose->corners);
  before_last_time_s_ = std::exchange(last_time_s_, time_s);
  last_small_ = small;
  r.pose = pose;
  if (!options_.measure_blur) {
    r.frame_ms = MsSince(t0);
    return r;
  }

  const auto t1 = std::chrono::steady_clock::now();
  calib::CalibrateOptions options = options_.calibrate;
  options.known_pose = *pose;
  options.fit_model = false;  // one model for the whole take, fitted to every frame's sections at the end (FitTakeModel)
  const int edges = board_.EdgeCount(), total = edges * board_.SectionCount();
  r.sections_measured = total;
  if (options_.sections_per_frame > 0 && options_.sections_per_frame < total) {
    // Edge after edge within a section number (section 1 of edges 1 .. E, then section 2, ...): a few sections of a
    // frame lie at the board's different depths, which is what a lens fit needs.
    for (int i = 0; i < options_.sections_per_frame; ++i) {
      const int k = (next_section_ + i) % total;
      options.only_sections.push_back((k % edges) * board_.SectionCount() + k / edges);
    }
    next_section_ = (next_section_ + options_.sections_per_frame) % total;
    r.sections_measured = options_.sections_per_frame;
  }
  try {
    r.calib = calib::Calibrate(planes_, camera_, board_, options);
    r.calib->detect_ms = r.pose_ms;
  } catch (const Error& e) {
    // The board is there but its blur is not measurable (the reference edge or the whole board flagged).
    if (e.kind() != ErrorKind::kNotFound) throw;
    r.status = FrameStatus::kLost;
    r.note = e.what();
    r.pose.reset();
  }
  r.measure_ms = MsSince(t1);
  r.frame_ms = MsSince(t0);
  return r;
}

optics::FittedModel FitTakeModel(std::vector<FrameResult>& frames, const optics::FitOptions& options) {
  std::vector<optics::BlurSample> samples;
  const calib::CalibResult* any = nullptr;
  for (const FrameResult& f : frames) {
    if (!f.calib) continue;
    any = &*f.calib;
    const std::vector<optics::BlurSample> own = calib::ModelSamples(*f.calib);
    samples.insert(samples.end(), own.begin(), own.end());
  }
  if (!any) throw Error(ErrorKind::kNotFound, "no frame of the take has a calibration (the board was never found)");
  const optics::FittedModel model =
      optics::FitThinLens(optics::Lens::FromCamera(any->camera), samples, options);
  for (FrameResult& f : frames)
    if (f.calib) calib::ApplyModel(*f.calib, model);
  return model;
}

}  // namespace blurcue::track
