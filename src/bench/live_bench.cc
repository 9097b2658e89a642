#include "bench/live_bench.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include "bench/scratch.h"
#include "calib/calibrate.h"
#include "core/atomic_file.h"
#include "core/csv.h"
#include "core/data_dir.h"
#include "core/error.h"
#include "core/json_io.h"
#include "core/process.h"
#include "core/stats.h"
#include "optics/thin_lens.h"
#include "synth/take.h"

namespace blurcue::bench {
namespace {

// The ball the bench draws: board mm (x, y), radius 10 mm - the one the live tests draw (tests/live_test.sh).
constexpr const char* kBall = "87.5,125";
constexpr double kSettledRelError = 0.02;  // LiveBenchRow::settle_frames

double LoadAverage() {
  std::ifstream in("/proc/loadavg");
  double load = 0;
  in >> load;
  return load;
}

// A CSV's rows as name -> field maps (the header names the columns).
std::vector<std::map<std::string, std::string>> ReadTable(const std::filesystem::path& path) {
  const CsvText csv = ParseCsv(ReadTextFile(path, "a CSV file"), 1000000);
  if (!csv.problems.empty() || csv.records.empty())
    throw InputError(path.string(), csv.problems.empty() ? "is empty" : csv.problems[0].message);
  RequireFullRecords(csv, path.string());
  std::vector<std::map<std::string, std::string>> rows;
  const std::vector<std::string>& header = csv.records[0].fields;
  for (size_t i = 1; i < csv.records.size(); ++i) {
    std::map<std::string, std::string> row;
    for (size_t k = 0; k < header.size(); ++k) row[header[k]] = csv.records[i].fields[k];
    rows.push_back(std::move(row));
  }
  return rows;
}

// The take's true blur at depth u: its thin lens (focus, aperture) and the floor it applied, r = 2 std (DESIGN.md).
struct TrueLens {
  optics::Lens lens;
  double focus_mm = 0, floor_sigma_px = 0;
  double RPx(double u_mm) const {
    const double defocus = optics::BlurRadiusPx(lens, focus_mm, u_mm);
    return std::sqrt(defocus * defocus + 4 * floor_sigma_px * floor_sigma_px);
  }
};

TrueLens ReadTrueLens(const std::filesystem::path& truth_json, const Camera& camera) {
  const Json t = ReadJsonFile(truth_json);
  TrueLens truth;
  truth.lens = optics::Lens::FromCamera(camera);
  truth.lens.aperture_mm = t.at("aperture_mm").get<double>();
  truth.focus_mm = t.at("focus_mm").get<double>();
  truth.floor_sigma_px = t.at("floor_sigma_applied_px").get<double>();
  return truth;
}

// The given lens model: calibrate's of the take's first frame rendered with the focus at kLiveBenchStaleFocusMm.
void WriteStaleCalib(synth::TakeOptions take, const std::filesystem::path& path) {
  take.scene.focus_mm = kLiveBenchStaleFocusMm;
  const synth::TakeFrame frame = synth::RenderTakeFrame(take, 0);
  WriteJsonFile(path, calib::CalibToJson(calib::Calibrate(frame.scene.image, frame.scene.camera, frame.scene.board)));
}

// One row from a live run's log: its summary, its per-frame sections, and the ball's r against the truth.
LiveBenchRow ScoreRun(int n, const std::filesystem::path& log, const TrueLens& truth) {
  LiveBenchRow row;
  row.sections_per_frame = n;
  const Json s = ReadJsonFile(log / "summary.json");
  row.frames_shown = s.at("frames_shown").get<int>();
  row.frames_dropped = s.at("frames_dropped").get<int>();
  row.frames_delivered = row.frames_shown + row.frames_dropped;
  row.median_latency_ms = s.at("median_latency_ms").get<double>();
  row.p95_latency_ms = s.at("p95_latency_ms").get<double>();
  row.median_track_ms = s.at("median_track_ms").get<double>();
  row.median_measure_ms = s.at("median_measure_ms").get<double>();
  row.median_render_ms = s.at("median_render_ms").get<double>();
  row.cpu_ms_per_frame = s.at("cpu_ms_per_frame_shown").get<double>();
  for (const auto& r : ReadTable(log / "live.csv")) {
    row.max_sections = std::max(row.max_sections, std::stoi(r.at("sections")));
    row.lens_sections = std::stoi(r.at("lens_sections"));
  }
  std::vector<double> errors;
  for (const auto& r : ReadTable(log / "drawn.csv")) {
    if (r.at("object").empty() || r.at("r_px").empty()) continue;  // a lost frame: nothing drawn
    const double truth_r = truth.RPx(std::stod(r.at("depth_mm")));
    errors.push_back(std::abs(std::stod(r.at("r_px")) - truth_r) / truth_r);
  }
  row.frames_drawn = int(errors.size());
  row.settle_frames = row.frames_drawn;
  while (row.settle_frames > 0 && errors[row.settle_frames - 1] <= kSettledRelError) --row.settle_frames;
  row.r_median_rel_error = Percentile(errors, 0.5);
  const std::vector<double> late(errors.begin() + long(errors.size() * 2 / 3), errors.end());
  row.r_late_median_rel_error = Percentile(late, 0.5);
  row.r_late_max_rel_error = late.empty() ? 0 : *std::max_element(late.begin(), late.end());
  return row;
}

}  // namespace

std::vector<LiveBenchRow> RunLiveBench(const LiveBenchOptions& options) {
  synth::TakeOptions take;  // 1148 x 764, edge 1 from 440 to 360 mm and 50 mm sideways, focus 450 mm, floor 0.35 px
  take.frames = options.quick ? std::min(12, options.frames) : options.frames;
  take.fps = options.fps;
  take.scene.noise_std = 0.004;
  take.scene.seed = options.seed;
  const std::vector<int> sections = options.quick ? std::vector<int>{0, 4, 77} : options.sections;
  // A folder of its own, made new (it used to remove whatever TMPDIR/blurcue-bench-live-PID held first).
  const std::filesystem::path dir = detail::MakeScratchFolder("blurcue-bench-live-");
  const synth::TakeFiles files = synth::WriteTake(take, dir / "take", options.progress);
  // Played as a camera delivers: the video where OpenCV could write one, else the frames, decoded before the clock
  // starts (--preload: a camera hands over decoded frames; FFV1's ~17 ms of CPU a frame is no camera's cost).
  const std::string input = (dir / "take" / (files.video.empty() ? synth::kTakeFramePattern : files.video)).string();
  const Camera camera = LoadCamera(dir / "take" / "camera.json");
  const TrueLens truth = ReadTrueLens(dir / "take" / synth::TakeTruthName(0), camera);
  WriteStaleCalib(take, dir / "stale-calib.json");
  if (options.progress) options.progress("the given lens model: calibrated at a focus of 400 mm (the take's: 450 mm)");

  const std::filesystem::path exe = ExecutableDir() / "blurcue";
  std::vector<LiveBenchRow> rows;
  for (const int n : sections) {
    const std::filesystem::path log = dir / ("live-" + std::to_string(n));
    const double load = LoadAverage();
    ProcessTimes times;
    const std::vector<std::string> argv = {
        exe.string(), "live", input, "--camera", (dir / "take" / "camera.json").string(), "--calib",
        (dir / "stale-calib.json").string(), "--ball", kBall, "--exposure-ms", "16", "--fps",
        std::to_string(options.fps), "--preload", "--measure-sections", std::to_string(n), "--log", log.string(),
        "--quiet"};
    const int status = RunProcess(argv, &times);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
      throw Error(ErrorKind::kInternal, "blurcue live --measure-sections " + std::to_string(n) + " failed (status " +
                                            std::to_string(status) + "); its input stays in " + dir.string());
    LiveBenchRow row = ScoreRun(n, log, truth);
    row.cpu_ms = times.cpu_ms;
    row.load1 = load;
    rows.push_back(row);
    if (options.progress)
      options.progress("--measure-sections " + std::to_string(n) + ": " + std::to_string(row.frames_shown) +
                       " shown, " + std::to_string(row.frames_dropped) + " dropped, latency median " +
                       std::to_string(row.median_latency_ms).substr(0, 6) + " ms (load " +
                       std::to_string(load).substr(0, 4) + ")");
  }
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
  return rows;
}

void WriteLiveBenchCsv(const std::vector<LiveBenchRow>& rows, const std::filesystem::path& path, bool quick) {
  std::string text =
      "sections_per_frame,frames_delivered,frames_shown,frames_dropped,frames_drawn,max_sections,lens_sections,"
      "median_latency_ms,p95_latency_ms,median_track_ms,median_measure_ms,median_render_ms,cpu_ms,cpu_ms_per_frame,"
      "r_median_rel_error,r_late_median_rel_error,r_late_max_rel_error,settle_frames,load1,quick\n";
  for (const LiveBenchRow& r : rows) {
    char line[512];
    std::snprintf(line, sizeof line, "%d,%d,%d,%d,%d,%d,%d,%.3f,%.3f,%.3f,%.3f,%.3f,%.1f,%.2f,%.5f,%.5f,%.5f,%d,%.2f,%d\n",
                  r.sections_per_frame, r.frames_delivered, r.frames_shown, r.frames_dropped, r.frames_drawn,
                  r.max_sections, r.lens_sections, r.median_latency_ms, r.p95_latency_ms, r.median_track_ms,
                  r.median_measure_ms, r.median_render_ms, r.cpu_ms, r.cpu_ms_per_frame, r.r_median_rel_error,
                  r.r_late_median_rel_error,
                  r.r_late_max_rel_error, r.settle_frames, r.load1, int(quick));
    text += line;
  }
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  WriteFileAtomically(path, text);
}

std::string SummarizeLiveBench(const std::vector<LiveBenchRow>& rows) {
  std::ostringstream out;
  char line[512];
  std::snprintf(line, sizeof line, "%9s %6s %8s %9s %10s %8s %7s %8s %9s %9s %9s %7s %5s\n", "sections", "shown",
                "dropped", "latency", "lat_p95", "meas_ms", "cpu_ms", "lens", "r_err_%", "late_%", "late_max%",
                "settle", "load");
  out << line;
  for (const LiveBenchRow& r : rows) {
    const int delivered = std::max(1, r.frames_delivered);
    std::snprintf(line, sizeof line, "%9d %6d %7.1f%% %9.1f %10.1f %8.1f %7.1f %8d %9.2f %9.2f %9.2f %7d %5.2f\n",
                  r.sections_per_frame, r.frames_shown, 100.0 * r.frames_dropped / delivered, r.median_latency_ms,
                  r.p95_latency_ms, r.median_measure_ms, r.cpu_ms_per_frame, r.lens_sections, 100 * r.r_median_rel_error,
                  100 * r.r_late_median_rel_error, 100 * r.r_late_max_rel_error, r.settle_frames, r.load1);
    out << line;
  }
  out << "(frames decoded before the start, --preload, as a camera hands them over; latency: median ms from arrival "
         "to display; meas_ms: median ms a frame measuring sections (the lens is fitted on a thread of its own); "
         "cpu_ms: the process's CPU time a frame shown, every thread; lens: the readings the last frame's model was fitted to, 0: the given one; "
         "r_err: the ball's drawn r against the true lens's, median over the frames drawn; late: over their last "
         "third; settle: frames drawn before every later one is within 2 %)\n";
  // Ratios in this run: what the sections cost against the pose-only run, per section measured.
  const auto base =
      std::find_if(rows.begin(), rows.end(), [](const LiveBenchRow& r) { return r.sections_per_frame == 0; });
  if (base != rows.end())
    for (const LiveBenchRow& r : rows) {
      if (r.sections_per_frame == 0 || base->median_latency_ms <= 0) continue;
      std::snprintf(line, sizeof line,
                    "%d sections a frame: latency %.2fx the pose-only run's, %.2f ms of measuring a section; r error "
                    "%.2f %% against %.2f %% with the given model\n",
                    r.sections_per_frame, r.median_latency_ms / base->median_latency_ms,
                    r.max_sections > 0 ? r.median_measure_ms / r.max_sections : 0.0, 100 * r.r_median_rel_error,
                    100 * base->r_median_rel_error);
      out << line;
    }
  return out.str();
}

}  // namespace blurcue::bench
