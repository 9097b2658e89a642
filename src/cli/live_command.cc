// blurcue live: the thesis's prototype in real time - a camera, or a video played as one, tracked frame by frame,
// virtual objects drawn with the lens model's blur as `ar` draws them, shown in a window (or headless), and every
// frame's latency logged (src/live/ holds the GL-free parts: the paced reader, the mailbox, the plan, the log).
#include <atomic>
#include <chrono>
#include <csignal>
#include <ctime>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <unistd.h>

#include "calib/scene_blur.h"
#include "cli/commands.h"
#include "cli/placed_objects.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/image.h"
#include "core/interrupt.h"
#include "core/json_io.h"
#include "core/output_guard.h"
#include "core/typed.h"
#include "live/live_log.h"
#include "live/live_plan.h"
#include "live/mailbox.h"
#include "live/paced_source.h"
#include "render/frame_compositor.h"
#include "render/gl_context.h"
#include "scene/stimuli.h"
#include "track/frames.h"
#include "track/tracker.h"

namespace blurcue::cli {
namespace {

// A run logs at most an hour at 30 fps: the log is held in memory (about 250 bytes a frame) and written whole.
constexpr int kMaxLiveFrames = 108000;


// The names a --log folder holds: what live writes, and nothing else is replaced.
bool IsLiveLogFile(const std::string& name) {
  if (name == "live.csv" || name == "drawn.csv" || name == "summary.json") return true;
  return name.size() == 14 && name.rfind("frame-", 0) == 0 && name.compare(10, 4, ".png") == 0 &&
         name.find_first_not_of("0123456789", 6) == 10;
}

struct LiveArgs {
  std::string input, camera, track, calib, log, blur = "fitted", method = "disc";
  ObjectOptions objects;
  std::vector<int> save_frames;
  double fps = 0, exposure_ms = -1;
  int frames = 0, measure_sections = 0;
  bool window = false, quiet = false, preload = false;
};

// What a run needs before its first frame: the lens, the objects, the tracker, the reader.
struct LiveSetup {
  Camera camera;
  std::unique_ptr<live::LivePlanner> planner;
  std::unique_ptr<track::Tracker> tracker;
  std::unique_ptr<live::PacedSource> source;
  std::unique_ptr<live::LiveLens> live_lens;  // --measure-sections: the lens model fitted as the frames come
  double exposure_ms = 0;
  double preload_s = 0;  // --preload: the seconds decoding the whole input took, before the start
  std::string exposure_note, lens_note;
};

// The run as it goes: the rows, the drawn CSV, the frames asked for as PNGs, and how it ended.
struct LiveRecord {
  std::vector<live::LiveRow> rows;
  std::string live_csv = live::LiveCsvHeader(), drawn_csv = stimulus::DrawnCsvHeader();
  std::map<int, cv::Mat> saved;  // by the number of the frame shown
  std::set<int> saved_for;       // the --save-frame numbers done
  std::string ended;
  std::optional<Error> error;
  int dropped = 0;
  double cpu_s = 0;  // the process's CPU time (every thread) from the start to the end of the frames
};

// CPU time of the whole process, every thread, s.
double ProcessCpuS() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

void WriteLiveLog(const LiveArgs& a, const LiveRecord& record, const live::LiveSummary& summary) {
  WriteFolderAtomically(
      a.log,
      [&](const std::filesystem::path& partial) {
        WriteFileAtomically(partial / "live.csv", record.live_csv);
        WriteFileAtomically(partial / "drawn.csv", record.drawn_csv);
        Json j = live::SummaryJson(summary);
        j["input"] = a.input;
        WriteJsonFile(partial / "summary.json", j);
        for (const auto& [index, image] : record.saved) {
          char name[32];
          std::snprintf(name, sizeof name, "frame-%04d.png", index);
          WriteImage(partial / name, image);
        }
      },
      IsLiveLogFile);
}

void GuardLiveOutputs(const LiveArgs& a) {
  OutputGuard guard;
  if (live::CameraDevice(a.input).empty())
    for (const std::filesystem::path& file : track::TakeInputFiles(a.input)) guard.Input("INPUT", file);
  guard.Input("--camera", a.camera);
  if (!a.track.empty()) guard.Input("--track", a.track);
  if (!a.calib.empty()) guard.Input("--calib", a.calib);
  GuardObjectInputs(guard, a.objects);
  guard.OutputFolder("--log", a.log);
  guard.Check();
  // A folder live may not replace for what it holds - an input (the guard above), one's own files, another tool's
  // frames - is one refusal, a usage error (exit 2): nothing in it is read or wrong, and the way out is another --log
  // (it was exit 3 for one's own files and 2 for an input's folder). A path of the wrong kind - a file, a FIFO, a
  // folder live cannot write in - stays the guard's exit 3, as for every command's output (docs/ar.md says the same).
  const auto holds = [](const Error& e) {
    return std::string(e.what()).find(": holds ") != std::string::npos ? ErrorKind::kUsage : e.kind();
  };
  try {
    RequireReplaceableFolder(a.log, IsLiveLogFile);
  } catch (const Error& e) {
    throw e.Wrapped(holds(e), "--log ");
  }
  try {
    // A folder of frame-NNNN.png alone (ar --frames, a take's frames) passes the check above and was replaced.
    RequireMarkedFolder("--log", a.log, "live.csv", "a log live wrote", "frame-NNNN.png images of another run or tool?");
  } catch (const Error& e) {
    throw Error(holds(e), e.lines());
  }
  RemoveLeftoversBeside("live", a.log);
}

LiveSetup SetUpLive(const LiveArgs& a) {
  if (a.track.empty() == a.calib.empty())
    throw Error(ErrorKind::kUsage, "give the lens model with one of --track DIR (a take blurcue track wrote) or "
                                   "--calib calib.json (blurcue calibrate)");
  stimulus::TakeBlur blur;
  blur.source = calib::ParseBlurSource(a.blur, &blur.fixed_r_px, "--blur");
  live::RequireLiveSource(blur.source, "--blur");
  // The sections measured live feed the lens model only: a source that draws without it would measure for nothing
  // (estimated is eq. 3.7 from the given calibration's reference edge and the nominal aperture: no model either).
  if (a.measure_sections > 0 && blur.source != BlurSource::kFitted)
    throw Error(ErrorKind::kUsage,
                "--measure-sections " + std::to_string(a.measure_sections) + ": feeds the lens model, which --blur " +
                    a.blur + " does not draw with; give --blur fitted, or leave --measure-sections out");
  GuardLiveOutputs(a);
  LiveSetup s;
  blur.method = a.method;
  std::vector<std::string> given;
  std::vector<stimulus::PlacedObject> objects = PlaceObjects(a.objects, &given);
  s.camera = LoadCamera(a.camera);
  calib::SceneCalib lens = a.track.empty() ? live::LensFromCalib(a.calib, s.camera)
                                           : live::LensFromTrack(a.track, s.camera);
  s.lens_note = a.track.empty() ? a.calib : a.track + " (its lens model)";
  if (a.preload && !live::CameraDevice(a.input).empty())
    throw Error(ErrorKind::kUsage, "--preload: " + a.input + " is a camera, which hands over its frames decoded "
                                   "already; --preload is for a video or an image sequence");
  try {
    s.source = std::make_unique<live::PacedSource>(a.input, a.fps, a.frames > 0 ? a.frames : kMaxLiveFrames);
  } catch (const Error& e) {
    // No camera there: the run ends before its first frame, and its log (no frame) says so, whole.
    if (live::CameraDevice(a.input).empty() || e.kind() != ErrorKind::kInput) throw;
    WriteLiveLog(a, LiveRecord(), live::Summarize({}, 0, e.what()));
    throw;
  }
  // Decoded whole before the clock starts: frames then come from memory, as a camera hands over the frames it decoded.
  if (a.preload) {
    const cv::Size frame_size(s.camera.image_width_px, s.camera.image_height_px);
    s.source->CheckPreloadFits(frame_size, live::kMaxPreloadMb);  // refused before a frame is decoded
    if (!a.quiet) std::fprintf(stderr, "live: --preload: decoding %s before the start ...\n", a.input.c_str());
    s.preload_s = s.source->Preload(frame_size, live::kMaxPreloadMb, &InterruptSignal());
  }
  const double rate = s.source->fps();
  if (a.exposure_ms >= 0) {
    if (const std::string beyond = stimulus::ExposureBeyondFrame(a.exposure_ms, rate); !beyond.empty())
      throw Error(ErrorKind::kUsage, "--exposure-ms " + Num(a.exposure_ms) + ": " + beyond +
                                         ": a camera exposes each frame within its own interval");
    blur.exposure_ms = a.exposure_ms;
    s.exposure_note = "given";
  } else if (s.camera.exposure_ms) {
    if (const std::string beyond = stimulus::ExposureBeyondFrame(*s.camera.exposure_ms, rate); !beyond.empty())
      throw InputError(a.camera + ": exposure_ms", "is " + Num(*s.camera.exposure_ms) + " ms, " + beyond +
                                                       ": give --exposure-ms");
    blur.exposure_ms = *s.camera.exposure_ms;
    s.exposure_note = "the camera's exposure_ms";
  } else {
    blur.exposure_ms = rate > 0 ? 1000 / rate / 2 : 0;
    s.exposure_note = rate > 0 ? "the camera's exposure is unknown: half the frame interval at " + Num(rate) +
                                     " fps (give --exposure-ms)"
                               : "no motion blur: the camera's exposure is unknown (give --exposure-ms)";
  }
  s.exposure_ms = blur.exposure_ms;
  track::TrackOptions options;
  // A fixed lens model needs the pose alone; --measure-sections N measures N sections a frame, in turn, and fits the
  // model to every section's latest reading.
  options.measure_blur = a.measure_sections > 0;
  options.sections_per_frame = a.measure_sections;
  if (a.measure_sections > 0) {
    s.live_lens = std::make_unique<live::LiveLens>(s.camera);
    s.lens_note += ", fitted again to the sections measured live (" + std::to_string(a.measure_sections) +
                   " a frame) once they lie on 3 edges";
  }
  s.tracker = std::make_unique<track::Tracker>(s.camera, lens.board, options);
  s.planner = std::make_unique<live::LivePlanner>(std::move(lens), std::move(objects), blur);
  return s;
}

double MsBetween(live::Clock::time_point a, live::Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

// Why the window asks to end ("" when it does not): Escape, or the window closed.
std::string WindowEnd(render::GlContext& context) {
  for (const render::InputEvent& e : context.TakeEvents())
    if (e.key == "Escape") return "Escape pressed";
  return context.ShouldClose() ? "the window was closed" : "";
}

// One frame: pose, plan, draw, show; its row and drawn rows recorded.
void ShowFrame(LiveSetup& s, const LiveArgs& a, live::LiveFrame& frame, live::Clock::time_point start,
               int dropped, render::GlContext& context, render::FrameCompositor& compositor, LiveRecord& record,
               std::optional<calib::BoardPose>& last_pose) {
  const live::Clock::time_point t0 = live::Clock::now();
  const track::FrameResult result = s.tracker->Process(frame.image, frame.index, frame.time_s);
  if (s.live_lens) {
    // The model a fit finished since the frame before, then this frame's readings (a fit of them started meanwhile
    // on a thread of its own: the next frames draw with it once it is done).
    optics::FittedModel model;
    if (s.live_lens->TakeModel(&model)) s.planner->SetModel(model);
    if (result.calib) s.live_lens->Update(*result.calib);
  }
  const live::Clock::time_point t1 = live::Clock::now();
  const stimulus::TrackedFramePlan plan = s.planner->Plan(frame.index, frame.time_s, result.status, result.pose);
  if (result.pose) last_pose = result.pose;
  const calib::SceneCalib& lens = s.planner->lens();
  // A lost frame is shown as the camera saw it, without objects (at the last pose, which draws nothing).
  // Composed once (a frame is shown once): the photo is uploaded straight into the frame the objects are blended over.
  compositor.SetFrame(last_pose ? last_pose->rvec : lens.rvec, last_pose ? last_pose->tvec : lens.tvec, frame.image,
                      true);
  compositor.Compose(plan.objects);
  if (a.window) compositor.Present(context.width_px(), context.height_px());
  compositor.Finish();
  const live::Clock::time_point t2 = live::Clock::now();
  if (a.window) {
    context.SwapBuffers();  // blocks to the refresh with vsync
    compositor.Finish();
  }
  const live::Clock::time_point shown = live::Clock::now();
  live::LiveRow row;
  row.frame = frame.index;
  row.arrival_s = std::chrono::duration<double>(frame.arrival - start).count();
  row.status = result.status;
  if (result.pose) row.rvec = result.pose->rvec, row.tvec = result.pose->tvec;
  row.track_ms = result.pose_ms;
  row.sections = result.calib ? result.sections_measured : 0;
  // The sections (the model's fit runs on its own thread); 0 for a frame that measured none (the tracker's work
  // besides the pose left 0.002 ms there, a time for nothing done).
  row.measure_ms = row.sections > 0 ? MsBetween(t0, t1) - result.pose_ms : 0;
  row.lens_sections = s.live_lens ? s.live_lens->sections() : 0;
  row.render_ms = MsBetween(t1, t2);
  row.display_s = std::chrono::duration<double>(shown - start).count();
  row.latency_ms = MsBetween(frame.arrival, shown);
  row.dropped = dropped;
  live::AppendLiveCsvRow(row, &record.live_csv);
  record.drawn_csv += stimulus::DrawnCsvRows(frame.index, frame.time_s, track::Name(result.status), plan.drawn);
  record.rows.push_back(row);
  // Frame N, or the first shown after it when N was dropped: saved under the number of the frame it is.
  for (int wanted : a.save_frames)
    if (frame.index >= wanted && record.saved_for.insert(wanted).second) record.saved[frame.index] = compositor.Read();
}

// Frames until the input ends, the window asks to end, a signal comes, or a frame fails (kept in record.error).
void RunLiveLoop(LiveSetup& s, const LiveArgs& a, render::GlContext& context, render::FrameCompositor& compositor,
                 LiveRecord& record) {
  live::FrameMailbox mailbox;
  const double cpu0 = ProcessCpuS();
  const live::Clock::time_point start = live::Clock::now();
  s.source->Start(&mailbox, start);
  live::LiveFrame frame;
  std::optional<calib::BoardPose> last_pose;
  int dropped_seen = 0;
  const bool tty = isatty(2) && !a.quiet;
  while (true) {
    if (Interrupted()) {
      record.ended = std::string("interrupted (") + InterruptName(InterruptSignal()) + ")";
      break;
    }
    if (a.window) {
      record.ended = WindowEnd(context);
      if (!record.ended.empty()) break;
    }
    const live::FrameMailbox::Got got = mailbox.Take(frame, std::chrono::milliseconds(a.window ? 5 : 50));
    if (got == live::FrameMailbox::Got::kTimeout) continue;
    if (got == live::FrameMailbox::Got::kClosed) {
      record.ended = mailbox.why_closed();
      record.error = s.source->error();
      break;
    }
    // Frames dropped while the frame before was drawn: replaced in the slot before this one was taken.
    const int dropped = mailbox.dropped();
    try {
      ShowFrame(s, a, frame, start, dropped - dropped_seen, context, compositor, record, last_pose);
    } catch (const Error& e) {
      // Named by the input and the frame once (the tracker's message names the frame already), and a frame of
      // another size by the camera.json it contradicts.
      const std::string own = "frame " + std::to_string(frame.index) + ": ";
      std::string what = e.what();
      if (what.rfind(own, 0) == 0) what.erase(0, own.size());
      if (const size_t at = what.find("the camera says"); at != std::string::npos)
        what.replace(at, 15, "the camera (" + a.camera + ") says");
      record.ended = a.input + ", " + own + what;
      record.error = Error(e.kind(), record.ended);
      break;
    }
    dropped_seen = dropped;
    // Said once, on the screen itself: the first frame is shown (a script waits for it before it presses a key).
    if (a.window && record.rows.size() == 1) context.SetTitle("blurcue live: " + a.input + " - showing");
    if (tty) std::fprintf(stderr, "\rframe %d: %s, %d dropped   ", frame.index, track::Name(record.rows.back().status),
                          dropped);
  }
  if (tty) std::fprintf(stderr, "\n");
  s.source->Stop();
  record.dropped = mailbox.dropped();
  record.cpu_s = ProcessCpuS() - cpu0;
}

void RunLive(const LiveArgs& a) {
  // From before the preload to the log written: a signal then ends the run as Escape does (the preload stops, the
  // loop ends at once), and one during the log's writing waits for it - the log is always whole.
  const InterruptScope signals;
  LiveSetup s = SetUpLive(a);
  const Camera& camera = s.camera;
  std::unique_ptr<render::GlContext> context;
  if (a.window) {
    render::WindowOptions w;
    w.width_px = std::min(camera.image_width_px, 1280);
    w.height_px = std::max(1, w.width_px * camera.image_height_px / camera.image_width_px);
    w.vsync = true;
    w.title = "blurcue live: " + a.input;
    context = render::GlContext::CreateWindow(w);
  } else {
    context = render::GlContext::CreateOffscreen();
  }
  const calib::SceneCalib& lens = s.planner->lens();
  // Every GL object made once, before the first frame: the photo's texture and targets, each texture uploaded and
  // mipmapped by a warm-up frame of the objects at the lens's own pose.
  const cv::Mat grey(camera.image_height_px, camera.image_width_px, CV_8UC3, cv::Scalar::all(128));
  render::FrameCompositor compositor(camera, lens.rvec, lens.tvec, grey);
  {
    std::vector<scene::BlurredObject> warm;
    for (const stimulus::PlacedObject& p : s.planner->objects()) {
      scene::BlurredObject b;
      b.object = p.object;
      b.r_px = 2;
      warm.push_back(b);
    }
    compositor.Compose(warm);
    compositor.Finish();
  }
  if (!a.quiet)
    std::fprintf(stderr, "live: %s (%s), %zu object%s, blur %s with the lens of %s, exposure %s ms (%s), %s\n",
                 a.input.c_str(),
                 s.source->is_camera() ? "a camera, at its own rate"
                                       : ("played at " + Num(s.source->fps()) + " fps").c_str(),
                 s.planner->objects().size(), s.planner->objects().size() == 1 ? "" : "s", a.blur.c_str(),
                 s.lens_note.c_str(), Num(s.exposure_ms).c_str(),
                 s.exposure_note.c_str(), a.window ? "in a window (vsync)" : "headless");
  if (!a.quiet && a.preload)
    std::fprintf(stderr, "live: --preload: %d frames (%.0f MB) decoded in %.1f s before the start; decoding is not timed\n",
                 s.source->preloaded_frames(), s.source->preloaded_mb(), s.preload_s);
  LiveRecord record;
  record.rows.reserve(size_t(a.frames > 0 ? a.frames : 4096));
  RunLiveLoop(s, a, *context, compositor, record);
  live::LiveSummary summary = live::Summarize(record.rows, record.dropped, record.ended);
  summary.preloaded_frames = s.source->preloaded_frames();
  if (summary.shown > 0) summary.cpu_ms_per_frame = 1000 * record.cpu_s / summary.shown;
  WriteLiveLog(a, record, summary);
  // An end that is an error is said once, by the error on stderr (its line names the log too); a clean end here.
  if (!a.quiet) {
    if (!record.error) std::printf("%s\n", record.ended.c_str());
    std::printf("%s\nwrote %s (live.csv, drawn.csv, summary.json)\n", live::SummaryLine(summary).c_str(),
                a.log.c_str());
  }
  if (record.error)
    throw Error(record.error->kind(), std::string(record.error->what()) + "; the log of the " +
                                          std::to_string(record.rows.size()) + " frames shown is whole in " + a.log);
}

}  // namespace

void AddLiveCommand(CLI::App& app) {
  auto a = std::make_shared<LiveArgs>();
  CLI::App* cmd = app.add_subcommand(
      "live",
      "Show virtual objects in a camera's frames as they come: the thesis's prototype in real time.\n"
      "Each frame's board pose is tracked from the frame before (a full detection when tracking is lost), the objects\n"
      "are planned and drawn as `blurcue ar` draws them (the lens model's defocus x floor at each object's depth,\n"
      "streaked by its image motion since the last frame with a pose over the exposure, in linear light) and shown\n"
      "in a window with vsync (--window; Escape or closing it ends the run) or, without --window, headless.\n"
      "INPUT is a camera - /dev/videoN or an index N, through OpenCV's videoio (V4L2) - or a video file or image\n"
      "sequence (a printf pattern) played as a camera would deliver it: frame k at k / fps s from the start. Frames\n"
      "reach the drawing through a one-slot mailbox: one that arrives while the previous is still being drawn\n"
      "replaces it and is counted dropped, never queued. The lens model: --track DIR (a take `blurcue track` wrote\n"
      "with this camera) or --calib calib.json (`blurcue calibrate`), fixed; with --measure-sections N, N board\n"
      "sections are measured a frame, in turn, and the model is fitted again to every section's latest reading.\n"
      "Objects as in `blurcue ar`: --ball X,Y[,RADIUS], --card X,Y[,WIDTH[,HEIGHT]] (board mm), --objects FILE.\n"
      "\n"
      "Writes --log DIR whole at the end of the run (docs/live.md): live.csv (a row per frame shown: arrival, status,\n"
      "pose, track ms, render ms, display time, latency, dropped), drawn.csv (ar's CSV of what was drawn) and\n"
      "summary.json; the summary line is printed. The input ending, --frames, Escape, a closed window, Ctrl-C:\n"
      "exit 0. A camera that stops or a damaged frame: one line, exit 3, the log of the frames before it written.\n"
      "No camera at /dev/videoN: exit 3 naming it. DIR must be new or a log live wrote (other files: exit 2).\n"
      "Example: blurcue live take/take.avi --camera take/camera.json --track take/track --ball 87.5,125 --window\n"
      "         --log live-run");
  cmd->add_option("input", a->input, "/dev/videoN or N (a camera), a video file, or a printf pattern of images")
      ->required();
  cmd->add_option("--camera", a->camera, "the camera's camera.json (blurcue camera): the frames' size and intrinsics")
      ->required()->check(CLI::ExistingFile);
  cmd->add_option("--track", a->track, "the lens model of a take blurcue track wrote with this camera (its folder)");
  cmd->add_option("--calib", a->calib, "the lens model of a calib.json blurcue calibrate wrote with this camera")
      ->check(CLI::ExistingFile);
  cmd->add_option("--log", a->log, "the folder the run's log is written to (live.csv, drawn.csv, summary.json)")
      ->required();
  AddObjectOptions(cmd, &a->objects);
  cmd->add_option("--blur", a->blur,
                  "blur source at each object's centre: fitted (the lens model), estimated, none, or a radius in px\n"
                  "(measured sources need sections measured in every frame, which live does not do)")
      ->capture_default_str();
  cmd->add_option("--method", a->method, "the defocus's shape: disc (a thin lens's pillbox) or gaussian")
      ->capture_default_str()->check(OneOf({"disc", "gaussian"}));
  cmd->add_option("--exposure-ms", a->exposure_ms,
                  "the camera's exposure; objects are streaked by their image velocity over it (0: no motion blur).\n"
                  "Default: camera.json's exposure_ms; when unknown, half the frame interval of the pace")
      ->check(FiniteRange(0, 1000, "ms"));
  cmd->add_flag("--window", a->window, "show the frames in a window with vsync (Escape or closing it ends the run)");
  cmd->add_option("--fps", a->fps,
                  "the pace a video or image sequence is delivered at, frames per second (default: the video's own\n"
                  "rate; 30 for an image sequence); a camera keeps its own")
      ->check(FiniteRange(0.01, 1000, "frames per second"));
  cmd->add_option("--frames", a->frames, "read at most N frames of INPUT, then end as if it had ended (default: all, "
                                         "at most 108000)")
      ->check(IntRange(1, kMaxLiveFrames));
  cmd->add_option("--save-frame", a->save_frames,
                  "also write frame N as shown into DIR/frame-NNNN.png, or the first frame shown after it when N was\n"
                  "dropped, under its own number (repeatable; the read-back adds to that frame's latency)")
      ->check(IntRange(0, kMaxLiveFrames));
  cmd->add_option("--measure-sections", a->measure_sections,
                  "measure the blur of N board sections a frame, a rotating subset (all of them once in every\n"
                  "sections / N frames), and draw with the thin lens fitted to every section's latest reading once\n"
                  "they lie on 3 edges (the given model until then; fitted on a thread of its own, a frame draws with\n"
                  "the newest fit finished); live.csv says how many each frame measured.\n"
                  "0: none, the given model throughout; at least the board's sections: all of them every frame.\n"
                  "With --blur fitted only (no other source draws with the model)")
      ->capture_default_str()->check(IntRange(0, 10000));
  cmd->add_flag("--preload", a->preload,
                "decode the whole video or image sequence before the clock starts and deliver the frames from memory\n"
                "at their pace, as a camera hands over frames it decoded itself: the decoding, which a camera never\n"
                "costs this computer, is taken out of the latency (the summary line and summary.json say so). At most\n"
                "2000 MB decoded (760 frames of 1148 x 764; more is refused before decoding; --frames to play fewer);\n"
                "not for a camera");
  cmd->add_flag("--quiet", a->quiet, "print only errors");
  cmd->callback([a] { RunLive(*a); });
}

}  // namespace blurcue::cli
