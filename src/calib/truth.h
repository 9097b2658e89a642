#pragma once
// Holding a calibration against a ground-truth scene's truth.json (written by `blurcue synth-scene`).
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "core/json_io.h"

namespace blurcue::calib {

// Error of one method on one section: value - truth (px); `answered` is false where the method gave no value.
struct MethodError {
  bool answered = false;
  double error_px = 0;
};

struct SectionComparison {
  int edge = 0, section = 0;
  double true_r_px = 0, true_u_mm = 0;
  bool flawed = false;  // the truth says a printing flaw touches it
  MethodError model, thesis, estimated, fitted;
};

struct TruthComparison {
  double translation_error_mm = 0;  // |t - t_true| (board origin in the camera frame)
  double rotation_error_deg = 0;    // angle of R_true^T R
  double max_depth_error_mm = 0;    // over section midpoints
  std::vector<SectionComparison> sections;
  std::vector<double> true_r_per_edge;  // mean over the edge's sections
};

// Throws Error(kInput) naming `where` when truth.json lacks the pose or a section of this board.
TruthComparison CompareToTruth(const CalibResult& result, const Json& truth, const std::string& where);

// Tolerance of the model fit (issue target): max(0.25 px, 5 %) of the true radius.
inline double MeasureTolerancePx(double true_r_px) { return true_r_px * 0.05 > 0.25 ? true_r_px * 0.05 : 0.25; }

// One method's errors over all sections (answered ones only; zeros when none answered).
struct MethodSummary {
  int sections = 0, answered = 0, within_target = 0;  // within MeasureTolerancePx
  double mean_abs_error_px = 0, median_abs_error_px = 0, p90_abs_error_px = 0, max_abs_error_px = 0;
  double bias_px = 0;  // mean signed error
  // |error| / true r: median and 90th percentile (the "Must hold" measure)
  double median_rel_error = 0, p90_rel_error = 0;
};
MethodSummary SummarizeMethod(const TruthComparison& comparison, MethodError SectionComparison::*method);

}  // namespace blurcue::calib
