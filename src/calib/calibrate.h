#pragma once
// The calibration pipeline (thesis Fig. 4.1, steps 1-4): find the board, solve the pose, measure the blur of
// every edge section two ways, and estimate every section from the reference edge (eq. 3.7) and from a thin-lens
// model fitted to all usable sections.
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "calib/board_pose.h"
#include "calib/edge_blur.h"
#include "calib/model_undetermined.h"
#include "calib/phase_check.h"
#include "core/board.h"
#include "core/camera.h"
#include "core/json_io.h"
#include "optics/fit.h"

namespace blurcue::calib {

struct CalibrateOptions {
  int reference_edge = 1;  // the thesis used the nearest edge, focused on it
  DetectOptions detect;
  ModelFitOptions model_fit;
  ThesisOptions thesis;
  optics::FitOptions optics_fit;
  // Skip detection and use this pose (benchmarks: to measure blur where detection breaks first).
  std::optional<BoardPose> known_pose;
  // The sections measured on every core (false: one after another; the numbers are the same either way).
  bool parallel_sections = true;
  // Fit the scene's lens model to this photo's sections (false: the result's model is left empty and r_fitted_px 0,
  // for a caller that fits one model to many photos and applies it with ApplyModel: track, a take's frames).
  bool fit_model = true;
  // Read sections whose phases are few with each PSF family and flag those the families leave open phase_limited
  // (phase_check.h; with fit_model only: the sections at other phases choose the family through the lens fit). false:
  // the blur fit's readings as they are, none flagged (to compare).
  bool phase_check = true;
  // Measure only these sections (flat index (edge - 1) * SectionCount() + section - 1; the others are left unmeasured,
  // not usable): a live view's rotating subset. Empty: every section. Meant without fit_model (a subset rarely pins a
  // lens); no reference edge is taken then (reference_u_mm and _r_px 0, no eq. 3.7 estimates), as a subset mostly
  // leaves it unmeasured.
  std::vector<int> only_sections;
};

struct SectionResult {
  int edge = 0, section = 0;          // 1-based
  cv::Vec3d midpoint_camera_mm;       // 3-D midpoint in the camera frame
  double u_mm = 0;                    // its depth (camera z)
  EdgeSegment segment;                // the section in the photo (end points, window across it)
  ModelFit fit;                       // r_px = fit.r_px, usable when fit.ok
  ThesisMeasure thesis;               // r_thesis_px
  PhaseCheck phase;                   // the readings per PSF family where its phases are few
  // How much the lens distortion (camera.json's dist_coeffs) stretches a blur across this edge at its midpoint
  // (core/distortion.h; 1 without distortion): photo px per ideal (pinhole) px. The thin-lens model lives in ideal
  // px, so it is fitted to r_px / stretch and predicts r_fitted_px = model x stretch.
  double stretch = 1;
  std::optional<double> r_estimated_px;  // eq. 3.7 from the reference edge; empty where it does not hold
  std::string estimated_note;            // why it is empty
  double r_fitted_px = 0;                // fitted thin-lens model, in photo px (the model's ideal px x stretch)
  double r_fitted_se_px = 0;             // its standard error where a mask was chosen (PropagateModelError), else 0
};

struct EdgeResult {
  int index = 0;
  double u_mm = 0;  // mean depth of its sections
  std::vector<SectionResult> sections;
  // Means (NaN-free: each count says over how many): r_thesis_px over usable sections; r_px, the value blur source
  // `measured` draws, over usable sections and those pooled into the lens fit (phase.joins_fit); r_estimated_px over
  // the sections where eq. 3.7 holds; r_fitted_px over every section (the model predicts each, usable or not).
  int usable = 0;
  int measured = 0;   // usable or pooled sections (r_px averages those)
  int estimated = 0;  // sections where eq. 3.7 holds (r_estimated_px averages those)
  double r_px = 0, r_thesis_px = 0, r_estimated_px = 0, r_fitted_px = 0;
};

struct CalibResult {
  Camera camera;
  Board board;
  BoardPose pose;
  int reference_edge = 1;
  double reference_u_mm = 0, reference_r_px = 0;
  optics::FittedModel model;
  ModelUndetermined undetermined;  // where `model` is not determined within 5 % (calib.json model.undetermined)
  PhaseChoice phase;  // the PSF family the sections chose where phases are few, and how many were flagged
  std::vector<EdgeResult> edges;
  double detect_ms = 0, measure_ms = 0, estimate_ms = 0;  // where the time went
};

// Linear-light grey of an 8-bit sRGB photo: each channel decoded first, then mixed (mixing encoded values would
// bend edges). CV_32F, one channel.
cv::Mat LinearGrey(const cv::Mat& photo);
// The same into `linear`, whose buffer is reused when it has the size already (a video's frames).
void LinearGrey(const cv::Mat& photo, cv::Mat& linear);

// A photo's two working images: the 8-bit grey as stored (detection, corners, the thesis's method) and the
// linear-light grey (the model fit). A tracker keeps one and refills it every frame, so a take allocates them once.
struct PhotoPlanes {
  cv::Mat grey8, linear;
  void Fill(const cv::Mat& photo);  // 8-bit BGR, BGRA or grey sRGB
};

// `photo` is 8-bit BGR or grey sRGB as read from disk. Throws Error(kInput) when the photo's size differs from
// the camera's, Error(kNotFound) when no board is found or the reference edge has no usable section.
CalibResult Calibrate(const cv::Mat& photo, const Camera& camera, const Board& board,
                      const CalibrateOptions& options = {});
// The same on a photo's planes made already (PhotoPlanes::Fill).
CalibResult Calibrate(const PhotoPlanes& planes, const Camera& camera, const Board& board,
                      const CalibrateOptions& options = {});

// The usable sections as the thin-lens model's samples, with the phase_limited ones that join the fit
// (PhaseCheck::joins_fit): depth and r_px / stretch (ideal px), so a distorted photo's blur is fitted in the
// undistorted lens's terms. A tracked take pools these over its frames. With a sharpening's variance (< 0: the chosen
// family's taps, PhaseChoice::variance_px2), the optics' readings before it, sqrt(r_px^2 - 4 v) / stretch.
std::vector<optics::BlurSample> ModelSamples(const CalibResult& result, double filter_variance_px2 = 0);
// Whether a section is one of ModelSamples's: usable, or phase_limited but joined at its reading (joins_fit).
bool InModel(const SectionResult& s);

// The sections the thin-lens model was not fitted to (those not in ModelSamples), counted by the flag that disqualified each (its first:
// "phase_limited", "crowded", "low_contrast", ...).
std::map<std::string, int> SectionsLeftOut(const CalibResult& result);

// A section flag in words, for a summary: what it means and whether the section is used ("poor_fit": "the blur model
// fits the profile worse than 8 % of the step (a smudge, a reflection)"). Empty for a name it does not know.
std::string SectionFlagMeaning(const std::string& flag);
// The informational flags (never disqualify a section): "flaw", "neighbours", "short", "junctions".
const std::vector<std::string>& InformationalFlags();

// Makes `model` the result's thin-lens model: every section's r_fitted_px and every edge's mean follow it (a tracked
// take's one lens model replacing each frame's own).
void ApplyModel(CalibResult& result, const optics::FittedModel& model);

// calib.json: camera, board, pose, reference edge, fitted model, and 11 edges x 7 sections with u_mm, r_px,
// r_thesis_px, r_estimated_px, r_fitted_px, ok (and flags, psf, fit quality).
Json CalibToJson(const CalibResult& result);

// The thesis's Figure 4.11 as a text table: per edge, depth, measured (model fit and thesis method), estimated by
// eq. 3.7 and by the fitted model, and how many sections were usable.
// With `true_r_per_edge` (from a ground-truth scene) a column of true radii is added.
std::string FormatEdgeTable(const CalibResult& result, const std::vector<double>& true_r_per_edge = {});

}  // namespace blurcue::calib
