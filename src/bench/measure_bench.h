#pragma once
// Speed against accuracy of the blur measurement methods, on ground-truth scenes swept one factor at a time:
// sensor noise, contrast, JPEG quality, printing flaws, blur size and camera tilt. One row per (method, condition).
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace blurcue::bench {

struct MeasureRow {
  std::string method;      // "model_fit", "thesis", "eq37", "fitted_model"
  std::string factor;      // "base", "noise", "contrast", "jpeg", "flaws", "blur", "tilt", the PSF family
                           // ("psf_disc", "psf_gaussian", "psf_disc_floor_0.25" ... : floor sigma / disc radius),
                           // "near_focus" (disc + 0.35 px floor), "vignetting", "distortion", and (issue 42)
                           // "post_gaussian", "post_sharpen" (a filter on the sampled image), "edge_angle",
                           // "phase" (the sections of one level scene, split by their edge's sub-pixel phase)
  double level = 0;        // the factor's value (noise std, Michelson contrast, JPEG quality, spots, r px, deg;
                           // PSF family and near focus: the true r px; vignetting: fall-off at the corner;
                           // post_gaussian: its std px; post_sharpen: its amount; edge_angle: the edges' median
                           // angle to the pixel rows in the photo, deg; phase: the middle of a 0.1 px band of
                           // distance from the nearest pixel centre, px)
  int sections = 0;        // sections in the scene
  int answered = 0;        // sections the method gave a value for (model fit: flagged ok)
  double mean_abs_error_px = 0, median_abs_error_px = 0, p90_abs_error_px = 0, max_abs_error_px = 0;
  double bias_px = 0;          // mean signed error
  double median_rel_error = 0, p90_rel_error = 0;  // |error| / true r
  double within_target = 0;    // fraction of answered sections within max(0.25 px, 5 %); post_gaussian,
                               // post_sharpen and phase: within max(0.05 px, 10 %) (issue 42)
  double time_us_per_section = 0;  // measurement methods: per section; estimators: per section from measured input
  bool meets_target = false;   // answered >= 50 % of sections and >= 90 % of them within target; post_gaussian,
                               // post_sharpen and phase: every answered one (the others flagged), the fitted
                               // model median <= 2 %, p90 <= 5 %
  bool board_found = true;     // false: detection failed here, and the blur was measured at the true pose
  int phase_limited = 0;       // sections the calibration flagged phase_limited (not answered by the model fit)
  // post_gaussian, post_sharpen and phase (issue 42's rule): answered sections off max(0.05 px, 10 %) of the truth,
  // i.e. neither within it nor flagged; -1 elsewhere (the CSV leaves it empty).
  int off_rule = -1;
};

struct MeasureBenchOptions {
  bool quick = false;     // two conditions per factor (a smoke run for CI)
  uint64_t seed = 1;
  std::function<void(const std::string&)> progress;  // one line per condition
};

std::vector<MeasureRow> RunMeasureBench(const MeasureBenchOptions& options);
// The last column, quick, says a --quick (smoke) run made the rows: charts say so.
void WriteMeasureCsv(const std::vector<MeasureRow>& rows, const std::filesystem::path& path,
                     bool quick = false);
// For each (method, factor): the levels where the method meets its target and where it first fails.
std::string DescribeBreakpoints(const std::vector<MeasureRow>& rows);

struct PipelineTiming {
  int width = 0, height = 0;
  double render_s = 0;                      // making the scene (not part of calibration)
  double decode_ms = 0;                     // PNG decode
  double detect_ms = 0, measure_ms = 0, estimate_ms = 0, total_ms = 0;  // calibration proper
  double model_us_per_section = 0, thesis_us_per_section = 0;
};
// Full-resolution thesis scene (4592 x 3056): time of each calibration stage, best of `repeats`.
PipelineTiming TimeFullResolution(int repeats, const std::function<void(const std::string&)>& progress);

}  // namespace blurcue::bench
