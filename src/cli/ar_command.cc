// blurcue ar: the offline AR view of a tracked take - virtual objects drawn in every frame with that frame's pose,
// defocus and motion blur (the thesis's prototype, on video; src/stimulus/tracked_take.h places them).
#include <algorithm>
#include <chrono>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "calib/scene_blur.h"
#include "cli/commands.h"
#include "cli/placed_objects.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/image.h"
#include "core/media.h"
#include "core/output_guard.h"
#include "core/own_output.h"
#include "core/typed.h"
#include "render/frame_compositor.h"
#include "render/gl_context.h"
#include "scene/stimuli.h"
#include "stimulus/tracked_take.h"
#include "track/frames.h"

namespace blurcue::cli {
namespace {

// The most objects one run draws (stimulus::kMaxPlacedObjects), and the most frames: each object is drawn in every
// frame, and the CSV (one row per object per frame) is held until the end, so both are bounded before any work
// (64 x 18000 rows is about 200 MB).
constexpr size_t kMaxArObjects = stimulus::kMaxPlacedObjects;
constexpr int kMaxArFrames = 18000;  // 10 minutes at 30 fps

struct ArArgs {
  std::string input, track, out, csv, frames_dir, blur = "fitted", method = "disc";
  ObjectOptions objects;
  double exposure_ms = -1;
  bool quiet = false;
};

namespace fs = std::filesystem;

// The file ar writes into every --frames folder beside its images: a non-empty folder without it is not one ar
// wrote (one's own frame-NNNN.png images, say) and is refused rather than replaced.
constexpr const char* kArFramesMarker = "ar-frames.txt";

// A name --frames may hold: frame-NNNN.png, and the marker.
bool IsArFrameName(const std::string& name) {
  if (name == kArFramesMarker) return true;
  return name.size() == 14 && name.rfind("frame-", 0) == 0 && name.compare(10, 4, ".png") == 0 &&
         name.find_first_not_of("0123456789", 6) == 10;
}

// Nothing is read or drawn before every output is known to be writable and none is an input: checks them, removes
// what an earlier run left beside them, and returns the CSV's path.
std::string CheckArOutputs(const ArArgs& args) {
  {
    std::string extension = fs::path(args.out).extension().string();
    for (char& c : extension) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (extension != ".avi") throw Error(ErrorKind::kUsage, "--out " + Echo(args.out) + ": must end in .avi");
  }
  const std::string csv_path = args.csv.empty() ? fs::path(args.out).replace_extension(".csv").string() : args.csv;
  if (args.objects.balls.size() + args.objects.cards.size() > kMaxArObjects)
    throw Error(ErrorKind::kUsage, std::to_string(args.objects.balls.size() + args.objects.cards.size()) +
                                       " --ball and --card options: at most " + std::to_string(kMaxArObjects) +
                                       " objects a run");
  {
    OutputGuard guard;
    for (const fs::path& file : track::TakeInputFiles(args.input)) guard.Input("INPUT", file);
    guard.Input("--track", args.track);
    GuardObjectInputs(guard, args.objects);
    guard.OutputFile("--out", args.out).OutputFile(args.csv.empty() ? "the CSV (OUT with .csv)" : "--csv", csv_path);
    if (!args.frames_dir.empty()) guard.OutputFolder("--frames", args.frames_dir);
    guard.Check();
  }
  try {
    if (!args.frames_dir.empty()) RequireReplaceableFolder(args.frames_dir, IsArFrameName);
  } catch (const Error& e) {
    throw e.Wrapped(e.kind(), "--frames ");
  }
  // A folder of frame-NNNN.png alone (one's own images, a take's frames) passed the check above and was replaced.
  if (!args.frames_dir.empty())
    RequireMarkedFolder("--frames", args.frames_dir, kArFramesMarker, "frames ar drew",
                        "one's own frame-NNNN.png images?");
  for (const std::string& target : {args.out, csv_path, args.frames_dir})
    if (!target.empty()) RemoveLeftoversBeside("ar", target);
  return csv_path;
}

// The take within the frame limit, and every object seen in at least one of its frames.
void CheckArTake(const ArArgs& args, const stimulus::TrackedTake& take, const track::FrameSource& source,
                 const std::vector<stimulus::PlacedObject>& objects, const std::vector<std::string>& given) {
  if (int(take.frames.size()) > kMaxArFrames || source.expected_frames() > kMaxArFrames)
    throw InputError(int(take.frames.size()) > kMaxArFrames ? args.track : args.input,
                     std::to_string(std::max(int(take.frames.size()), source.expected_frames())) +
                         " frames: ar draws at most " + std::to_string(kMaxArFrames) + " a run");
  // An object in no frame's photo would leave a video without it and a summary that counts it drawn: a slip of
  // millimetres (400 for 40) is refused before anything is written.
  for (size_t i = 0; i < objects.size(); ++i) {
    if (!stimulus::SeenInAnyFrame(take, objects[i].object))
      throw InputError(given[i], objects[i].name + " at (" + Num(objects[i].object.center_board_mm[0]) + ", " +
                                     Num(objects[i].object.center_board_mm[1]) +
                                     ") mm on the board lies outside the photo in every frame of the take (the board "
                                     "is " + Num(take.board().WidthMm()) + " x " + Num(take.board().LengthMm()) +
                                     " mm): nothing of it would be drawn");
  }
}

// The exposure that streaks the objects, into blur->exposure_ms: --exposure-ms, else the camera's, else half a
// video's frame interval, else none. Returns where it came from, for the run's first line.
std::string ChooseArExposure(const ArArgs& args, const stimulus::TrackedTake& take, const track::FrameSource& source,
                             stimulus::TakeBlur* blur) {
  const Camera& camera = take.camera();
  const double take_fps = take.FramesPerSecond();
  std::string exposure_note = "given";
  if (args.exposure_ms < 0 && camera.exposure_ms) {
    // A frame is exposed within its own interval: a longer exposure is a camera.json of a photo, not of this take.
    if (const std::string beyond = stimulus::ExposureBeyondFrame(*camera.exposure_ms, take_fps); !beyond.empty())
      throw InputError(args.track + ": the camera's exposure_ms",
                       "is " + Num(*camera.exposure_ms) + " ms, " + beyond +
                           ": not this take's camera? give --exposure-ms");
    blur->exposure_ms = *camera.exposure_ms;
    exposure_note = "the camera's exposure_ms, as tracked";
  } else if (args.exposure_ms < 0) {
    const bool rate_known = source.is_video() && source.fps() > 0;
    blur->exposure_ms = rate_known ? 1000 / source.fps() / 2 : 0;
    exposure_note = rate_known ? "the camera's exposure is unknown: half the frame interval of the video's " +
                                     Num(source.fps()) + " fps (give --exposure-ms)"
                               : "no motion blur: the camera's exposure is unknown and an image sequence states no "
                                 "frame rate (give --exposure-ms)";
  } else {
    if (const std::string beyond = stimulus::ExposureBeyondFrame(args.exposure_ms, take_fps); !beyond.empty())
      throw Error(ErrorKind::kUsage, "--exposure-ms " + Num(args.exposure_ms) + ": " + beyond +
                                         ": a camera exposes each frame within its own interval");
    blur->exposure_ms = args.exposure_ms;
  }
  return exposure_note;
}

// One run's drawing: every frame of the source into the video (opened at the first frame), the CSV's rows and the
// --frames PNGs, and what the summary counts.
struct ArDrawing {
  const ArArgs& args;
  const stimulus::TrackedTake& take;
  const std::vector<stimulus::PlacedObject>& objects;
  const stimulus::TakeBlur& blur;
  track::FrameSource& source;
  fs::path video_temp;
  std::unique_ptr<render::FrameCompositor> compositor = nullptr;
  media::VideoWriter video = {};
  std::string codec_used = {};
  std::string csv = stimulus::DrawnCsvHeader();
  int written = 0, drawn_frames = 0, unposed = 0;
  std::optional<Error> ended = std::nullopt;
  std::vector<double> draw_ms = {};  // per frame with objects: photo upload, pose, compose, read back

  // Draws every frame: into the video, the CSV and (when not empty) `frames_dir`.
  void DrawFrames(const fs::path& frames_dir) {
    const bool tty = isatty(2) && !args.quiet;
    cv::Mat frame;
    int index = 0;
    double time_s = 0;
    while (true) {
      if (written == kMaxArFrames) {
        ended = InputError(args.input, "more than " + std::to_string(kMaxArFrames) + " frames: ar draws at most " +
                                           std::to_string(kMaxArFrames) + " a run");
        break;
      }
      try {
        if (!source.Next(&frame, &index, &time_s)) break;
      } catch (const Error& e) {
        ended = e;
        break;
      }
      const std::string status = DrawFrame(frame, index, time_s, frames_dir);
      ++written;
      if (!args.quiet && (tty || (written % 10 == 0)))
        std::fprintf(stderr, "%sframe %d%s: %s%s", tty ? "\r" : "", index,
                     source.expected_frames() > 0 ? ("/" + std::to_string(source.expected_frames())).c_str() : "",
                     status.c_str(), tty ? "   " : "\n");
    }
    if (tty) std::fprintf(stderr, "\n");
    if (written == 0) throw ended ? *ended : InputError(args.input, "holds no frame; nothing written");
    video.Release();  // the frames written so far make a whole file, also when the input ended early
  }

  // One frame with its objects (when it has a pose) into the video, its rows into the CSV; returns its status.
  std::string DrawFrame(const cv::Mat& frame, int index, double time_s, const fs::path& frames_dir) {
    stimulus::CheckTakeFrame(take, index, frame, args.input, args.track);
    if (!video.IsOpened()) {
      const char* codec = OpenLosslessVideo(video, video_temp, source.fps() > 0 ? source.fps() : 30, frame.size());
      if (!codec) throw InputError(args.out, "cannot open a video writer (FFV1 or MJPEG .avi)");
      codec_used = codec;
    }
    const bool in_take = index < int(take.frames.size());
    const stimulus::TrackedFramePlan plan = stimulus::PlanTrackedFrame(take, index, objects, blur);
    cv::Mat out = frame;
    if (in_take && take.frames[size_t(index)].calib) {
      const calib::SceneCalib& c = *take.frames[size_t(index)].calib;
      if (!compositor) compositor = std::make_unique<render::FrameCompositor>(take.camera(), c.rvec, c.tvec, frame);
      const auto draw_start = std::chrono::steady_clock::now();
      // Composed once (each frame is drawn once, then read back), as live composes: the photo is uploaded straight
      // into the frame the objects are blended over, without the whole-frame copy from a base frame a second
      // composition would restore it from (the frames written are byte for byte the same: docs/ar.md).
      compositor->SetFrame(c.rvec, c.tvec, frame, true);
      compositor->Compose(plan.objects);
      out = compositor->Read();
      draw_ms.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - draw_start).count());
      ++drawn_frames;
    } else {
      ++unposed;
    }
    video.Write(out);
    if (!frames_dir.empty()) {
      char name[32];
      std::snprintf(name, sizeof name, "frame-%04d.png", index);
      WriteImage(frames_dir / name, out);
    }
    const std::string status = in_take ? track::Name(take.frames[size_t(index)].status) : "untracked";
    csv += stimulus::DrawnCsvRows(index, in_take ? take.frames[size_t(index)].time_s : time_s, status, plan.drawn);
    return status;
  }
};

// What was written and how long drawing took (not with --quiet).
void PrintArSummary(const ArArgs& args, const ArDrawing& d, const std::string& csv_path, double seconds) {
  std::printf("%d frames: %d with objects, %d without (lost or beyond track.csv); wrote %s (%s) and %s in %.1f s\n",
              d.written, d.drawn_frames, d.unposed, args.out.c_str(), d.codec_used.c_str(), csv_path.c_str(), seconds);
  if (!d.draw_ms.empty()) {
    std::vector<double> draw_ms = d.draw_ms;
    std::sort(draw_ms.begin(), draw_ms.end());
    std::printf("drawing: median %.1f ms a frame, slowest %.1f ms (photo upload, objects composed, frame read "
                "back; decoding and encoding not included)\n",
                draw_ms[draw_ms.size() / 2], draw_ms.back());
  }
  if (!d.ended && d.written < int(d.take.frames.size()))
    std::printf("note: %s ended after %d frames; track.csv has %zu\n", args.input.c_str(), d.written,
                d.take.frames.size());
}

}  // namespace

void AddArCommand(CLI::App& app) {
  auto args = std::make_shared<ArArgs>();
  CLI::App* cmd = app.add_subcommand(
      "ar",
      "Draw virtual objects into a tracked take: the offline AR view, every frame at its own pose, each object blurred\n"
      "for its depth (the frame's blur model: defocus x the lens floor) and for its image motion between frames over\n"
      "the exposure, in one pass in linear light, through the GL renderer (headless).\n"
      "INPUT is the take `blurcue track` read (a video, or an image sequence as a printf pattern); --track is the\n"
      "folder it wrote. Objects: --ball X,Y[,RADIUS] and --card X,Y[,WIDTH[,HEIGHT]] in board mm (repeatable; a ball\n"
      "resting on the board over X,Y; a card standing on the board facing the camera, its bottom edge's middle at\n"
      "X,Y), or --objects objects.json (docs/ar.md). Lost frames are written without objects and flagged.\n"
      "\n"
      "Writes OUT.avi (FFV1, lossless; MJPEG where videoio has no FFV1) and a CSV (--csv, default OUT.csv) with one row\n"
      "per object per frame: screen position, depth, r, floor, motion streak, the frame's tracking status.\n"
      "A damaged or truncated INPUT ends the take: the frames drawn before it are written, exit 3. Any other\n"
      "failure writes nothing. The outputs are built beside their places and moved in at the end: an earlier\n"
      "OUT.avi, CSV and --frames folder stay as they were until the new ones are whole. No output may be an input\n"
      "or lie in the --track folder, and --frames must be a folder of frame-NNNN.png only.\n"
      "Limits: at most 64 objects and 18000 frames (10 minutes at 30 fps) a run.\n"
      "Example: blurcue ar take/take.avi --track take/track --ball 87.5,125 --card 120,150,40,30 --out ar.avi");
  cmd->add_option("input", args->input, "the take: a video file, or a printf pattern of an image sequence")
      ->required();
  cmd->add_option("--track", args->track, "the folder blurcue track wrote for INPUT (track.csv, calib-NNNN.json)")
      ->required();
  cmd->add_option("--out", args->out, "the AR video to write (.avi)")->required();
  cmd->add_option("--csv", args->csv, "what was drawn, per frame and object (default: OUT with .csv)");
  AddObjectOptions(cmd, &args->objects);
  cmd->add_option("--blur", args->blur,
                  "blur source at each object's centre: fitted (the take's lens model), measured, measured_section,\n"
                  "estimated, none, or a radius in px")
      ->capture_default_str();
  cmd->add_option("--method", args->method, "the defocus's shape: disc (a thin lens's pillbox) or gaussian")
      ->capture_default_str()->check(OneOf({"disc", "gaussian"}));
  cmd->add_option("--exposure-ms", args->exposure_ms,
                  "the camera's exposure; objects are streaked by their image velocity over it (0: no motion blur).\n"
                  "Default: the camera's exposure_ms (camera.json, as tracked: EXIF ExposureTime from `blurcue\n"
                  "camera`, 0 for a synth-take); when it is unknown, half the frame interval of a video that states\n"
                  "its frame rate (a 180-degree shutter), and 0 for an image sequence, whose rate is not known")
      ->check(FiniteRange(0, 1000, "ms"));
  cmd->add_option("--frames", args->frames_dir, "also write each frame as frame-NNNN.png into this folder");
  cmd->add_flag("--quiet", args->quiet, "print only errors");
  cmd->callback([args] {
    const auto t0 = std::chrono::steady_clock::now();
    const std::string csv_path = CheckArOutputs(*args);
    stimulus::TakeBlur blur;
    blur.source = calib::ParseBlurSource(args->blur, &blur.fixed_r_px, "--blur");
    blur.method = args->method;

    std::vector<std::string> given;  // where each object was given, for messages: the option or the file's pointer
    const std::vector<stimulus::PlacedObject> objects = PlaceObjects(args->objects, &given);

    const stimulus::TrackedTake take = stimulus::LoadTrackedTake(args->track);
    const double take_fps = take.FramesPerSecond();
    track::FrameSource source(args->input, take_fps > 0 ? take_fps : 30);
    CheckArTake(*args, take, source, objects, given);
    const std::string exposure_note = ChooseArExposure(*args, take, source, &blur);
    if (!args->quiet)
      std::fprintf(stderr, "%zu objects, blur %s, exposure %s ms (%s), %zu frames in %s\n", objects.size(),
                   args->blur.c_str(), Num(blur.exposure_ms).c_str(), exposure_note.c_str(), take.frames.size(),
                   args->track.c_str());

    std::unique_ptr<render::GlContext> context = render::GlContext::CreateOffscreen();
    // The video is written under its own name (the extension tells the writer its container) and the CSV whole,
    // each inside a folder of its own beside its place (PartialFile), and both are moved into place once the video,
    // the frames and the CSV are whole; a run that fails or is killed leaves the earlier ones (the next run removes
    // the partial folders).
    PartialFile video_file(args->out), csv_file(csv_path);
    ArDrawing drawing{*args, take, objects, blur, source, video_file.path()};
    auto draw = [&](const fs::path& frames_dir) {
      drawing.DrawFrames(frames_dir);
      if (!frames_dir.empty())
        WriteFileAtomically(frames_dir / kArFramesMarker,
                            "frame-NNNN.png: frames blurcue ar drew (its video's frames with the objects); a later "
                            "`ar --frames` may replace this folder whole, as it holds this file.\n");
    };
    // The video and the CSV, both whole on disk, are moved into place by two renames one after the other, and with
    // --frames the frames folder is swapped in by a third right after (WriteFolderAtomically's before_swap): the
    // three are no single step, but all that lies between them is three renames.
    auto move_in = [&] {
      WriteFileAtomically(csv_file.path(), drawing.csv);
      video_file.Finish();
      csv_file.Finish();
    };
    if (args->frames_dir.empty()) {
      draw({});
      move_in();
    } else {
      WriteFolderAtomically(args->frames_dir, draw, IsArFrameName, move_in);
    }
    if (!args->quiet)
      PrintArSummary(*args, drawing, csv_path,
                     std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    if (drawing.ended)
      throw Error(drawing.ended->kind(), std::string(drawing.ended->what()) + "; the " +
                                             std::to_string(drawing.written) + " frames before it are in " + args->out);
  });
}

}  // namespace blurcue::cli
