#pragma once
// Speed against accuracy of `blurcue live --measure-sections N`: latency and dropped frames against the number of
// board sections measured a frame, and how near the ball's drawn blur comes to the truth, on a ground-truth take
// (src/synth/take.h) played at its frame rate. `blurcue live` is run as a command, headless, once per N, each run
// timed by its own log. One row per N.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace blurcue::bench {

struct LiveBenchRow {
  int sections_per_frame = 0;       // --measure-sections N (0: the given lens model throughout)
  int frames_delivered = 0, frames_shown = 0, frames_dropped = 0;
  int frames_drawn = 0;             // frames shown with the ball drawn (a pose found)
  int max_sections = 0;             // the most sections one frame measured (live.csv's sections)
  int lens_sections = 0;            // the readings the last frame's lens model was fitted to (0: the given model)
  double median_latency_ms = 0, p95_latency_ms = 0;
  double median_track_ms = 0, median_measure_ms = 0, median_render_ms = 0;
  double cpu_ms = 0;                // the live process's CPU time over the whole run (start-up and --preload included)
  double cpu_ms_per_frame = 0;      // its CPU time over the frames (every thread) / frames shown: summary.json's
  // |drawn r_px - true r| / true r of the ball, over the frames drawn: median, and median and worst over the last
  // third of them (once the model has had a third of the run to settle).
  double r_median_rel_error = 0, r_late_median_rel_error = 0, r_late_max_rel_error = 0;
  // The frames drawn before the ball's r is within 2 % of the truth in every frame after: how long the model takes
  // to settle (frames_drawn when it never does; 0 when it is within from the first frame).
  int settle_frames = 0;
  double load1 = 0;                 // the machine's 1-minute load average as the run started
};

struct LiveBenchOptions {
  int frames = 60;
  double fps = 30;
  bool quick = false;               // 12 frames, N in {0, 4, 77} (a smoke run: its figures are not the targets')
  std::vector<int> sections = {0, 1, 2, 4, 8, 16, 32, 77};
  uint64_t seed = 1;
  std::function<void(const std::string&)> progress;
};

// The focus the given lens model was calibrated at: the take's lens is focused at 450 mm, the model handed to live
// at 400 mm (the focus ring turned since the calibration), so N = 0 draws the stale model's blur and N > 0 shows
// how fast and how closely the sections measured live bring it to the truth.
inline constexpr double kLiveBenchStaleFocusMm = 400;

std::vector<LiveBenchRow> RunLiveBench(const LiveBenchOptions& options);
void WriteLiveBenchCsv(const std::vector<LiveBenchRow>& rows, const std::filesystem::path& path, bool quick);
// The table, and the ratios measured in the run (latency and measure time against N = 0, per section).
std::string SummarizeLiveBench(const std::vector<LiveBenchRow>& rows);

}  // namespace blurcue::bench
