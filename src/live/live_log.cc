#include "live/live_log.h"

#include <algorithm>
#include <cstdio>

#include "core/stats.h"

namespace blurcue::live {

const std::vector<LiveColumn> kLiveColumns = {
    {"frame", "the input's frame number from 0: a video's or sequence's index, a camera's count of delivered frames "
              "(a gap: frames dropped)"},
    {"arrival_s", "when the frame was delivered, s from the run's start (frame 0's due time)"},
    {"status", "found (full detection), tracked (carried from the frame before) or lost (no pose: shown without "
               "objects)"},
    {"rvec_x", "pose rotation (Rodrigues vector, board frame -> camera), rad; empty when lost"},
    {"rvec_y", ""},
    {"rvec_z", ""},
    {"tvec_x_mm", "board origin in the camera frame, mm; empty when lost"},
    {"tvec_y_mm", ""},
    {"tvec_z_mm", "... its depth"},
    {"track_ms", "finding the pose: tracking from the frame before, or detection, ms"},
    {"render_ms", "planning the objects, uploading the photo, composing and drawing the frame (the GPU finished), ms"},
    {"display_s", "when the frame was on screen: the window's swap returned (vsync) and the GPU finished; headless, "
                  "when the GPU finished; s from the run's start"},
    {"latency_ms", "display_s - arrival_s, ms"},
    {"dropped", "frames delivered since the frame shown before and never shown (replaced in the one-slot mailbox "
                "while a frame was processed)"},
    {"sections", "board sections whose blur this frame measured (--measure-sections N: a rotating subset of N; 0: none, "
                 "lost, or no --measure-sections)"},
    {"measure_ms", "measuring them, ms (the lens model is fitted to every section's latest reading on a thread of its "
                   "own, meanwhile)"},
    {"lens_sections", "sections the lens model this frame was drawn with was fitted to live (their latest readings); "
                      "0: the model of --track or --calib"},
};

std::string LiveCsvHeader() {
  std::string line;
  for (const LiveColumn& c : kLiveColumns) line += (line.empty() ? "" : ",") + std::string(c.name);
  return line + "\n";
}

void AppendLiveCsvRow(const LiveRow& r, std::string* csv) {
  char pose[160] = ",,,,,";
  if (r.rvec && r.tvec)
    std::snprintf(pose, sizeof pose, "%.8f,%.8f,%.8f,%.4f,%.4f,%.4f", (*r.rvec)[0], (*r.rvec)[1], (*r.rvec)[2],
                  (*r.tvec)[0], (*r.tvec)[1], (*r.tvec)[2]);
  char line[360];
  std::snprintf(line, sizeof line, "%d,%.6f,%s,%s,%.3f,%.3f,%.6f,%.3f,%d,%d,%.3f,%d\n", r.frame, r.arrival_s,
                track::Name(r.status), pose, r.track_ms, r.render_ms, r.display_s, r.latency_ms, r.dropped, r.sections,
                r.measure_ms, r.lens_sections);
  csv->append(line);
}

LiveSummary Summarize(const std::vector<LiveRow>& rows, int dropped, const std::string& ended) {
  LiveSummary s;
  s.shown = int(rows.size());
  s.dropped = dropped;
  s.ended = ended;
  std::vector<double> latency, track, render, measure;
  for (const LiveRow& r : rows) {
    latency.push_back(r.latency_ms);
    measure.push_back(r.measure_ms);
    s.sections_per_frame = std::max(s.sections_per_frame, r.sections);
    s.lens_sections = r.lens_sections;
    track.push_back(r.track_ms);
    render.push_back(r.render_ms);
    s.max_latency_ms = std::max(s.max_latency_ms, r.latency_ms);
    s.found += r.status == track::FrameStatus::kFound;
    s.tracked += r.status == track::FrameStatus::kTracked;
    s.lost += r.status == track::FrameStatus::kLost;
  }
  s.median_latency_ms = Percentile(latency, 0.5);
  s.p95_latency_ms = Percentile(latency, 0.95);
  s.median_track_ms = Percentile(track, 0.5);
  s.median_render_ms = Percentile(render, 0.5);
  s.median_measure_ms = Percentile(measure, 0.5);
  // Both rates over one span, the arrivals of the first and the last frame shown, so that the frames shown are a part
  // of those delivered: shown <= delivered, equal when none was dropped between. (The shown rate was taken between
  // the first and last display: when the first frame took longer than the last - a full detection, a warm-up - that
  // span was the shorter, and 60 frames delivered at 31.2 a second read as 31.5 shown.)
  if (rows.size() >= 2 && rows.back().arrival_s > rows.front().arrival_s) {
    const double span_s = rows.back().arrival_s - rows.front().arrival_s;
    s.shown_fps = (rows.size() - 1) / span_s;
    s.delivered_fps = (rows.back().frame - rows.front().frame) / span_s;
  }
  return s;
}

std::string SummaryLine(const LiveSummary& s) {
  const int delivered = s.shown + s.dropped;
  // No frame shown: no latency or rate to give (a 0.0 ms median would read as a measurement).
  if (s.shown == 0)
    return "no frames shown, " + std::to_string(s.dropped) + " dropped: no latency to give" +
           (s.preloaded_frames > 0 ? "; " + std::to_string(s.preloaded_frames) + " frames preloaded" : std::string());
  char line[400];
  std::snprintf(line, sizeof line,
                "%d frames shown, %d dropped (%.1f %%); latency median %.1f ms, p95 %.1f ms, max %.1f ms; "
                "%d found, %d tracked, %d lost; %.1f frames a second shown of %.1f delivered",
                s.shown, s.dropped, delivered > 0 ? 100.0 * s.dropped / delivered : 0.0, s.median_latency_ms,
                s.p95_latency_ms, s.max_latency_ms, s.found, s.tracked, s.lost, s.shown_fps, s.delivered_fps);
  std::string out = line;
  // What the frames cost the computer, which other work on it inflates less than their latency.
  if (s.cpu_ms_per_frame > 0) {
    char cpu[80];
    std::snprintf(cpu, sizeof cpu, "; %.1f ms of CPU a frame shown", s.cpu_ms_per_frame);
    out += cpu;
  }
  // --preload: the decoding a camera never costs was done before the start, and no latency holds it.
  if (s.preloaded_frames > 0)
    out += "; decoding taken out (--preload: " + std::to_string(s.preloaded_frames) + " frames decoded before the start)";
  // --measure-sections: whether the lens model was ever fitted live, else the run drew with the given one throughout.
  if (s.sections_per_frame > 0)
    return out + (s.lens_sections > 0 ? "; lens model fitted live to " + std::to_string(s.lens_sections) + " readings"
                                       : std::string("; lens model never fitted live (readings on fewer than 3 "
                                                     "edges, or no fit found one): the given one throughout"));
  return out;
}

Json SummaryJson(const LiveSummary& s) {
  Json j;
  j["frames_shown"] = s.shown;
  j["frames_dropped"] = s.dropped;
  j["found"] = s.found;
  j["tracked"] = s.tracked;
  j["lost"] = s.lost;
  j["median_latency_ms"] = s.median_latency_ms;
  j["p95_latency_ms"] = s.p95_latency_ms;
  j["max_latency_ms"] = s.max_latency_ms;
  j["median_track_ms"] = s.median_track_ms;
  j["median_render_ms"] = s.median_render_ms;
  j["median_measure_ms"] = s.median_measure_ms;
  j["sections_per_frame"] = s.sections_per_frame;
  j["lens_sections"] = s.lens_sections;
  j["shown_fps"] = s.shown_fps;
  j["delivered_fps"] = s.delivered_fps;
  j["ended"] = s.ended;
  j["preloaded_frames"] = s.preloaded_frames;
  j["cpu_ms_per_frame_shown"] = s.cpu_ms_per_frame;
  // No frame shown: the times and rates are not determined (null), not 0.
  if (s.shown == 0)
    for (const char* key : {"median_latency_ms", "p95_latency_ms", "max_latency_ms", "median_track_ms",
                            "median_render_ms", "median_measure_ms", "shown_fps", "delivered_fps",
                            "cpu_ms_per_frame_shown"})
      j[key] = nullptr;
  return j;
}

}  // namespace blurcue::live
