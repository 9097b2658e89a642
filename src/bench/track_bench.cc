#include "bench/track_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <map>
#include <optional>
#include <sstream>

#include <opencv2/imgcodecs.hpp>  // its flags (the functions: core/media.h)
#include "core/media.h"

#include "calib/calibrate.h"
#include "calib/truth.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "synth/take.h"
#include "track/tracker.h"

namespace blurcue::bench {
namespace {

using Clock = std::chrono::steady_clock;
double Ms(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

// CPU time of the whole process (every thread), ms.
double CpuMs() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const double pos = q * (v.size() - 1);
  const size_t lo = static_cast<size_t>(pos);
  const size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - lo) * (v[hi] - v[lo]);
}

// The row's accuracy from the frame's calibration against the frame's truth.
void Score(TrackRow& row, const calib::CalibResult& c, const synth::Scene& truth) {
  const calib::TruthComparison cmp = calib::CompareToTruth(c, truth.truth, "truth");
  const calib::MethodSummary m = calib::SummarizeMethod(cmp, &calib::SectionComparison::model);
  row.answered = m.answered;
  row.sections = m.sections;
  row.r_median_rel_error = m.median_rel_error;
  row.r_p90_rel_error = m.p90_rel_error;
  row.fitted_median_rel_error = calib::SummarizeMethod(cmp, &calib::SectionComparison::fitted).median_rel_error;
  row.translation_error_mm = cmp.translation_error_mm;
  row.max_depth_error_rel = 0;
  size_t k = 0;
  for (const auto& edge : c.edges)
    for (const auto& s : edge.sections) {
      const double u = truth.sections[k++].u_mm;
      row.max_depth_error_rel = std::max(row.max_depth_error_rel, std::abs(s.u_mm - u) / u);
    }
}

}  // namespace

std::vector<TrackRow> RunTrackBench(const TrackBenchOptions& options) {
  synth::TakeOptions take;  // 1148 x 764, edge 1 from 440 to 360 mm and 50 mm sideways, focus 450 mm, floor 0.35 px
  take.frames = options.frames;
  // A quick run renders the first 4 frames of the same path: the same motion from frame to frame as a full run.
  const int frames = options.quick ? std::min(4, take.frames) : take.frames;
  take.scene.noise_std = 0.004;
  take.scene.seed = options.seed;
  // Each frame as a camera would deliver it: encoded to PNG and decoded again, the decode timed apart.
  std::vector<synth::Scene> truth;
  std::vector<std::vector<uint8_t>> png;
  for (int i = 0; i < frames; ++i) {
    const auto t0 = Clock::now();
    synth::TakeFrame f = synth::RenderTakeFrame(take, i);
    png.emplace_back();
    media::Imencode(".png", f.scene.image, &png.back());
    truth.push_back(std::move(f.scene));
    if (options.progress)
      options.progress("rendered frame " + std::to_string(i + 1) + "/" + std::to_string(frames) + " in " +
                       std::to_string(int(Ms(t0))) + " ms");
  }
  const Camera camera = truth[0].camera;
  const Board board = truth[0].board;

  std::vector<TrackRow> rows;
  for (const std::string mode : {"track", "detect", "calibrate"}) {
    track::TrackOptions to;
    to.always_detect = mode == "detect";
    track::Tracker tracker(camera, board, to);
    std::vector<track::FrameResult> results;
    std::vector<TrackRow> mode_rows;
    for (int i = 0; i < frames; ++i) {
      TrackRow row;
      row.mode = mode;
      row.frame = i;
      auto t0 = Clock::now();
      const cv::Mat photo = media::Imdecode(png[i], cv::IMREAD_COLOR);
      row.decode_ms = Ms(t0);
      if (mode == "calibrate") {
        t0 = Clock::now();
        const double cpu0 = CpuMs();
        std::optional<calib::CalibResult> c;
        try {
          c = calib::Calibrate(photo, camera, board);
        } catch (const Error& e) {
          if (e.kind() != ErrorKind::kNotFound) throw;
        }
        row.frame_ms = Ms(t0);
        row.cpu_ms = CpuMs() - cpu0;
        row.status = c ? "found" : "lost";
        if (c) {
          row.pose_ms = c->detect_ms;
          row.measure_ms = c->measure_ms + c->estimate_ms;
          Score(row, *c, truth[i]);
        }
        mode_rows.push_back(row);
      } else {
        const double cpu0 = CpuMs();
        results.push_back(tracker.Process(photo, i, i / take.fps));
        row.cpu_ms = CpuMs() - cpu0;
        const track::FrameResult& r = results.back();
        row.status = track::Name(r.status);
        row.frame_ms = r.frame_ms;
        row.pose_ms = r.pose_ms;
        row.measure_ms = r.measure_ms;
        mode_rows.push_back(row);
      }
      if (options.progress)
        options.progress(mode + " frame " + std::to_string(i) + ": " + mode_rows.back().status + ", " +
                         std::to_string(mode_rows.back().frame_ms).substr(0, 6) + " ms");
    }
    if (mode != "calibrate") {
      // The take's one lens model is fitted after the last frame (its time is the take's, not a frame's).
      track::FitTakeModel(results);
      for (size_t i = 0; i < results.size(); ++i)
        if (results[i].calib) Score(mode_rows[i], *results[i].calib, truth[i]);
    }
    rows.insert(rows.end(), mode_rows.begin(), mode_rows.end());
  }
  return rows;
}

void WriteTrackCsv(const std::vector<TrackRow>& rows, const std::filesystem::path& path, bool quick) {
  std::string text =
      "mode,frame,status,frame_ms,cpu_ms,pose_ms,measure_ms,decode_ms,max_depth_error_rel,translation_error_mm,answered,"
      "sections,r_median_rel_error,r_p90_rel_error,fitted_median_rel_error,quick\n";
  for (const auto& r : rows) {
    char line[512];
    std::snprintf(line, sizeof line, "%s,%d,%s,%.3f,%.3f,%.3f,%.3f,%.3f,%.3e,%.4f,%d,%d,%.5f,%.5f,%.5f,%d\n",
                  r.mode.c_str(), r.frame, r.status.c_str(), r.frame_ms, r.cpu_ms, r.pose_ms, r.measure_ms, r.decode_ms,
                  r.max_depth_error_rel, r.translation_error_mm, r.answered, r.sections, r.r_median_rel_error,
                  r.r_p90_rel_error, r.fitted_median_rel_error, int(quick));
    text += line;
  }
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  WriteFileAtomically(path, text);
}

std::string SummarizeTrackBench(const std::vector<TrackRow>& rows) {
  std::map<std::string, std::vector<const TrackRow*>> by_mode;
  for (const auto& r : rows) by_mode[r.mode].push_back(&r);
  auto median_of = [&](const std::string& mode, double TrackRow::*field) {
    std::vector<double> ms;
    for (const TrackRow* r : by_mode[mode]) ms.push_back(r->*field);
    return Quantile(ms, 0.5);
  };
  std::ostringstream out;
  char line[512];
  std::snprintf(line, sizeof line, "%-10s %6s %9s %9s %9s %9s %9s %12s %11s %11s\n", "mode", "frames", "median_ms", "cpu_ms",
                "p90_ms", "pose_ms", "meas_ms", "depth_err_%", "r_med_err_%", "r_p90_err_%");
  out << line;
  for (const std::string mode : {"track", "detect", "calibrate"}) {
    const auto& g = by_mode[mode];
    if (g.empty()) continue;
    std::vector<double> ms, pose, meas, depth, rmed, rp90;
    int tracked = 0;
    for (const TrackRow* r : g) {
      ms.push_back(r->frame_ms), pose.push_back(r->pose_ms), meas.push_back(r->measure_ms);
      depth.push_back(r->max_depth_error_rel), rmed.push_back(r->r_median_rel_error), rp90.push_back(r->r_p90_rel_error);
      tracked += r->status == "tracked";
    }
    std::snprintf(line, sizeof line, "%-10s %6zu %9.1f %9.1f %9.1f %9.1f %9.1f %12.4f %11.2f %11.2f%s\n", mode.c_str(),
                  g.size(), Quantile(ms, 0.5), median_of(mode, &TrackRow::cpu_ms), Quantile(ms, 0.9), Quantile(pose, 0.5), Quantile(meas, 0.5),
                  100 * *std::max_element(depth.begin(), depth.end()), 100 * Quantile(rmed, 0.5),
                  100 * *std::max_element(rp90.begin(), rp90.end()),
                  mode == "track" ? (" (" + std::to_string(tracked) + " tracked)").c_str() : "");
    out << line;
  }
  out << "(depth_err: worst section of any frame; r_med_err: median over frames of the frame's median; r_p90_err: "
         "worst frame's p90)\n";
  const double track = median_of("track", &TrackRow::frame_ms), calibrate = median_of("calibrate", &TrackRow::frame_ms);
  const double track_cpu = median_of("track", &TrackRow::cpu_ms), calibrate_cpu = median_of("calibrate", &TrackRow::cpu_ms);
  if (track > 0 && calibrate > 0) {
    std::snprintf(line, sizeof line,
                  "track: median %.1f ms a frame wall, %.1f ms CPU (target <= 33 ms: %s); %.1fx faster than calibrate "
                  "a frame wall, %.1fx CPU (target >= 6x: %s)\n",
                  track, track_cpu, track <= 33 ? "met" : "NOT met", calibrate / track,
                  track_cpu > 0 ? calibrate_cpu / track_cpu : 0.0, calibrate / track >= 6 ? "met" : "NOT met");
    out << line;
  }
  return out.str();
}

}  // namespace blurcue::bench
