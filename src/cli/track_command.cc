// blurcue track: a video or image sequence tracked frame by frame (src/track).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "core/camera.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/output_guard.h"
#include "core/own_output.h"
#include "optics/fit.h"
#include "track/take.h"

namespace blurcue::cli {

namespace {

// What a take came to: its frames, how each was found, the take's lens model, what was written.
void PrintTakeSummary(const track::TakeResult& take, const Camera& camera, const std::string& out,
                      std::chrono::steady_clock::time_point t0) {
  const int n = static_cast<int>(take.frames.size());
  std::vector<double> ms;
  for (const auto& f : take.frames) ms.push_back(f.frame_ms);
  std::sort(ms.begin(), ms.end());
  const double median = ms.empty() ? 0 : (ms.size() % 2 ? ms[ms.size() / 2]
                                                         : 0.5 * (ms[ms.size() / 2 - 1] + ms[ms.size() / 2]));
  std::printf("%d frames: %d tracked, %d found by full detection, %d lost; median %.1f ms a frame (decoding, "
              "%.1f ms a frame, done meanwhile on a thread of its own)\n",
              n, take.tracked, take.found, take.lost, median, n > 0 ? take.decode_ms / n : 0.0);
  if (take.model) {
    const auto& m = *take.model;
    std::printf("the take's lens model (%s, %d sections): focus %s mm, aperture %.3f mm (nominal %.3f), %s, "
                "rms %.3f px\n",
                m.kind.c_str(), m.samples_used,
                std::isinf(m.focus_mm) ? "infinity" : std::to_string(m.focus_mm).substr(0, 7).c_str(),
                m.aperture_mm, camera.ApertureMm(), optics::FloorText(m).c_str(), m.rms_px);
  }
  std::printf("wrote %s/track.csv and %d calib-NNNN.json in %.1f s\n", out.c_str(), n - take.lost,
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

}  // namespace

void AddTrackCommand(CLI::App& app) {
  struct Args {
    std::string input, camera, out, board = "7x10";
    double square_mm = 25, fps = 30, max_track_error_px = 0.5;
    bool detect_every_frame = false, quiet = false, board_turned = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "track",
      "Track a video or image sequence of the board: pose and blur frame by frame, one lens model per take.\n"
      "INPUT is a video file (whatever OpenCV's videoio reads) or an image sequence given as a printf pattern\n"
      "numbered from 0 (frames/frame-%04d.png). For every frame the board's corners are carried from the previous\n"
      "frames (predicted at constant velocity and refined where they are; a full detection when there is no history\n"
      "or the refined corners do not fit a pose, flagged 'found'), the pose is solved, every edge section's blur is\n"
      "measured as `calibrate` measures it, and one thin-lens model (fixed focus and aperture) is fitted to every\n"
      "usable section of the whole take.\n"
      "\n"
      "Writes to --out DIR:\n"
      "  calib-0000.json ...  one per frame with a pose, in calibrate's calib.json format (the take's lens model)\n"
      "  track.csv            one row per frame: frame, time_s, status (found | tracked | lost), reprojection error,\n"
      "                       pose, the lens model's focus, aperture and floor, usable sections, ms spent\n"
      "A damaged or truncated video, or a frame missing from a sequence, ends the take: what was tracked before it\n"
      "is written, and the error is reported (exit 3). docs/track.md explains the output.\n"
      "DIR is built beside its place and swapped in whole: an earlier track there stays until the new one is\n"
      "complete. DIR must be new or hold only a track's files, its track.csv among them, and may not hold the take.\n"
      "Example: blurcue track take/frame-%04d.png --camera take/camera.json --out take/track");
  cmd->add_option("input", args->input, "video file, or printf pattern of an image sequence (frame-%04d.png)")
      ->required();
  cmd->add_option("--camera", args->camera, "camera.json of the camera that shot the take")
      ->required()->check(CLI::ExistingFile);
  cmd->add_option("--out", args->out, "folder to write calib-NNNN.json and track.csv to (created)")->required();
  cmd->add_option("--board", args->board, "board size in squares, COLSxROWS")->capture_default_str();
  cmd->add_option("--square-mm", args->square_mm, "side of one square in mm")->capture_default_str()
      ->check(FiniteRange(1, 1000, "mm"));
  cmd->add_option("--fps", args->fps, "frame rate of an image sequence (a video's own rate is used when it has one)")
      ->capture_default_str()->check(FiniteRange(track::kMinFps, track::kMaxFps, "frames per second"));
  cmd->add_option("--max-track-error-px", args->max_track_error_px,
                  "a tracked pose whose corners' rms reprojection error exceeds this falls back to full detection")
      ->capture_default_str()->check(FinitePositive(100, "px"));
  cmd->add_flag("--detect-every-frame", args->detect_every_frame, "full detection on every frame (no tracking)");
  cmd->add_flag("--board-turned", args->board_turned,
                "take a board found with its edges within 10 deg of running straight away from the camera (refused\n"
                "without it, as calibrate refuses it: every edge then lies at one depth, and a 10x7 board so found is\n"
                "likelier a 7x10 one)");
  cmd->add_flag("--quiet", args->quiet, "print only errors");
  cmd->callback([args] {
    const auto t0 = std::chrono::steady_clock::now();
    // Every refusal before the first frame is read: the output's kind and place, and an input that is a FIFO.
    {
      OutputGuard guard;
      for (const std::filesystem::path& file : track::TakeInputFiles(args->input)) guard.Input("INPUT", file);
      guard.Input("--camera", args->camera).OutputFolder("--out", args->out).Check();
      try {
        RequireReplaceableFolder(args->out, track::IsTrackFile);
      } catch (const Error& e) {
        throw e.Wrapped(e.kind(), "--out ");
      }
      // A folder of one's own calib-NNNN.json or a track.csv of another tool passed the names' check and was
      // replaced: a take track wrote always holds its track.csv, with this header.
      RequireMarkedFolder("--out", args->out, "track.csv", "a take track wrote", "one's own calib-NNNN.json files?");
      RequireOwnFile("--out", std::filesystem::path(args->out) / "track.csv", "a track.csv track wrote",
                     BeginsWith("frame,time_s,status,reprojection_error_px,"));
      RemoveLeftoversBeside("track", args->out);
    }
    const Board board = Board::Parse(args->board, args->square_mm);
    const Camera camera = LoadCamera(args->camera);
    track::FrameSource source(args->input, args->fps);
    track::TrackOptions options;
    options.max_track_error_px = args->max_track_error_px;
    options.always_detect = args->detect_every_frame;
    // The check calibrate makes (calib/board_pose.h): a board detected with its edges running into depth is refused,
    // before anything is written, naming the frame; --board-turned takes it.
    options.calibrate.detect.refuse_edges_into_depth_deg = args->board_turned ? 0 : 10;
    track::Tracker tracker(camera, board, options);
    const int expected = source.expected_frames();
    auto progress = [&](const track::FrameResult& r) {
      if (args->quiet) return;
      int usable = 0;
      if (r.calib)
        for (const auto& e : r.calib->edges) usable += e.usable;
      std::fprintf(stderr, "frame %d%s: %-7s %s%d sections usable, %.1f ms%s%s\n", r.index,
                   expected > 0 ? ("/" + std::to_string(expected)).c_str() : "", track::Name(r.status),
                   r.calib ? ("reprojection " + std::to_string(r.calib->pose.reprojection_error_px).substr(0, 5) +
                              " px, ").c_str()
                           : "",
                   usable, r.frame_ms, r.note.empty() ? "" : " - ", r.note.c_str());
    };
    const track::TakeResult take = [&] {
      try {
        return track::TrackTake(source, tracker, progress);
      } catch (const Error& e) {
        if (e.kind() != ErrorKind::kUsage) throw;
        throw e.Wrapped(ErrorKind::kUsage, args->input + ": ");
      }
    }();
    track::WriteTake(take, args->out, args->input);
    const int n = static_cast<int>(take.frames.size());
    if (!args->quiet) PrintTakeSummary(take, camera, args->out, t0);
    if (take.error) {
      const std::string kept = n > 0 ? "; the " + std::to_string(n) + " frames before it are in " + args->out
                                     : "; no frame was read";
      throw Error(take.error->kind(), std::string(take.error->what()) + kept);
    }
  });
}

}  // namespace blurcue::cli
