#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <cctype>
#include <sstream>
#include <string>
#include <thread>

#include <unistd.h>

#include <opencv2/calib3d.hpp>
#include "core/output_guard.h"
#include "core/own_output.h"
#include "core/media.h"

#include "calib/scene_blur.h"
#include "cli/commands.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/image.h"
#include "core/typed.h"
#include "render/blur.h"
#include "render/frame_compositor.h"
#include "render/gl_context.h"
#include "render/scene_render.h"
#include "scene/frame.h"
#include "scene/objects.h"
#include "scene/stimuli.h"

namespace blurcue::cli {

namespace {

struct AnimateArgs {
  std::string calib, background, left = "estimated", right = "none", texture = "soccer", method = "gaussian";
  std::string video, frames_dir, log;
  double speed_cm_s = 3, fps = 60, gain = 1, exposure_ms = 0;
  int from_edge = 1, to_edge = 11, left_section = 3, right_section = 5;
  bool window = false, fullscreen = false;
};

// --log's first line: a file at --log is replaced only when it begins with it (a log animate wrote).
constexpr const char* kLogHeader =
    "frame,t_s,y_mm,r_left_px,r_right_px,floor_sigma_left_px,floor_sigma_right_px,motion_left_x_px,"
    "motion_left_y_px,motion_right_x_px,motion_right_y_px,render_ms,flip_s\n";
// --frames is replaced as a whole, and only when it holds this file, which every run writes into it (a folder of
// frame-NNNNN.png alone may be one's own images).
constexpr const char* kFramesMarker = "animate-frames.txt";

// A name --frames may hold: frame-NNNNN.png, and the marker.
bool IsAnimateFrameName(const std::string& name) {
  if (name == kFramesMarker) return true;
  return name.size() == 15 && name.rfind("frame-", 0) == 0 && name.compare(11, 4, ".png") == 0 &&
         name.find_first_not_of("0123456789", 6) == 11;
}

// The options against the calibration (edges and sections it has) and the outputs, before any frame is drawn:
// OpenCV's writer picks its container by the extension (and prints its own multi-line warnings for one it does not
// know), and a device or FIFO is not a file to replace (opening a FIFO to write waits for a reader forever).
void CheckAnimateArgs(const AnimateArgs& args, const calib::SceneCalib& scene) {
  const int edges = scene.board.EdgeCount(), sections = scene.board.SectionCount();
  auto check = [](const char* name, int v, int lo, int hi) {
    if (v < lo || v > hi)
      throw Error(ErrorKind::kUsage, std::string(name) + " must be " + std::to_string(lo) + ".." +
                                         std::to_string(hi) + ", got " + std::to_string(v));
  };
  check("--from-edge", args.from_edge, 1, edges);
  check("--to-edge", args.to_edge, 1, edges);
  check("--left-section", args.left_section, 1, sections);
  check("--right-section", args.right_section, 1, sections);
  if (args.video.empty() && args.frames_dir.empty() && !args.window)
    throw Error(ErrorKind::kUsage, "say where the frames go: --video, --frames or --window");
  // Outputs checked before any frame is drawn: OpenCV's writer picks its container by the extension (and prints
  // its own multi-line warnings for one it does not know), and a device or FIFO is not a file to replace (opening
  // a FIFO to write waits for a reader forever).
  if (!args.video.empty()) {
    std::string extension = std::filesystem::path(args.video).extension().string();
    for (char& c : extension) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (extension != ".avi")
      throw Error(ErrorKind::kUsage, "--video " + Echo(args.video, false) + ": must end in .avi (it writes an MJPG AVI)");
    RequireReplaceableFile(args.video);
  }
  if (!args.log.empty()) RequireReplaceableFile(args.log);
  {
    OutputGuard guard;
    guard.Input("--calib", args.calib).Input("--background", args.background);
    if (!args.video.empty()) guard.OutputFile("--video", args.video);
    if (!args.log.empty()) guard.OutputFile("--log", args.log);
    if (!args.frames_dir.empty()) guard.OutputFolder("--frames", args.frames_dir);
    guard.Check();
  }
  // What the guard lets pass is still someone's unless animate wrote it: a protocol at --log, one's own take at
  // --video, one's own images in --frames.
  if (!args.video.empty()) RequireOwnFile("--video", args.video, "a video (an AVI)", AviFile());
  if (!args.log.empty()) RequireOwnFile("--log", args.log, "a log animate wrote", BeginsWith(kLogHeader));
  if (!args.frames_dir.empty()) {
    try {
      RequireReplaceableFolder(args.frames_dir, IsAnimateFrameName);
    } catch (const Error& e) {
      throw e.Wrapped(e.kind(), "--frames ");
    }
    RequireMarkedFolder("--frames", args.frames_dir, kFramesMarker, "frames animate drew",
                        "one's own frame-NNNNN.png images?");
  }
  for (const std::string& target : {args.video, args.log, args.frames_dir})
    if (!target.empty()) RemoveLeftoversBeside("animate", target);
}

// The two balls of each frame: rolling from --from-edge to --to-edge at --speed-cm-s, each blurred for its depth by
// its own blur source (x --gain) and, while rolling, streaked over the exposure: where its centre's image goes from
// half an exposure before to half after.
class RollingBalls {
 public:
  RollingBalls(const AnimateArgs& args, const calib::SceneCalib& scene, const scene::SurfaceTexture& texture)
      : args_(args), scene_(scene), texture_(texture) {
    source_[0] = calib::ParseBlurSource(args.left, &fixed_[0], "--left");
    source_[1] = calib::ParseBlurSource(args.right, &fixed_[1], "--right");
    y0_ = (args.from_edge - 1) * scene.board.square_mm;
    y1_ = (args.to_edge - 1) * scene.board.square_mm;
    half_mm_ = 0.5 * speed_mm_s() * args.exposure_ms / 1000 * (y1_ >= y0_ ? 1 : -1);
  }
  double speed_mm_s() const { return args_.speed_cm_s * 10; }
  double distance_mm() const { return std::abs(y1_ - y0_); }
  // Where the balls are at time t (s), along the board.
  double YAt(double t) const { return y0_ + (y1_ > y0_ ? 1 : -1) * std::min(distance_mm(), speed_mm_s() * t); }
  scene::BlurredObject Ball(int b, double y) const {
    scene::BlurredObject o;
    o.object = scene::BallOnBoard(scene_.board, b == 0 ? args_.left_section : args_.right_section, y, kRadiusMm, y0_);
    o.object.texture = texture_;
    return o;
  }
  // The first ball drawn whose fitted blur lies where calibrate found the model not determined within 5 %
  // (calib::UndeterminedNote; "" where none): said once after the frames.
  const std::string& note() const { return note_; }
  // Frame `i`'s two balls at time t; throws Error(kUsage) naming the option whose radius is beyond the blur's range.
  std::vector<scene::BlurredObject> At(int i, double t) const {
    const double y = YAt(t);
    const bool rolling = speed_mm_s() * t < distance_mm();
    std::vector<scene::BlurredObject> balls = {Ball(0, y), Ball(1, y)};
    for (int b = 0; b < 2; ++b) {
      const cv::Vec3d centre = scene_.ToCamera(balls[b].object.center_board_mm);
      const double r = args_.gain * calib::BlurAtPx(scene_, source_[b], centre, fixed_[b]);
      if (!(r >= 0 && r <= render::kMaxBlurRadiusPx))
        throw Error(ErrorKind::kUsage, std::string(b == 0 ? "--left " + args_.left : "--right " + args_.right) +
                                           " x --gain " + BoundText(args_.gain) + " gives " + BoundText(r) +
                                           " px at frame " + std::to_string(i) + calib::BlurFrom(scene_, source_[b]) +
                                           "; the blur radius must be in [0, " +
                                           BoundText(render::kMaxBlurRadiusPx) + "] px");
      balls[b].r_px = r;
      if (note_.empty()) note_ = calib::UndeterminedNote(scene_, source_[b], centre[2]);
      balls[b].method = args_.method;
      balls[b].floor_sigma_px = calib::FloorSigmaPx(scene_, source_[b], centre);
      balls[b].shape = calib::ShapeAt(scene_, source_[b], centre);
      balls[b].motion_px = rolling ? Streak(b, y) : cv::Vec2d(0, 0);
    }
    return balls;
  }

 private:
  static constexpr double kRadiusMm = 10;
  cv::Vec2d Streak(int b, double y) const {
    if (!(half_mm_ != 0)) return {0, 0};
    std::vector<cv::Point3d> ends = {cv::Point3d(Ball(b, y - half_mm_).object.center_board_mm),
                                     cv::Point3d(Ball(b, y + half_mm_).object.center_board_mm)};
    std::vector<cv::Point2d> image;
    cv::projectPoints(ends, scene_.rvec, scene_.tvec, cv::Matx33d(scene_.camera.Intrinsics().data()),
                      scene_.camera.dist_coeffs, image);
    return {image[1].x - image[0].x, image[1].y - image[0].y};
  }
  const AnimateArgs& args_;
  const calib::SceneCalib& scene_;
  const scene::SurfaceTexture& texture_;
  mutable std::string note_;  // note()
  calib::BlurSource source_[2];
  double fixed_[2] = {0, 0};
  double y0_ = 0, y1_ = 0, half_mm_ = 0;
};

struct Drawn {
  double worst_ms = 0;
  std::string log;
};

// Draws the frames to the window, the video and (when not empty) `frames_dir`; returns the log and the slowest.
Drawn DrawFrames(const AnimateArgs& args, const RollingBalls& rolling, int frames, render::GlContext& context,
                 render::FrameCompositor& compositor, media::VideoWriter& video,
                 const std::filesystem::path& frames_dir) {
  std::ostringstream log;
  log << kLogHeader;
  using Clock = std::chrono::steady_clock;
  {  // a warm-up frame uploads and mipmaps the texture, so frame 0 is not slower than the rest
    compositor.Compose({rolling.Ball(0, rolling.YAt(0))});
    compositor.Finish();
  }
  const bool tty = isatty(2);
  const auto start = Clock::now();
  double worst_ms = 0;
  for (int i = 0; i < frames && !(context.ShouldClose()); ++i) {
    const double t = i / args.fps;
    const double y = rolling.YAt(t);
    const std::vector<scene::BlurredObject> balls = rolling.At(i, t);
    const double r[2] = {balls[0].r_px, balls[1].r_px};
    const auto t0 = Clock::now();
    compositor.Compose(balls);
    compositor.Finish();
    const double render_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    worst_ms = std::max(worst_ms, render_ms);
    double flip_s = std::chrono::duration<double>(Clock::now() - start).count();
    if (args.window) {
      compositor.Present(context.width_px(), context.height_px());
      context.SwapBuffers();
      flip_s = std::chrono::duration<double>(Clock::now() - start).count();
    }
    if (video.IsOpened() || !frames_dir.empty()) {
      const cv::Mat frame = compositor.Read();
      if (video.IsOpened()) video.Write(frame);
      if (!frames_dir.empty()) {
        char name[32];
        std::snprintf(name, sizeof name, "frame-%05d.png", i);
        WriteImage(frames_dir / name, frame);
      }
    }
    log << i << "," << t << "," << y << "," << r[0] << "," << r[1] << "," << balls[0].floor_sigma_px << ","
        << balls[1].floor_sigma_px << "," << balls[0].motion_px[0] << "," << balls[0].motion_px[1] << ","
        << balls[1].motion_px[0] << "," << balls[1].motion_px[1] << "," << render_ms << "," << flip_s << "\n";
    if (tty || (i + 1) % std::max(1, frames / 4) == 0 || i + 1 == frames)
      std::fprintf(stderr, "%sframe %d/%d  y %.1f mm  r %.2f | %.2f px  %.1f ms%s", tty ? "\r" : "", i + 1, frames,
                   y, r[0], r[1], render_ms, tty ? "" : "\n");
  }
  if (tty) std::fprintf(stderr, "\n");
  return {worst_ms, log.str()};
}

// Two balls rolling side by side, each re-blurred every frame for its depth by its own blur source.
void Animate(const AnimateArgs& args) {
  const calib::SceneCalib scene = calib::LoadSceneCalib(args.calib);
  const cv::Mat photo = ReadImage(args.background, 1);
  scene.RequireSameSize(photo, args.background);
  CheckAnimateArgs(args, scene);
  const scene::SurfaceTexture texture(ReadImage(scene::ResolveStimulus(args.texture)));
  const RollingBalls rolling(args, scene, texture);

  std::unique_ptr<render::GlContext> context;
  if (args.window) {
    render::WindowOptions w;
    w.width_px = std::min(photo.cols, 1280);
    w.height_px = w.width_px * photo.rows / photo.cols;
    w.fullscreen = args.fullscreen;
    context = render::GlContext::CreateWindow(w);
  } else {
    context = render::GlContext::CreateOffscreen();
  }
  render::FrameCompositor compositor(scene.camera, scene.rvec, scene.tvec, photo);

  const double frame_count = std::ceil(rolling.distance_mm() / rolling.speed_mm_s() * args.fps) + 1;
  constexpr double kMaxFrames = 36000;  // ten minutes at 60 fps
  if (frame_count > kMaxFrames)
    throw Error(ErrorKind::kUsage, "--speed-cm-s " + BoundText(args.speed_cm_s) + " and --fps " +
                                       BoundText(args.fps) + " make " + BoundText(frame_count) +
                                       " frames; at most " + BoundText(kMaxFrames) + " (go faster or lower --fps)");
  const int frames = std::max(1, int(frame_count));
  // The video is written as DIR/.NAME.partial-PID/NAME and renamed to --video once whole: a run killed or failing
  // midway leaves the earlier video (or none), never half of one under its name; a later run removes what a killed
  // one left.
  media::VideoWriter video;
  std::optional<PartialFile> video_file;
  if (!args.video.empty()) {
    RemoveStaleLeftovers(args.video);
    video_file.emplace(args.video);
    if (!video.Open(video_file->path().string(), media::Fourcc('M', 'J', 'P', 'G'), args.fps, photo.size()))
      throw InputError(args.video, "cannot open a video writer (MJPG .avi)");
  }
  // The log is written whole at the end (WriteFileAtomically): a run cut short leaves no half log. The frames are
  // drawn into a folder beside --frames and swapped in whole, with the marker that lets a later run replace it.
  Drawn drawn;
  auto draw = [&](const std::filesystem::path& frames_dir) {
    drawn = DrawFrames(args, rolling, frames, *context, compositor, video, frames_dir);
    if (!frames_dir.empty())
      WriteFileAtomically(frames_dir / kFramesMarker, "frame-NNNNN.png: frames blurcue animate drew; a later "
                                                      "`animate --frames` may replace this folder whole, as it holds "
                                                      "this file.\n");
  };
  if (args.frames_dir.empty())
    draw({});
  else
    WriteFolderAtomically(args.frames_dir, draw, IsAnimateFrameName);
  const double worst_ms = drawn.worst_ms;
  if (video_file) {
    video.Release();
    video_file->Finish();
  }
  if (!args.log.empty()) WriteFileAtomically(args.log, drawn.log);
  std::printf("%d frames (%.1f s of motion at %.1f cm/s, %.0f fps); slowest frame %.1f ms%s%s%s\n", frames,
              (frames - 1) / args.fps, args.speed_cm_s, args.fps, worst_ms,
              args.video.empty() ? "" : ("; video " + args.video).c_str(),
              args.frames_dir.empty() ? "" : ("; frames in " + args.frames_dir).c_str(),
              args.log.empty() ? "" : ("; log " + args.log).c_str());
  if (!rolling.note().empty()) std::printf("note: %s\n", rolling.note().c_str());
}

}  // namespace

void AddAnimateCommand(CLI::App& app) {
  using Args = AnimateArgs;
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "animate",
      "Two balls rolling side by side across the board (user tests 2 and 3), each re-blurred every frame for its\n"
      "current depth by its own blur source. Renders offscreen to a video (MJPG .avi) and/or PNG frames for\n"
      "inspection, or to a window at the display's refresh (--window; needs a display, e.g. Xvfb). Every frame's\n"
      "timestamps, position and radii go to --log (CSV).\n"
      "Example (pattern 1 of Table 5.1): blurcue animate --calib calib.json --background scene.png\n"
      "         --left measured --right none --speed-cm-s 3 --video pattern1.avi --log pattern1.csv");
  cmd->add_option("--calib", args->calib, "calib.json")->required()->check(CLI::ExistingFile);
  cmd->add_option("--background", args->background, "the scene photo")->required()->check(CLI::ExistingFile);
  cmd->add_option("--left", args->left, "blur source of the left ball: none|measured|measured_section|estimated|fitted|R")
      ->capture_default_str();
  cmd->add_option("--right", args->right, "blur source of the right ball")->capture_default_str();
  cmd->add_option("--texture", args->texture, "soccer, wood or an equirectangular image")->capture_default_str();
  cmd->add_option("--method", args->method, "gaussian or disc")->capture_default_str()
      ->check(OneOf({"gaussian", "disc"}));
  cmd->add_option("--gain", args->gain, "multiplies both radii")->capture_default_str()->check(FiniteRange(0, 100, ""));
  cmd->add_option("--speed-cm-s", args->speed_cm_s, "rolling speed (the thesis: 3 and 1.8)")->capture_default_str()
      ->check(FiniteRange(0.1, 1000, "cm/s"));
  cmd->add_option("--fps", args->fps, "frames per second of the video (a window runs at its refresh)")
      ->capture_default_str()->check(FiniteRange(1, 1000, "frames per second"));
  cmd->add_option("--exposure-ms", args->exposure_ms,
                  "the camera's exposure: each rolling ball gets the motion blur of its image velocity over it, drawn\n"
                  "with its defocus in one kernel (0: none)")
      ->capture_default_str()->check(FiniteRange(0, 1000, "ms"));
  cmd->add_option("--from-edge", args->from_edge, "start edge")->capture_default_str()->transform(IntRange(1, 1000));
  cmd->add_option("--to-edge", args->to_edge, "end edge")->capture_default_str()->transform(IntRange(1, 1000));
  cmd->add_option("--left-section", args->left_section, "section the left ball rolls along")->capture_default_str()
      ->transform(IntRange(1, 1000));
  cmd->add_option("--right-section", args->right_section, "section the right ball rolls along")
      ->capture_default_str()->transform(IntRange(1, 1000));
  cmd->add_option("--video", args->video, "write an MJPG .avi (an existing file is replaced only when it is an AVI; it is\n"
                  "written beside it as .NAME.partial-PID and renamed when whole, so a run killed midway leaves the\n"
                  "earlier video)");
  cmd->add_option("--frames", args->frames_dir,
                  "write frame-NNNNN.png into this folder, swapped in whole; an existing folder is replaced only when\n"
                  "animate drew it (it holds animate-frames.txt)");
  cmd->add_option("--log", args->log,
                  "per-frame CSV: index, t_s, y_mm, r_left_px, r_right_px, each ball's lens floor (std) and motion\n"
                  "streak (x, y) in photo px, render_ms, flip_s; an existing file is replaced only when it is such a\n"
                  "log");
  CLI::Option* window = cmd->add_flag("--window", args->window, "show in a GLFW window (vsync)");
  // Without a window nothing would read it (it was ignored).
  cmd->add_flag("--fullscreen", args->fullscreen, "with --window: fullscreen on the first monitor")->needs(window);
  cmd->callback([args] { Animate(*args); });
}

}  // namespace blurcue::cli
