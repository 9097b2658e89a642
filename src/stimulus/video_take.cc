#include "stimulus/video_take.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <optional>

#include "core/error.h"
#include "core/hash.h"
#include "core/names.h"
#include "optics/thin_lens.h"
#include "protocol/trials.h"
#include "stimulus/internal.h"
#include "track/frames.h"

namespace blurcue::stimulus {
namespace {

constexpr double kMaxTakeBytes = 4.0 * (1 << 30);

}  // namespace

VideoTake::VideoTake(const protocol::Protocol& protocol) {
  try {
    take_ = LoadTrackedTake(protocol.scene.track);
  } catch (const std::exception& e) {
    throw InputError(At(protocol, "/scene/track"), e.what());
  }
  const int n = int(take_.frames.size());
  first_posed_ = 0;
  while (!take_.frames[size_t(first_posed_)].calib) ++first_posed_;  // LoadTrackedTake: at least one has a pose
  last_posed_ = n - 1;
  while (!take_.frames[size_t(last_posed_)].calib) --last_posed_;
  // Over the whole take: track.csv's times are rounded to the microsecond, a step between two frames is not exact.
  const double span = take_.frames.back().time_s - take_.frames.front().time_s;
  fps_ = n > 1 && span > 0 ? (n - 1) / span : 30;
  // A camera exposes each frame within its own interval: a longer exposure is no camera's, and would streak the
  // objects over several frames' motion (and cost seconds a frame to draw).
  if (const std::string beyond = ExposureBeyondFrame(protocol.content.exposure_ms, fps_); !beyond.empty())
    throw InputError(At(protocol, "/content/exposure_ms"),
                     "is " + Num(protocol.content.exposure_ms) + " ms, " + beyond +
                         ": a camera exposes each frame within its own interval");
  const std::string track = protocol.scene.track.string(), video = protocol.scene.video.string();
  // Every frame is held decoded for the session (8-bit BGR): a take that would not fit is refused before decoding.
  const Camera& camera = take_.camera();
  const double bytes = 3.0 * camera.image_width_px * camera.image_height_px * (last_posed_ - first_posed_ + 1);
  if (bytes > kMaxTakeBytes)
    throw InputError(At(protocol, "/scene/track"),
                     "the take's " + std::to_string(last_posed_ - first_posed_ + 1) + " frames from the first to the "
                     "last with a pose would hold " + Num(bytes / (1 << 30)) + " GiB decoded (at most " +
                     Num(kMaxTakeBytes / (1 << 30)) + " GiB): cut the take, or track a shorter part of it");
  try {
    track::FrameSource source(video, fps_);
    cv::Mat image;
    int at = -1, read = 0;
    double time_s = 0;
    // Every frame track.csv lists must be in the video (a longer track.csv is another take's), each one posed the
    // frame that was tracked; frames after the last with a pose are read, not kept.
    while (at < n - 1) {
      if (!source.Next(&image, &at, &time_s))
        throw Error(ErrorKind::kInput, (read == 0 ? std::string("has no frames") :
                                         "has " + std::to_string(read) + " frames (0-" + std::to_string(read - 1) + ")") +
                                            ", but " + track + "/track.csv lists " + std::to_string(n) +
                                            " (the track of another take?)");
      ++read;
      CheckTakeFrame(take_, at, image, video, track);
      if (at > last_posed_) continue;
      if (at < first_posed_) {
        photos_.emplace_back();  // never shown
        continue;
      }
      photos_.push_back(image.clone());
    }
  } catch (const std::exception& e) {
    throw InputError(At(protocol, "/scene/video"), e.what());
  }
}

TakeFrameShown VideoTake::FrameAt(double t_s) const {
  const int last = int(take_.frames.size()) - 1;
  const double k = first_posed_ + std::floor(std::max(0.0, t_s) * fps_ + 1e-6);
  TakeFrameShown shown;
  const bool past = k > last;
  shown.take_frame = past ? last : int(k);
  shown.posed = std::min(shown.take_frame, last_posed_);
  while (!take_.frames[size_t(shown.posed)].calib) --shown.posed;  // first_posed_ <= posed: it has one
  const TrackedFrame& f = take_.frames[size_t(shown.take_frame)];
  shown.status = past || !f.calib ? "held" : track::Name(f.status);
  return shown;
}

void VideoTake::CheckMemory(const protocol::Protocol& protocol, cv::Size screen_photo) const {
  const Camera& camera = take_.camera();
  const double frames = double(PosedFrames().size());
  const double bytes = frames * (3.0 * camera.image_width_px * camera.image_height_px +
                                 4.0 * screen_photo.width * screen_photo.height);
  if (bytes > kMaxTakeBytes)
    throw InputError(At(protocol, "/scene/track"),
                     "the take's " + std::to_string(int(frames)) + " frames with a pose, decoded and resampled for a " +
                         std::to_string(screen_photo.width) + " x " + std::to_string(screen_photo.height) +
                         " px screen, would hold " + Num(bytes / (1 << 30)) + " GiB (at most " +
                         Num(kMaxTakeBytes / (1 << 30)) + " GiB): cut the take, or show it smaller");
}

Json TakeIdentity(const VideoTake& take) {
  std::string frames;
  for (const TrackedFrame& f : take.take().frames) {
    frames += std::to_string(f.index) + ' ' + track::Name(f.status);
    for (const double v : f.signature) frames += ' ' + Num(v);
    frames += '\n';
  }
  return {{"frames", take.take().frames.size()},
          {"fps", std::round(take.fps() * 1000) / 1000},
          {"frames_fnv1a64", HashHex(Fnv1a64(frames))}};
}

std::vector<int> VideoTake::PosedFrames() const {
  std::vector<int> posed;
  for (int i = first_posed_; i <= last_posed_; ++i)
    if (take_.frames[size_t(i)].calib) posed.push_back(i);
  return posed;
}

std::array<std::optional<scene::BlurredObject>, 2> VideoObjectsAt(const protocol::Protocol& protocol,
                                                                   const VideoTake& take, const TakeFrameShown& shown,
                                                                   const TrialScene& trial, double t_s) {
  auto objects = ObjectsAt(protocol, take.Calib(shown.posed), trial, t_s);
  if (trial.exposure_ms > 0)
    for (auto& o : objects)
      if (o) o->motion_px += StreakPx(take.take(), shown.posed, o->object.center_board_mm, trial.exposure_ms);
  return objects;
}

double TakeWindowS(const protocol::Protocol& protocol, const VideoTake& take, const protocol::Trial& trial,
                   const TrialScene& scene) {
  const protocol::Timing& timing = protocol::TimingOf(protocol, trial);
  if (scene.intervals > 0)
    return (scene.intervals * timing.interval_ms + (scene.intervals - 1) * timing.isi_ms) / 1000;
  if (timing.stimulus_ms > 0) return timing.stimulus_ms / 1000;
  double s = std::max((double(take.take().frames.size()) - take.first_posed()) / take.fps(), scene.MotionS());
  if (timing.deadline_ms > 0) s = std::min(s, timing.deadline_ms / 1000);
  return s;
}

namespace {

// The take as it plays in a window of `window_s` seconds: frame k of the take from (k - first) / fps to the next
// frame's start (the last frame to the window's end), clipped to the window; `f(from_s, to_s)` for each.
template <typename F>
void ForEachFrameSpan(const VideoTake& take, double window_s, F&& f) {
  const int n = int(take.take().frames.size());
  for (int k = take.first_posed(); k < n; ++k) {
    const double from = (k - take.first_posed()) / take.fps();
    if (from >= window_s) break;
    f(from, k == n - 1 ? window_s : std::min(window_s, (k + 1 - take.first_posed()) / take.fps()));
  }
}

// The frames with a pose a trial shows, each with its time on screen in the window (a lost one and the time past the
// take's end hold the frame before).
std::map<int, double> ShownFrames(const protocol::Protocol& protocol, const VideoTake& take,
                                  const protocol::Trial& trial, const TrialScene& scene) {
  std::map<int, double> weight;
  ForEachFrameSpan(take, TakeWindowS(protocol, take, trial, scene), [&](double from, double to) {
    weight[take.FrameAt(from + 0.5 / take.fps()).posed] += to - from;
  });
  return weight;
}

}  // namespace

void PlanVideoOnScreen(const protocol::Protocol& protocol, const VideoTake& take, const protocol::Trial& trial,
                       const Presentation& presentation, TrialScene* scene) {
  const TrialScene given = *scene;
  PlanOnScreen(protocol, take.Calib(take.first_posed()), presentation, scene);
  for (const auto& shown : ShownFrames(protocol, take, trial, given)) {
    if (shown.first == take.first_posed()) continue;
    TrialScene t = given;
    PlanOnScreen(protocol, take.Calib(shown.first), presentation, &t);
    scene->r_span_screen_px = std::max(scene->r_span_screen_px, t.r_span_screen_px);
    scene->per_pixel = scene->per_pixel || t.per_pixel;
  }
}

TrialScene DescribeVideoTrial(const protocol::Protocol& protocol, const VideoTake& take, const protocol::Trial& trial,
                              const Presentation& presentation) {
  auto describe = [&](int posed) {
    try {
      const calib::SceneCalib& c = take.Calib(posed);
      TrialScene t = DescribeTrial(protocol, trial, &c, &presentation);
      PlanOnScreen(protocol, c, presentation, &t);
      return t;
    } catch (const Error& e) {
      throw Error(e.kind(), std::string(e.what()) + " (in the take's frame " + std::to_string(posed) + ")");
    }
  };
  TrialScene scene = describe(take.first_posed());
  // Each frame with a pose, weighted by its time on screen in the window.
  const std::map<int, double> weight = ShownFrames(protocol, take, trial, scene);
  double total = 0;
  for (const auto& [posed, w] : weight) total += w;
  if (!(total > 0)) return scene;
  TrialScene mean = scene;
  mean.r_scene_px = 0;
  for (SideShown& side : mean.sides) side.r_px = side.floor_sigma_px = 0, side.motion_px = cv::Vec2d(0, 0);
  mean.r_span_screen_px = 0;
  mean.per_pixel = false;
  for (const auto& [posed, w] : weight) {
    const TrialScene t = posed == take.first_posed() ? scene : describe(posed);
    const double a = w / total;
    mean.r_scene_px += a * t.r_scene_px;
    for (size_t side = 0; side < 2; ++side) {
      mean.sides[side].r_px += a * t.sides[side].r_px;
      mean.sides[side].floor_sigma_px += a * t.sides[side].floor_sigma_px;
      mean.sides[side].motion_px += a * t.sides[side].motion_px;
    }
    mean.r_span_screen_px = std::max(mean.r_span_screen_px, t.r_span_screen_px);
    mean.per_pixel = mean.per_pixel || t.per_pixel;
  }
  if (scene.intervals > 0) return mean;  // each interval shows one side in the same place: frame by frame above
  // Each side's radius and streak are what is drawn, averaged over the window: VideoObjectsAt - the side's source at
  // the object's place at that moment, in the frame shown then, with the camera's streak over the exposure - in
  // steps within each take frame's time on screen, a sixteenth of a frame and at most a quarter board square of a
  // rolling ball's run apart (a measured source steps where the ball enters another section). A frame's own
  // DescribeTrial above averages a rolling ball over its whole run, and adds no camera streak.
  const double window = TakeWindowS(protocol, take, trial, scene);
  const double rate = std::max(16 * take.fps(), scene.speed_mm_s > 0 ? 4 * scene.speed_mm_s /
                                                                           take.take().board().square_mm : 0.0);
  double weight_of[2] = {0, 0}, r[2] = {0, 0};
  cv::Vec2d motion[2] = {{0, 0}, {0, 0}};
  ForEachFrameSpan(take, window, [&](double from, double to) {
    const int steps = std::clamp(int(std::ceil((to - from) * rate)), 1, 4000);
    for (int i = 0; i < steps; ++i) {
      const double t_s = from + (i + 0.5) * (to - from) / steps, w = (to - from) / steps;
      const TakeFrameShown shown = take.FrameAt(t_s);
      std::array<std::optional<scene::BlurredObject>, 2> objects;
      try {
        objects = VideoObjectsAt(protocol, take, shown, scene, t_s);
      } catch (const std::exception& e) {
        throw InputError(At(protocol, "/scene/track"), "trial " + std::to_string(trial.index + 1) +
                                                          " cannot be drawn in the take's frame " +
                                                          std::to_string(shown.take_frame) + " (" + Num(t_s) +
                                                          " s after onset): " + e.what());
      }
      for (size_t side = 0; side < 2; ++side)
        if (objects[side]) {
          weight_of[side] += w;
          r[side] += w * objects[side]->r_px;
          motion[side] += w * objects[side]->motion_px;
        }
    }
  });
  for (size_t side = 0; side < 2; ++side)
    if (weight_of[side] > 0)
      mean.sides[side].r_px = r[side] / weight_of[side], mean.sides[side].motion_px = motion[side] / weight_of[side];
  return mean;
}

void CheckVideoTrial(const protocol::Protocol& protocol, const VideoTake& take, const protocol::Trial& trial,
                     const TrialScene& scene) {
  // Every moment the trial can show: each frame of the take as it starts and, while a ball rolls (on to its end,
  // whatever frame is shown or held then), every half frame interval and every half board square of its run.
  std::vector<double> times;
  const double frame_s = 1 / take.fps();
  for (const int index : take.PosedFrames()) times.push_back((index - take.first_posed()) * frame_s);
  if (scene.MotionS() > 0) {
    const double step = std::min(frame_s / 2, 0.5 * take.take().board().square_mm / scene.speed_mm_s);
    const int n = int(std::min(4000.0, std::ceil(scene.MotionS() / step)));
    for (int i = 0; i <= n; ++i) times.push_back(std::min(scene.MotionS() - 1e-6, i * scene.MotionS() / n));
  }
  for (const double t_s : times) {
    const TakeFrameShown shown = take.FrameAt(t_s);
    const int index = shown.take_frame;
    try {
      for (const auto& o : VideoObjectsAt(protocol, take, shown, scene, t_s))
        if (o && !(o->r_px >= 0 && o->r_px <= optics::kMaxBlurRadiusPx &&
                   cv::norm(o->motion_px) <= optics::kMaxBlurRadiusPx))
          throw Error(ErrorKind::kDomain, "blur r " + Num(o->r_px) + " px, streak " + Num(cv::norm(o->motion_px)) +
                                              " px; each must be in [0, " + Num(optics::kMaxBlurRadiusPx) + "] px");
    } catch (const std::exception& e) {
      throw InputError(At(protocol, "/scene/track"), "trial " + std::to_string(trial.index + 1) +
                                                        " cannot be drawn in the take's frame " +
                                                        std::to_string(index) + " (" + Num(t_s) + " s after onset): " +
                                                        e.what());
    }
  }
}

}  // namespace blurcue::stimulus
