#include "bench/track_bench.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <future>
#include <map>
#include <optional>
#include <fstream>
#include <sstream>

#include <opencv2/imgcodecs.hpp>  // its flags (the functions: core/media.h)
#include "bench/clock.h"
#include "bench/scratch.h"
#include "core/media.h"

#include "calib/calibrate.h"
#include "calib/truth.h"
#include "core/atomic_file.h"
#include "core/data_dir.h"
#include "core/error.h"
#include "core/json_io.h"
#include "core/process.h"
#include "synth/take.h"
#include "track/tracker.h"

namespace blurcue::bench {
namespace {

using detail::Clock;
using detail::Ms;

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

// Whether the command's calib.json holds the in-process calibration's sections (depth and r_px, exactly: JSON keeps
// a double's every digit), so the in-process accuracy is the command's.
bool SameSections(const std::filesystem::path& calib_json, const calib::CalibResult& c) {
  const Json j = ReadJsonFile(calib_json);
  const Json& edges = j.at("edges");
  if (edges.size() != c.edges.size()) return false;
  for (size_t e = 0; e < c.edges.size(); ++e) {
    const Json& sections = edges[e].at("sections");
    if (sections.size() != c.edges[e].sections.size()) return false;
    for (size_t k = 0; k < sections.size(); ++k) {
      const calib::SectionResult& s = c.edges[e].sections[k];
      if (sections[k].at("u_mm").get<double>() != s.u_mm || sections[k].at("r_px").get<double>() != s.fit.r_px)
        return false;
    }
  }
  return true;
}

// `calibrate` as the command on each frame, one process a frame, the way an experimenter would without `track`:
// start-up, PNG decode, detection, measurement, the model, calib.json written. The frames and camera.json are
// written beforehand (a camera's files), outside the timing. `rows` holds the in-process calibrate's rows, whose
// accuracy a process's row takes when it wrote the same sections (`calibrated`).
std::vector<TrackRow> CalibrateProcessRows(const std::vector<std::vector<uint8_t>>& png, const Camera& camera,
                                           const Board& board, const std::vector<TrackRow>& rows,
                                           const std::vector<std::optional<calib::CalibResult>>& calibrated,
                                           const TrackBenchOptions& options) {
  const int frames = int(png.size());
  const std::filesystem::path exe = ExecutableDir() / "blurcue";
  const std::filesystem::path dir = detail::MakeScratchFolder("blurcue-bench-track-");
  WriteJsonFile(dir / "camera.json", CameraToJson(camera));
  std::map<int, const TrackRow*> in_process;
  for (const TrackRow& r : rows)
    if (r.mode == "calibrate") in_process[r.frame] = &r;
  std::vector<TrackRow> process_rows;
  for (int i = 0; i < frames; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "frame-%04d", i);
    const std::filesystem::path png_path = dir / (std::string(name) + ".png"), out = dir / (std::string(name) + ".json");
    std::ofstream(png_path, std::ios::binary).write(reinterpret_cast<const char*>(png[i].data()), png[i].size());
    TrackRow row = *in_process.at(i);  // accuracy: the in-process calibration's, when the command wrote the same
    row.mode = "calibrate-process";
    row.pose_ms = row.measure_ms = row.decode_ms = 0;  // not seen from outside the process
    ProcessTimes times;
    const int status = RunProcess({exe.string(), "calibrate", png_path.string(), "--camera", (dir / "camera.json").string(),
                               "--board", std::to_string(board.cols) + "x" + std::to_string(board.rows), "--square-mm",
                               std::to_string(board.square_mm), "--out", out.string(), "--quiet"},
                              &times);
    row.frame_ms = row.period_ms = times.wall_ms, row.cpu_ms = times.cpu_ms;
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    row.status = code == 0 ? "found" : "lost";
    // A command that failed, or wrote other numbers than the library gave in this process, has no accuracy here.
    const bool same = code == 0 && calibrated[i] && SameSections(out, *calibrated[i]);
    if (!same) {
      const double nan = std::nan("");
      row.max_depth_error_rel = row.translation_error_mm = row.r_median_rel_error = row.r_p90_rel_error =
          row.fitted_median_rel_error = nan;
      row.answered = 0;
    }
    process_rows.push_back(row);
    if (options.progress)
      options.progress("calibrate (one process) frame " + std::to_string(i) + ": " + row.status + ", " +
                       std::to_string(row.frame_ms).substr(0, 6) + " ms" + (same ? "" : " (numbers differ)"));
  }
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
  return process_rows;
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
  std::vector<std::optional<calib::CalibResult>> calibrated(frames);  // the in-process calibrate's, per frame
  for (const std::string mode : {"track", "track-inline", "track-serial", "detect", "calibrate"}) {
    track::TrackOptions to;
    to.always_detect = mode == "detect";
    to.calibrate.parallel_sections = mode != "track-serial";
    track::Tracker tracker(camera, board, to);
    std::vector<track::FrameResult> results;
    std::vector<TrackRow> mode_rows;
    // track decodes ahead as track::TrackTake does: frame i + 1 on a thread of its own while frame i is processed.
    const bool ahead = mode == "track";
    auto decode = [&png](int i, cv::Mat* photo) {
      const auto t0 = Clock::now();
      *photo = media::Imdecode(png[i], cv::IMREAD_COLOR);
      return Ms(t0);
    };
    cv::Mat decoded[2];
    auto last_end = Clock::now();
    std::future<double> next;
    if (ahead) next = std::async(std::launch::async, decode, 0, &decoded[0]);
    for (int i = 0; i < frames; ++i) {
      TrackRow row;
      row.mode = mode;
      row.frame = i;
      cv::Mat photo;
      if (ahead) {
        row.decode_ms = next.get();
        photo = decoded[i % 2];
        if (i + 1 < frames) next = std::async(std::launch::async, decode, i + 1, &decoded[(i + 1) % 2]);
      } else {
        row.decode_ms = decode(i, &photo);
      }
      auto t0 = Clock::now();
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
        calibrated[i] = c;
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
      mode_rows.back().period_ms = ahead ? Ms(last_end) : row.decode_ms + mode_rows.back().frame_ms;
      last_end = Clock::now();
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

  const std::vector<TrackRow> process_rows = CalibrateProcessRows(png, camera, board, rows, calibrated, options);
  rows.insert(rows.end(), process_rows.begin(), process_rows.end());
  return rows;
}

void WriteTrackCsv(const std::vector<TrackRow>& rows, const std::filesystem::path& path, bool quick) {
  std::string text =
      "mode,frame,status,frame_ms,cpu_ms,pose_ms,measure_ms,decode_ms,period_ms,max_depth_error_rel,translation_error_mm,"
      "answered,sections,r_median_rel_error,r_p90_rel_error,fitted_median_rel_error,quick\n";
  for (const auto& r : rows) {
    char line[512];
    std::snprintf(line, sizeof line, "%s,%d,%s,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3e,%.4f,%d,%d,%.5f,%.5f,%.5f,%d\n",
                  r.mode.c_str(), r.frame, r.status.c_str(), r.frame_ms, r.cpu_ms, r.pose_ms, r.measure_ms, r.decode_ms,
                  r.period_ms,
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
  std::snprintf(line, sizeof line, "%-17s %6s %9s %9s %9s %9s %9s %9s %12s %11s %11s\n", "mode", "frames", "median_ms",
                "period_ms", "cpu_ms", "p90_ms", "pose_ms", "meas_ms", "depth_err_%", "r_med_err_%", "r_p90_err_%");
  out << line;
  for (const std::string mode : {"track", "track-inline", "track-serial", "detect", "calibrate", "calibrate-process"}) {
    const auto& g = by_mode[mode];
    if (g.empty()) continue;
    std::vector<double> ms, pose, meas, depth, rmed, rp90;
    int tracked = 0;
    for (const TrackRow* r : g) {
      ms.push_back(r->frame_ms), pose.push_back(r->pose_ms), meas.push_back(r->measure_ms);
      depth.push_back(r->max_depth_error_rel), rmed.push_back(r->r_median_rel_error), rp90.push_back(r->r_p90_rel_error);
      tracked += r->status == "tracked";
    }
    std::snprintf(line, sizeof line, "%-17s %6zu %9.1f %9.1f %9.1f %9.1f %9.1f %9.1f %12.4f %11.2f %11.2f%s\n",
                  mode.c_str(), g.size(), Quantile(ms, 0.5), median_of(mode, &TrackRow::period_ms),
                  median_of(mode, &TrackRow::cpu_ms), Quantile(ms, 0.9), Quantile(pose, 0.5), Quantile(meas, 0.5),
                  100 * *std::max_element(depth.begin(), depth.end()), 100 * Quantile(rmed, 0.5),
                  100 * *std::max_element(rp90.begin(), rp90.end()),
                  mode == "track" ? (" (" + std::to_string(tracked) + " tracked)").c_str() : "");
    out << line;
  }
  out << "(median_ms: the frame's work, decoding excluded; period_ms: decoding included, track decoding the next frame "
         "while it works, as blurcue track does; depth_err: worst section of any frame; r_med_err: median over frames "
         "of the frame's median; r_p90_err: worst frame's p90)\n";
  // The ratios measured in this run: against the command run once a frame (the comparison) and against the
  // same library call in this process.
  if (!by_mode["track-inline"].empty() && median_of("track", &TrackRow::period_ms) > 0) {
    std::snprintf(line, sizeof line, "track decoding the next frame meanwhile: %.2fx faster a frame than decoding in line "
                  "(track-inline), decoding included\n",
                  median_of("track-inline", &TrackRow::period_ms) / median_of("track", &TrackRow::period_ms));
    out << line;
  }
  // The target counts decoding in: track's period (the next frame decoded meanwhile) against the command's
  // whole wall time and the in-process calibrate's decode + work.
  const double work = median_of("track", &TrackRow::frame_ms), track = median_of("track", &TrackRow::period_ms);
  const double track_cpu = median_of("track", &TrackRow::cpu_ms);
  if (track > 0) {
    std::snprintf(line, sizeof line,
                  "track: median %.1f ms a frame wall, decoding included (%.1f ms of work, decoding excluded; %.1f ms "
                  "CPU; target <= 33 ms decoding included: %s)\n",
                  track, work, track_cpu, track <= 33 ? "met" : "NOT met");
    out << line;
    for (const std::string mode : {"calibrate-process", "calibrate"}) {
      if (by_mode[mode].empty()) continue;
      const double wall = median_of(mode, &TrackRow::period_ms), cpu = median_of(mode, &TrackRow::cpu_ms);
      const bool process = mode == "calibrate-process";
      std::snprintf(line, sizeof line, "track vs %s: %.1fx faster a frame wall, %.1fx CPU%s\n",
                    process ? "calibrate run as a command on each frame" : "calibrate in this process", wall / track,
                    track_cpu > 0 ? cpu / track_cpu : 0.0,
                    process ? (wall / track >= 6 ? " (target >= 6x: met)" : " (target >= 6x: NOT met)") : "");
      out << line;
    }
  }
  return out.str();
}

}  // namespace blurcue::bench
