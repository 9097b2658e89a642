#pragma once
// The log of a live run (docs/live.md): one row per frame shown in DIR/live.csv, what was drawn in DIR/drawn.csv
// (`blurcue ar`'s CSV, row for row), and DIR/summary.json with the run's totals; built in memory, written whole.
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/json_io.h"
#include "track/tracker.h"

namespace blurcue::live {

// One frame shown. Times in s from the run's start (frame 0's due time), durations in ms.
struct LiveRow {
  int frame = 0;                  // the input's frame number (a gap: frames dropped)
  double arrival_s = 0;           // when it was delivered into the mailbox
  track::FrameStatus status = track::FrameStatus::kLost;
  std::optional<cv::Vec3d> rvec, tvec;  // the pose (empty when lost)
  double track_ms = 0;            // the pose: tracking from the frame before, or detection
  double render_ms = 0;           // planning, photo upload, objects composed and drawn into the window's back buffer
  double display_s = 0;           // when it was on screen: the swap returned (vsync) and the GPU finished
  double latency_ms = 0;          // display_s - arrival_s
  int dropped = 0;                // frames dropped since the frame shown before (replaced in the mailbox unseen)
  int sections = 0;               // board sections whose blur this frame measured (--measure-sections; 0: none)
  double measure_ms = 0;          // measuring them (the lens is fitted on a thread of its own)
  int lens_sections = 0;          // sections the lens model drawn with was fitted to live (0: the given model)
};

struct LiveColumn {
  const char* name;
  const char* meaning;
};
// live.csv's columns in order (docs/live.md lists them).
extern const std::vector<LiveColumn> kLiveColumns;
std::string LiveCsvHeader();
// Appends the row's line to `csv` (no allocation once `csv` has room).
void AppendLiveCsvRow(const LiveRow& row, std::string* csv);

struct LiveSummary {
  int shown = 0, dropped = 0, found = 0, tracked = 0, lost = 0;
  double median_latency_ms = 0, p95_latency_ms = 0, max_latency_ms = 0;
  double median_track_ms = 0, median_render_ms = 0, median_measure_ms = 0;
  int sections_per_frame = 0;  // the most sections a frame measured (--measure-sections)
  int lens_sections = 0;  // the readings the last frame's lens model was fitted to live (0: the given model)
  // Frames a second over one span, from the arrival of the first frame shown to that of the last: shown_fps counts
  // the frames shown, delivered_fps every frame the input delivered (dropped ones too: a camera's own rate, or a
  // video's pace when its decoding kept up); shown_fps <= delivered_fps, equal when none was dropped.
  double shown_fps = 0;
  double delivered_fps = 0;
  std::string ended;      // why the run ended, in words
  double cpu_ms_per_frame = 0;  // the process's CPU time over the run (every thread: reader, decoder, GL) / frames shown
  int preloaded_frames = 0;  // --preload: frames decoded before the start (their decoding untimed); 0: decoded as played
};
// Totals of `rows`; `dropped` the mailbox's count (frames dropped after the last frame shown included).
LiveSummary Summarize(const std::vector<LiveRow>& rows, int dropped, const std::string& ended);
// "60 frames shown, 0 dropped (0.0 %); latency median 21.4 ms, p95 27.9 ms, max 30.2 ms; ..."
std::string SummaryLine(const LiveSummary& s);
Json SummaryJson(const LiveSummary& s);

}  // namespace blurcue::live
