#pragma once
// Speed against accuracy of tracking a take (src/track) against a full detection on every frame and against
// `calibrate` on every frame, on a ground-truth moving-camera take (src/synth/take.h). One row per (mode, frame).
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace blurcue::bench {

struct TrackRow {
  // "track" (carried pose, the next frame decoded meanwhile as track::TrackTake does), "track-inline" (the same,
  // each frame decoded before it is processed), "track-serial" (decoded in line, its sections measured one after
  // another on one core),
  // "detect" (full detection every frame), "calibrate" (calib::Calibrate in this process),
  // "calibrate-process" (`blurcue calibrate` run as a command on the frame's PNG: start-up, decode, calib.json
  // written; wall and the child's CPU time; its accuracy is the in-process calibrate's when it wrote the same
  // sections, NaN otherwise)
  std::string mode;
  int frame = 0;
  std::string status;      // found | tracked | lost (calibrate: found | lost)
  double frame_ms = 0;     // the frame's work, decoding excluded (the PNG decode is timed apart: decode_ms)
  double pose_ms = 0, measure_ms = 0;
  double cpu_ms = 0;       // the process's CPU time over the frame's work (all threads): what the frame costs when
                           // the machine is shared and wall time is not the frame's own
  double decode_ms = 0;    // PNG decode of the frame (the same for every mode)
  // The frame's time decoding included, as a take is tracked: track decodes the next frame on a thread of its own
  // while this one is processed (track::TrackTake), so its period is from the end of the frame before to the end of
  // this one; the other in-process modes decode in line (decode_ms + frame_ms); calibrate-process: frame_ms.
  double period_ms = 0;
  double max_depth_error_rel = 0;     // max over sections of |u - u_true| / u_true
  double translation_error_mm = 0;    // |t - t_true|
  int answered = 0, sections = 0;     // usable sections
  double r_median_rel_error = 0, r_p90_rel_error = 0;  // measured r_px against the applied kernels' r
  double fitted_median_rel_error = 0;  // the mode's lens model (track/detect: the take's; calibrate: the frame's)
};

struct TrackBenchOptions {
  int frames = 12;
  bool quick = false;      // the first 4 frames of the take (a smoke run, the same motion per frame)
  uint64_t seed = 1;
  std::function<void(const std::string&)> progress;
};

std::vector<TrackRow> RunTrackBench(const TrackBenchOptions& options);
void WriteTrackCsv(const std::vector<TrackRow>& rows, const std::filesystem::path& path, bool quick);
// Per mode: median and p90 ms a frame, the targets (median <= 33 ms; >= 6x faster than calibrate), and the
// accuracy beside the time.
std::string SummarizeTrackBench(const std::vector<TrackRow>& rows);

}  // namespace blurcue::bench
