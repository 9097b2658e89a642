#include "session/stimulus.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <set>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/image.h"
#include "optics/thin_lens.h"
#include "render/blur.h"
#include "render/frame_compositor.h"
#include "render/scene_render.h"
#include "render/stimuli.h"
#include "store/export.h"

namespace blurcue::session {
namespace {

constexpr int kLeftSection = 3, kRightSection = 5;  // the balls roll side by side, one section apart

using protocol::FindLevel;

// "FILE: /pointer": where a problem of a trial comes from in the protocol.
std::string At(const protocol::Protocol& p, const std::string& pointer) {
  return p.file.string() + ": " + (pointer.empty() ? "/" : pointer);
}

// `where` names the field that chose the source ("FILE: /pointer"), made only when there is a problem to name. A
// fixed radius on the screen is converted to photo px by `presentation`.
calib::BlurSource Source(const Json& v, double* fixed, const std::function<std::string()>& where,
                         const Presentation* presentation) {
  if (v.is_number()) {
    *fixed = v.get<double>();
    return calib::BlurSource::kFixed;
  }
  if (v.is_object() && v.size() == 1 && (v.contains("screen_px") || v.contains("arcmin")) && v.front().is_number()) {
    if (!presentation || presentation->scale <= 0)
      throw InputError(where(), "a radius on the screen needs the display it is shown on, got " + v.dump());
    const double r = v.front().get<double>();
    const double screen_px = v.contains("arcmin") ? display::ScreenPxOfArcmin(presentation->profile, r) : r;
    *fixed = screen_px / presentation->scale;
    return calib::BlurSource::kFixed;
  }
  if (!v.is_string()) throw InputError(where(), "the trial shows no blur source on this side, got " + v.dump());
  try {
    return calib::ParseBlurSource(v.get<std::string>(), fixed);
  } catch (const Error& e) {
    throw InputError(where(), e.what());
  }
}

// Board-frame placement of the two objects of a pair (render's poses on the board; x and y in mm where the trial
// says so).
render::VirtualObject Card(const calib::SceneCalib& s, const TrialScene& t, bool left) {
  render::VirtualObject o = render::CardBesideBoard(s.board, 1, left, t.card_width_mm);
  o.card_height_mm = t.card_height_mm;
  o.standing = t.standing;
  o.rotation_deg = t.rotation_deg;
  const double x = left ? t.left_x_mm : t.right_x_mm;
  // Its centre at the placement; a standing card's lowest edge rests at height_mm above the table.
  const double h = o.card_height_mm > 0 ? o.card_height_mm : o.size_mm;
  o.center_board_mm = {std::isnan(x) ? o.center_board_mm[0] : x, t.from_y_mm, t.height_mm + (t.standing ? h / 2 : 0)};
  return o;
}
render::VirtualObject Ball(const calib::SceneCalib& s, const TrialScene& t, double y_mm, double radius_mm, bool left) {
  render::VirtualObject o =
      render::BallOnBoard(s.board, left ? kLeftSection : kRightSection, y_mm, radius_mm, t.from_y_mm);
  const double x = left ? t.left_x_mm : t.right_x_mm;
  if (!std::isnan(x)) o.center_board_mm[0] = x;
  o.center_board_mm[2] += t.height_mm;
  return o;
}

// The largest distance between two points of an outline (px).
double ExtentPx(const std::vector<cv::Point2d>& outline) {
  double extent = 0;
  for (const cv::Point2d& p : outline)
    for (const cv::Point2d& q : outline) extent = std::max(extent, cv::norm(p - q));
  return extent;
}

}  // namespace

double TrialScene::MotionS() const {
  return speed_mm_s > 0 ? std::abs(to_y_mm - from_y_mm) / speed_mm_s : 0;
}

double TrialScene::BallYMm(double t_s) const {
  const double run = std::abs(to_y_mm - from_y_mm);
  const double travelled = speed_mm_s * std::max(0.0, t_s);
  if (travelled >= run && wipe_at_end && speed_mm_s > 0) return -std::numeric_limits<double>::infinity();
  return from_y_mm + (to_y_mm >= from_y_mm ? 1 : -1) * std::min(run, travelled);
}

namespace {

// What a pair trial shows at the start and at the end of its run (the same twice for a still one; the end taken just
// before a section run's wipe): where a check of its whole extent looks.
std::array<std::array<std::optional<render::BlurredObject>, 2>, 2> RunEnds(const protocol::Protocol& protocol,
                                                                         const calib::SceneCalib& scene,
                                                                         const TrialScene& trial) {
  return {ObjectsAt(protocol, scene, trial, 0),
          ObjectsAt(protocol, scene, trial, std::max(0.0, trial.MotionS() - 1e-6))};
}

// A placement must show: each object, at the start and at the end of its run, must land in the photo.
void CheckInPhoto(const protocol::Protocol& protocol, const protocol::Trial& trial, const calib::SceneCalib& scene,
                  const TrialScene& t) {
  const cv::Rect photo(0, 0, scene.camera.image_width_px, scene.camera.image_height_px);
  for (const auto& objects : RunEnds(protocol, scene, t)) {
    for (size_t side = 0; side < 2; ++side) {
      // An intervals trial shows the right side's object at the left's place (IntervalScene): side 0's check is its.
      if (!objects[side] || (side == 1 && t.intervals > 0)) continue;
      if ((render::FootprintOf(scene.camera, scene.rvec, scene.tvec, objects[side]->object).bounds & photo).empty()) {
        const char* level = t.content == "grid" ? (std::isnan(side == 0 ? t.left_x_mm : t.right_x_mm) ? "edge"
                                                   : side == 0 ? "left_x_mm" : "right_x_mm")
                                                : "speed_cm_s";
        throw InputError(protocol.file.string() + ": " + protocol::LevelPointer(protocol, trial, level),
                         std::string("the ") + (side == 0 ? "left" : "right") + " " + t.content + " at (" +
                             std::to_string(int(std::lround(objects[side]->object.center_board_mm[0]))) + ", " +
                             std::to_string(int(std::lround(objects[side]->object.center_board_mm[1]))) +
                             ") mm on the board lies outside the " + std::to_string(photo.width) + " x " +
                             std::to_string(photo.height) + " photo (trial " + std::to_string(trial.index) + ")");
      }
    }
  }
}

}  // namespace

TrialScene DescribeTrial(const protocol::Protocol& protocol, const protocol::Trial& trial,
                         const calib::SceneCalib* scene, const Presentation* presentation) {
  TrialScene t;
  t.content = protocol.content.type;
  t.left_only = protocol.layout == "single";
  t.intervals = protocol::IntervalCount(protocol);
  t.kernel = protocol.content.kernel;
  t.brightness = protocol.content.brightness;
  t.contrast = protocol.content.contrast;
  t.white_balance = protocol.content.white_balance;
  // Problems name the protocol field that asked for what cannot be shown, and the trial as a detail.
  const std::string trial_text = " (trial " + std::to_string(trial.index) + ", block " + trial.block + ")";
  if (t.content == "picture") {
    const Json* d = FindLevel(trial.levels, "distance_m");
    t.distance_m = d && d->is_number() ? d->get<double>() : 1.0;
    // The real picture's blur: the thin lens of the camera that took its photo (content.real_camera).
    if (const auto& camera = protocol.content.real_camera) {
      try {
        t.r_scene_px = optics::BlurRadiusPx(optics::Lens::FromCamera(*camera), protocol.content.real_focus_m * 1000,
                                            t.distance_m * 1000);
        // As synth-pictures refuses to make such a photo: a blur past any kernel is a wrong focus or camera.
        if (!(t.r_scene_px <= optics::kMaxBlurRadiusPx))
          throw Error(ErrorKind::kDomain, "the real picture at " + protocol::LevelText(t.distance_m) +
                                              " m would be blurred by " + std::to_string(std::lround(t.r_scene_px)) +
                                              " px, more than the largest blur (" +
                                              std::to_string(int(optics::kMaxBlurRadiusPx)) + " px)");
      } catch (const Error& e) {
        throw InputError(At(protocol, "/content/real_camera"), std::string(e.what()) + trial_text);
      }
    }
    return t;
  }
  if (!scene) throw InputError(protocol.file.string(), "/scene/calib: a " + t.content + " needs a calibration");
  // Where a side's source was chosen ("" for the scene's own blur, the calibration's): looked up only for a message.
  auto field = [&](const char* side) {
    return At(protocol, side ? protocol::SidePointer(protocol, trial, side) : "/scene/calib");
  };
  t.left = Source(trial.left, &t.left_fixed_px, [&] { return field("left"); }, presentation);
  t.right = Source(trial.right, &t.right_fixed_px, [&] { return field("right"); }, presentation);
  const double s = scene->board.square_mm;
  // Where the right side's object is shown, so where its radius is evaluated: its own place, or in an intervals
  // trial the left object's (IntervalScene shows each side alone there). Evaluated at its own place, a place-dependent
  // source (measured_section, estimated, fitted) gave the right interval a radius of somewhere not shown.
  const bool right_place = t.intervals > 0;  // Card / Ball: true = the left object's place
  // A radius that cannot be evaluated (eq. 3.7 nearer than focus, no usable measured section) is a problem of the
  // source the protocol chose with this calibration: an input error naming that field.
  auto r_at = [&](const cv::Vec3d& board_mm, calib::BlurSource source, double fixed, const char* side) {
    try {
      const double r = calib::BlurAtPx(*scene, source, scene->ToCamera(board_mm), fixed);
      if (!std::isfinite(r) || r < 0) throw Error(ErrorKind::kDomain, "radius " + std::to_string(r) + " px");
      return r;
    } catch (const Error& e) {
      throw InputError(field(side), calib::ToString(source) + " blur cannot be evaluated with " +
                                        protocol.scene.calib.string() + trial_text + ": " + e.what());
    }
  };
  // Edges and sections are the calibrated board's: its own count, whatever its size.
  const int edges = scene->board.EdgeCount();
  auto board_level = [&](const char* name, int most) -> std::optional<int> {
    const Json* v = FindLevel(trial.levels, name);
    if (!v || !v->is_number_integer()) return std::nullopt;
    const int n = v->get<int>();
    if (n < 1 || n > most)
      throw InputError(At(protocol, protocol::LevelPointer(protocol, trial, name)),
                       std::string(name) + " " + std::to_string(n) + " is not on the calibrated board (" +
                           std::to_string(scene->board.cols) + " x " + std::to_string(scene->board.rows) +
                           " squares: edges 1-" + std::to_string(edges) + ", sections 1-" + std::to_string(edges - 1) +
                           ")" + trial_text);
    return n;
  };
  auto mm_level = [&](const char* name) {
    const Json* v = FindLevel(trial.levels, name);
    return v && v->is_number() ? std::optional<double>(v->get<double>()) : std::nullopt;
  };
  if (auto x = mm_level("left_x_mm")) t.left_x_mm = *x;
  if (auto x = mm_level("right_x_mm")) t.right_x_mm = *x;
  t.height_mm = mm_level("height_mm").value_or(protocol.content.height_mm);
  if (t.content == "grid") {
    t.card_width_mm = protocol.content.size_mm;
    t.card_height_mm = protocol.content.card_height_mm;
    t.standing = protocol.content.standing;
    t.rotation_deg = mm_level("rotation_deg").value_or(protocol.content.rotation_deg);
  }
  if (t.content == "grid") {
    const auto edge = board_level("edge", edges);
    const auto y = mm_level("y_mm");
    if (!edge && !y)
      throw InputError(At(protocol, protocol::LevelPointer(protocol, trial, "edge")),
                       "a grid needs an integer level edge or a y_mm" + trial_text);
    t.edge = edge ? *edge : 0;
    t.from_y_mm = t.to_y_mm = y ? *y : (*edge - 1) * s;
    const cv::Vec3d l = Card(*scene, t, true).center_board_mm, r = Card(*scene, t, right_place).center_board_mm;
    t.r_left_px = r_at(l, t.left, t.left_fixed_px, "left");
    t.r_right_px = r_at(r, t.right, t.right_fixed_px, "right");
    t.r_scene_px = 0.5 * (r_at(l, calib::BlurSource::kFitted, 0, nullptr) +
                          r_at(r, calib::BlurSource::kFitted, 0, nullptr));
    CheckInPhoto(protocol, trial, *scene, t);
    return t;
  }
  // Balls: a section run (edge s to s + 1, wiped on arrival), explicit edges, the whole board, or at rest at an
  // edge. A ball without a speed rests where it starts, and its radii are those of that place, not of a run.
  int from = 1, to = scene->board.EdgeCount();
  const Json* speed = FindLevel(trial.levels, "speed_cm_s");
  t.speed_mm_s = speed && speed->is_number() ? 10 * speed->get<double>() : 0;
  const auto edge = board_level("edge", edges);
  const auto rest_y = mm_level("y_mm");
  if (edge || rest_y) {
    if (t.speed_mm_s > 0 || FindLevel(trial.levels, "section") || FindLevel(trial.levels, "from_edge") ||
        FindLevel(trial.levels, "to_edge") || FindLevel(trial.levels, "from_y_mm") ||
        FindLevel(trial.levels, "to_y_mm") || (edge && rest_y))
      throw InputError(At(protocol, protocol::LevelPointer(protocol, trial, edge ? "edge" : "y_mm")),
                       "a ball at an edge (or y_mm) rests there: it takes no speed_cm_s, section, from/to edge or "
                       "y_mm, and not both edge and y_mm" + trial_text);
    if (edge) from = to = *edge;
  } else if (const auto section = board_level("section", edges - 1)) {
    from = *section;
    to = from + 1;
    t.wipe_at_end = true;
  } else {
    if (const auto f = board_level("from_edge", edges)) from = *f;
    if (const auto e = board_level("to_edge", edges)) to = *e;
  }
  // Without a speed the ball rests where it starts: an end or a section it would run to is never shown (it would be
  // recorded all the same).
  if (t.speed_mm_s <= 0)
    for (const char* run_level : {"section", "to_edge", "to_y_mm"})
      if (FindLevel(trial.levels, run_level))
        throw InputError(At(protocol, protocol::LevelPointer(protocol, trial, run_level)),
                         std::string("a ball without a speed_cm_s rests where it starts: ") + run_level +
                             " describes a run it never makes (give a speed, or place it with edge, y_mm or "
                             "from_edge)" + trial_text);
  t.from_y_mm = rest_y ? *rest_y : mm_level("from_y_mm").value_or((from - 1) * s);
  t.to_y_mm = rest_y ? *rest_y : mm_level("to_y_mm").value_or((to - 1) * s);
  if (t.speed_mm_s <= 0) t.to_y_mm = t.from_y_mm;
  // Radii averaged over the run (what the observer sees on the whole), sampled evenly along it.
  const int samples = 21;
  const double radius = protocol.content.radius_mm;
  for (int i = 0; i < samples; ++i) {
    const double y = t.from_y_mm + (t.to_y_mm - t.from_y_mm) * i / (samples - 1);
    const cv::Vec3d l = Ball(*scene, t, y, radius, true).center_board_mm;
    const cv::Vec3d r = Ball(*scene, t, y, radius, right_place).center_board_mm;
    t.r_left_px += r_at(l, t.left, t.left_fixed_px, "left") / samples;
    t.r_right_px += r_at(r, t.right, t.right_fixed_px, "right") / samples;
    t.r_scene_px += 0.5 * (r_at(l, calib::BlurSource::kFitted, 0, nullptr) +
                           r_at(r, calib::BlurSource::kFitted, 0, nullptr)) / samples;
  }
  // Every edge the run passes, too: the samples step over edges on a long board, and a frame there must have a
  // radius (a measured source is its nearest edge's value, refused for an edge with no usable section).
  for (int k = 1; k <= edges; ++k) {
    const double y = (k - 1) * s;
    if (y < std::min(t.from_y_mm, t.to_y_mm) || y > std::max(t.from_y_mm, t.to_y_mm)) continue;
    r_at(Ball(*scene, t, y, radius, true).center_board_mm, t.left, t.left_fixed_px, "left");
    r_at(Ball(*scene, t, y, radius, right_place).center_board_mm, t.right, t.right_fixed_px, "right");
  }
  CheckInPhoto(protocol, trial, *scene, t);
  return t;
}

std::array<std::optional<render::BlurredObject>, 2> ObjectsAt(const protocol::Protocol& protocol,
                                                              const calib::SceneCalib& s, const TrialScene& trial,
                                                              double t_s) {
  std::array<std::optional<render::BlurredObject>, 2> shown;
  for (const bool left : {true, false}) {
    if (!left && trial.left_only) continue;
    render::BlurredObject b;
    render::VirtualObject& o = b.object;
    const calib::BlurSource source = left ? trial.left : trial.right;
    const double fixed = left ? trial.left_fixed_px : trial.right_fixed_px;
    const double gain = left ? trial.left_gain : trial.right_gain, add = left ? trial.left_add_px : trial.right_add_px;
    if (trial.content == "grid") {
      o = Card(s, trial, left);
    } else {
      const double y = trial.BallYMm(t_s);
      if (!std::isfinite(y)) continue;  // wiped at the end of a section
      o = Ball(s, trial, y, protocol.content.radius_mm, left);
    }
    if (trial.per_pixel) {
      // The radius along the object's line of sight at each depth: the source evaluated where the pixel's surface is.
      const cv::Vec3d centre = s.ToCamera(o.center_board_mm);
      b.r_of_depth_px = [&s, source, fixed, centre, gain, add](double z) {
        return gain * calib::BlurAlongSightPx(s, source, centre, z, fixed) + add;
      };
    }
    o.brightness = trial.brightness;
    o.contrast = trial.contrast;
    o.white_balance = {trial.white_balance[0], trial.white_balance[1], trial.white_balance[2]};
    b.method = trial.kernel;
    b.r_px = gain * calib::BlurAtPx(s, source, s.ToCamera(o.center_board_mm), fixed) + add;
    shown[left ? 0 : 1] = std::move(b);
  }
  return shown;
}

Presentation Presentation::Of(const protocol::Protocol& protocol, const StimulusImages& images,
                              const display::Profile& profile) {
  Presentation p;
  p.window_width_px = protocol.display.width_px;
  p.window_height_px = protocol.display.height_px;
  p.profile = profile;
  // The prompt's band: a line of text at the display's scale (TextScreen's unit).
  if (std::any_of(protocol.blocks.begin(), protocol.blocks.end(), [](const auto& b) { return !b.prompt.empty(); }))
    p.prompt_band_px = std::max(32, protocol.display.height_px / 12);
  // The stimulus has the window above the prompt's band.
  const int W = p.window_width_px, H = p.window_height_px - p.prompt_band_px;
  if (protocol.content.type == "picture") {
    // The depth-matching frame, 4:3, as large as the window holds (the thesis's 960 x 720 in a 1280 x 720 one).
    p.layout = render::DepthMatchingLayout::Of(std::min(W, H * 4 / 3), images.picture.size());
    p.frame_width_px = p.layout.frame.width;
    p.frame_height_px = p.layout.frame.height;
    p.scaling = "fit";
    p.view = {W, p.window_height_px, p.frame_width_px, p.frame_height_px, (W - p.frame_width_px) / 2,
              (H - p.frame_height_px) / 2};
    if (const auto& camera = protocol.content.real_camera)
      p.real_frame_px_per_px = p.layout.LowerScale(cv::Size(camera->image_width_px, camera->image_height_px));
    return p;
  }
  p.frame_width_px = images.photo.cols;
  p.frame_height_px = images.photo.rows;
  const int w = p.frame_width_px, h = p.frame_height_px;
  if (w <= 0 || h <= 0) return p;
  using protocol::Scaling;
  const Scaling scaling = protocol.display.scaling;
  double scale = 1;
  switch (scaling) {
    case Scaling::kFit: scale = render::FitScale(w, h, W, H), p.scaling = "fit"; break;
    case Scaling::kNative: scale = 1, p.scaling = "native"; break;
    case Scaling::kScale: scale = protocol.display.scale, p.scaling = "scale"; break;
    case Scaling::kDegrees:
      scale = protocol.display.width_deg * display::PxPerDeg(profile) / w, p.scaling = "degrees";
      break;
  }
  // Whole screen px: the photo's shown width sets the scale recorded, its height follows.
  const double shown_w = std::round(w * scale);
  if (!(shown_w >= 8 && shown_w <= 16384 && h * scale >= 8 && h * scale <= 16384)) {
    const bool degrees = scaling == Scaling::kDegrees;
    throw InputError(protocol.file.string() + (degrees ? ": /display/width_deg" : ": /display/scale"),
                     "shows the " + std::to_string(w) + " x " + std::to_string(h) + " px photo " +
                         std::to_string(int(shown_w)) + " px wide" +
                         (degrees ? " (at " + std::to_string(display::PxPerDeg(profile)) + " px/deg)" : "") +
                         "; it must be 8 to 16384 px on screen");
  }
  p.scale = shown_w / w;
  const int pw = int(shown_w), ph = int(std::lround(h * p.scale));
  p.view = {W, p.window_height_px, pw, ph, (W - pw) / 2, (H - ph) / 2};
  return p;
}

double Presentation::LevelScreenPx(double cutoff) const {
  return cutoff > 0 ? ScreenPx(2 * render::ButterworthEquivalentSigma(cutoff) * layout.picture.width) : 0;
}

render::FrameView Presentation::ViewFor(const protocol::Protocol& protocol, const calib::SceneCalib& scene,
                                        const TrialScene& trial) const {
  render::FrameView v = view;
  if (v.photo_width_px <= v.width_px && v.photo_height_px <= v.height_px - prompt_band_px) return v;
  // What the trial shows, in photo px: both objects at the start and at the end of their run.
  cv::Rect shows;
  for (const auto& objects : RunEnds(protocol, scene, trial))
    for (const auto& object : objects)
      if (object) {
        const cv::Rect b = render::FootprintOf(scene.camera, scene.rvec, scene.tvec, object->object).bounds;
        shows = shows.empty() ? b : (shows | b);
      }
  if (shows.empty()) return v;
  // Centre it, then keep the window covered by the photo along any side where the photo is the larger.
  auto place = [](double centre_photo_px, double scale, int photo_px, int window_px) {
    if (photo_px <= window_px) return (window_px - photo_px) / 2;
    const int x = int(std::lround(window_px / 2.0 - (scale * (centre_photo_px + 0.5) - 0.5)));
    return std::clamp(x, window_px - photo_px, 0);
  };
  const double sx = double(v.photo_width_px) / frame_width_px, sy = double(v.photo_height_px) / frame_height_px;
  v.x_px = place(shows.x + shows.width / 2.0, sx, v.photo_width_px, v.width_px);
  v.y_px = place(shows.y + shows.height / 2.0, sy, v.photo_height_px, v.height_px - prompt_band_px);
  return v;
}

bool IntervalShowsRight(const protocol::Trial& trial, const TrialScene& scene, int i) {
  if (scene.intervals == 2) return i == 1;
  return trial.task == protocol::Task::kForcedChoice && !trial.test_side.empty() &&
         std::isdigit(static_cast<unsigned char>(trial.test_side[0])) && std::stoi(trial.test_side) == i + 1;
}

TrialScene IntervalScene(const TrialScene& scene, bool right) {
  TrialScene s = scene;
  s.left_only = true;
  if (right) {
    s.left = s.right;
    s.left_fixed_px = s.right_fixed_px;
    s.left_gain = s.right_gain;
    s.left_add_px = s.right_add_px;
    s.r_left_px = s.r_right_px;
  }
  return s;
}

void ApplyLevel(const protocol::Procedure& procedure, const protocol::Trial& trial, double level,
                const Presentation& presentation, TrialScene* scene) {
  const bool left = trial.test_side == "left";
  double& gain = left ? scene->left_gain : scene->right_gain;
  double& add = left ? scene->left_add_px : scene->right_add_px;
  double& r = left ? scene->r_left_px : scene->r_right_px;
  const double reference = (r - add) / gain;  // as DescribeTrial made it
  if (procedure.variable == "relative_difference") {
    gain = 1 + level, add = 0;
  } else {
    gain = 1;
    add = presentation.scale > 0 ? display::ScreenPxOfArcmin(presentation.profile, level) / presentation.scale : 0;
  }
  r = gain * reference + add;
  scene->level = level;
}

void PlanOnScreen(const protocol::Protocol& protocol, const calib::SceneCalib& s, const Presentation& presentation,
              TrialScene* trial) {
  if (trial->content == "picture") return;
  const protocol::Content& c = protocol.content;
  const double threshold = c.depth_blur_threshold_unit == "arcmin"
                               ? display::ScreenPxOfArcmin(presentation.profile, c.depth_blur_threshold)
                               : c.depth_blur_threshold;
  // The objects as the per-pixel plan would draw them: each one's radius at its nearest and farthest depth is what
  // that plan would give those pixels (a procedure's gain included).
  TrialScene as_per_pixel = *trial;
  as_per_pixel.per_pixel = true;
  const auto ends = RunEnds(protocol, s, as_per_pixel);
  double span = 0;
  for (const auto& shown : ends)
    for (const auto& object : shown) {
      if (!object) continue;
      const render::Footprint f = render::FootprintOf(s.camera, s.rvec, s.tvec, object->object);
      span = std::max(span, presentation.ScreenPx(std::abs(object->r_of_depth_px(f.z_max_mm) -
                                                           object->r_of_depth_px(f.z_min_mm))));
    }
  trial->r_span_screen_px = span;
  trial->per_pixel = span >= threshold;
  const auto& onset = ends[0];
  for (size_t side = 0; side < 2; ++side)
    (side == 0 ? trial->size_left_deg : trial->size_right_deg) =
        onset[side] ? display::ArcminOfScreenPx(presentation.profile,
                                                presentation.ScreenPx(ExtentPx(render::OutlineOf(
                                                    s.camera, s.rvec, s.tvec, onset[side]->object)))) /
                          60
                    : 0;
}

Json TrialVariables(const protocol::Trial& trial, const TrialScene& scene, const Presentation& presentation) {
  // Every level under store::DesignColumn's name: one named like a column of trials.csv or a variable recorded
  // below (status, r_left_px, level, correct, ...) as factor_NAME, so what is recorded never overwrites a level.
  Json v = Json::object();
  if (trial.levels.is_object())
    for (const auto& [name, level] : trial.levels.items()) v[store::DesignColumn(name)] = level;
  // A level object's values get columns of their own (a pattern's speed_cm_s, a conditions table's edge); the sides
  // are recorded as such. A conditions table's row object itself is no factor of the design: only its columns stay.
  for (const auto& [name, level] : trial.levels.items())
    if (level.is_object())
      for (const auto& [key, value] : level.items())
        if (key != "left" && key != "right" && key != "object" && !v.contains(store::DesignColumn(key)))
          v[store::DesignColumn(key)] = value;
  if (v.contains("row") && v["row"].is_object()) v.erase("row");
  v["practice"] = trial.practice ? 1 : 0;
  v["block_name"] = trial.block;
  v["swapped"] = trial.swapped ? 1 : 0;
  if (trial.round >= 0) v["round"] = trial.round + 1;  // a practice block run until a criterion: which run
  if (trial.cell >= 0) {  // a procedure's trial: which of its block's procedures, the test side, the level shown
    v["procedure_cell"] = trial.cell;
    v["test_side"] = trial.test_side;
    if (!std::isnan(scene.level)) v["level"] = scene.level;
  }
  // Odd one out: the interval that showed the right side's object (the correct answer), and how many there were.
  if (scene.intervals > 2 && trial.task == protocol::Task::kForcedChoice) {
    v["odd_interval"] = std::stoi(trial.test_side);
    v["intervals"] = scene.intervals;
  }
  // Rounded to 1e-4 px: the record is read by people and charts, not fed back.
  auto round4 = [](double x) { return std::round(x * 1e4) / 1e4; };
  if (trial.task == protocol::Task::kAdjustment) {
    if (trial.start_index >= 0 && size_t(trial.start_index) < trial.adjust_levels.size())
      v["start_level"] = trial.adjust_levels[size_t(trial.start_index)];
    // The levels in the order "next" steps through them (cyclic): what the participant could reach, as shown.
    std::string levels;
    for (double level : trial.adjust_levels) levels += (levels.empty() ? "" : ";") + protocol::LevelText(level);
    v["adjust_levels"] = levels;
  }
  if (scene.content == "picture") {
    // The virtual picture's width as shown (a level c's blur is r = 2 x 0.1874 x this / c arcmin), and the real
    // picture's blur when its camera is known: in its camera's px, on the screen and on the eye.
    v["picture_width_arcmin"] = round4(presentation.Arcmin(presentation.layout.picture.width));
    if (presentation.real_frame_px_per_px > 0) {
      v["r_scene_px"] = round4(scene.r_scene_px);
      v["r_scene_screen_px"] = round4(presentation.ScreenPx(scene.r_scene_px * presentation.real_frame_px_per_px));
      v["r_scene_arcmin"] = round4(presentation.RealArcmin(scene.r_scene_px));
    }
  } else if (trial.task != protocol::Task::kAdjustment) {
    // Each radius as the camera made it (photo px), as the window shows it (screen px) and as the eye gets it.
    // The single layout shows only its object, recorded as the left side.
    for (const auto& [name, r] : {std::pair<const char*, double>{"left", scene.r_left_px},
                                  {"right", scene.r_right_px}, {"scene", scene.r_scene_px}}) {
      if (scene.left_only && name == std::string("right")) continue;
      v[std::string("r_") + name + "_px"] = round4(r);
      v[std::string("r_") + name + "_screen_px"] = round4(presentation.ScreenPx(r));
      v[std::string("r_") + name + "_arcmin"] = round4(presentation.Arcmin(r));
    }
    v["screen_px_per_photo_px"] = std::round(presentation.scale * 1e6) / 1e6;
    v["kernel"] = scene.kernel;
    v["blur_plan"] = scene.per_pixel ? "per_pixel" : "one_radius";
    v["r_span_screen_px"] = round4(scene.r_span_screen_px);
    v["size_left_deg"] = round4(scene.size_left_deg);
    if (!scene.left_only) v["size_right_deg"] = round4(scene.size_right_deg);
    v["brightness"] = scene.brightness;
    v["contrast"] = scene.contrast;
    v["white_balance_r"] = scene.white_balance[0];
    v["white_balance_g"] = scene.white_balance[1];
    v["white_balance_b"] = scene.white_balance[2];
  }
  return v;
}

Json DescribeFrame(const calib::SceneCalib* scene, const TrialScene& trial, const Presentation& presentation,
                   const render::FrameView& view, const std::array<std::optional<render::BlurredObject>, 2>& shown,
                   double cutoff) {
  const display::Profile& profile = presentation.profile;
  auto round = [](double x, double unit) {  // to a decimal unit, printed as such
    const double per = std::round(1 / unit);
    return std::round(x * per) / per;
  };
  Json frame = {
      {"display",
       // The monitor (its px go with its mm) and the window on it.
       {{"width_px", profile.width_px}, {"height_px", profile.height_px}, {"width_mm", profile.width_mm},
        {"height_mm", profile.height_mm}, {"distance_mm", profile.distance_mm},
        {"px_per_deg", round(display::PxPerDeg(profile), 1e-4)}, {"profile", profile.name},
        {"window_px", {view.width_px, view.height_px}}}},
      {"scaling", presentation.scaling},
      {"screen_px_per_photo_px", round(presentation.scale, 1e-6)},
      {"photo_rect_px", {view.x_px, view.y_px, view.photo_width_px, view.photo_height_px}},
      {"blur_plan", trial.content == "picture" ? "none" : trial.per_pixel ? "per_pixel" : "one_radius"},
      {"r_span_screen_px", std::round(trial.r_span_screen_px * 1e4) / 1e4},
      {"objects", Json::array()}};
  if (trial.content == "picture") {
    // The frame is shown at one screen px per frame px where `view` places it.
    const render::DepthMatchingLayout& l = presentation.layout;
    auto on_screen = [&](const cv::Rect& r) { return Json{view.x_px + r.x, view.y_px + r.y, r.width, r.height}; };
    frame["picture"] = {{"rect_px", on_screen(l.picture)},
                        {"cutoff", cutoff},
                        {"r_screen_px", round(presentation.LevelScreenPx(cutoff), 1e-4)},
                        {"r_arcmin", round(presentation.LevelArcmin(cutoff), 1e-4)},
                        {"width_arcmin", round(presentation.Arcmin(l.picture.width), 1e-4)}};
    Json real = {{"rect_px", on_screen(l.lower)}, {"distance_m", trial.distance_m}};
    if (presentation.real_frame_px_per_px > 0) {
      real["r_camera_px"] = round(trial.r_scene_px, 1e-4);
      real["r_screen_px"] = round(presentation.ScreenPx(trial.r_scene_px * presentation.real_frame_px_per_px), 1e-4);
      real["r_arcmin"] = round(presentation.RealArcmin(trial.r_scene_px), 1e-4);
    }
    frame["real_picture"] = real;
    return frame;
  }
  if (!scene) return frame;
  const Camera camera = view.CameraOf(scene->camera);
  for (int side = 0; side < 2; ++side) {
    if (!shown[size_t(side)]) continue;
    const render::BlurredObject& b = *shown[size_t(side)];
    const std::vector<cv::Point2d> outline = render::OutlineOf(camera, scene->rvec, scene->tvec, b.object);
    std::vector<cv::Point2d> centre;
    cv::projectPoints(std::vector<cv::Point3d>{cv::Point3d(b.object.center_board_mm)}, scene->rvec, scene->tvec,
                      cv::Matx33d(camera.Intrinsics().data()), camera.dist_coeffs, centre);
    Json polygon = Json::array();
    for (const cv::Point2d& p : outline) polygon.push_back({round(p.x, 1e-3), round(p.y, 1e-3)});
    frame["objects"].push_back(
        {{"side", side == 0 ? "left" : "right"},
         {"kind", b.object.kind == render::VirtualObject::Kind::kBall ? "ball" : "card"},
         {"source", calib::ToString(side == 0 ? trial.left : trial.right)},
         {"kernel", b.method},
         {"center_px", {round(centre[0].x, 1e-3), round(centre[0].y, 1e-3)}},
         {"outline_px", polygon},
         {"r_camera_px", round(b.r_px, 1e-4)},
         {"r_screen_px", round(presentation.ScreenPx(b.r_px), 1e-4)},
         {"r_arcmin", round(presentation.Arcmin(b.r_px), 1e-4)},
         {"size_deg", round(display::ArcminOfScreenPx(profile, ExtentPx(outline)) / 60, 1e-4)}});
  }
  return frame;
}

std::optional<calib::SceneCalib> LoadProtocolScene(const protocol::Protocol& protocol) {
  if (protocol.scene.calib.empty()) {
    if (protocol.content.type == "picture") return std::nullopt;
    throw InputError(At(protocol, "/scene/calib"), "a " + protocol.content.type + " needs a calibration");
  }
  try {
    return calib::LoadSceneCalib(protocol.scene.calib);
  } catch (const std::exception& e) {
    throw InputError(At(protocol, "/scene/calib"), std::string("not a calibration from blurcue calibrate: ") + e.what());
  }
}

namespace {

// Reads the image a field names, as 8-bit with 1, 3 or 4 channels; every failure is an input error naming the
// protocol field first. `max_aspect`: how much wider than tall (or taller than wide) its use can show it.
cv::Mat ReadFieldImage(const protocol::Protocol& protocol, const std::string& pointer, const std::filesystem::path& path,
                       int flags, double max_aspect, int max_side_px) {
  cv::Mat image;
  try {
    image = ReadImage(path, flags);
    if (image.depth() == CV_16U) image.convertTo(image, CV_8U, 1 / 257.0);
    else if (image.depth() == CV_32F || image.depth() == CV_64F) image.convertTo(image, CV_8U, 255);
  } catch (const std::exception& e) {  // Error, cv::Exception, std::filesystem::filesystem_error
    throw InputError(At(protocol, pointer), e.what());
  }
  const int w = image.cols, h = image.rows;
  if (image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3 && image.channels() != 4))
    throw InputError(At(protocol, pointer), path.string() + ": an image must be 8 or 16 bit grey, colour or colour "
                                                            "with alpha");
  if (w < 2 || h < 2 || w > max_side_px || h > max_side_px || w > max_aspect * h || h > max_aspect * w)
    throw InputError(At(protocol, pointer), path.string() + ": is " + std::to_string(w) + " x " + std::to_string(h) +
                                                " px; it must be 2 to " + std::to_string(max_side_px) +
                                                " px a side and at most " + std::to_string(int(max_aspect)) +
                                                " times as wide as tall or as tall as wide");
  return image;
}

// Photos up to 16384 px a side (more than a 45 MP camera's 8256); a ball's or card's texture needs far less than
// 8192.
constexpr int kMaxPhotoSidePx = 16384, kMaxTextureSidePx = 8192;

}  // namespace

StimulusImages LoadStimulusImages(const protocol::Protocol& protocol, const std::optional<calib::SceneCalib>& scene) {
  StimulusImages images;
  // A depth matching with real photos shows no scene photo (the protocol has no scene).
  const bool board_free = protocol.scene.ShowsBoardFree();
  const std::string photo_field = board_free ? "/scene/board_free" : "/scene/background";
  const auto& photo_path = protocol.scene.ShownPhoto();
  if (protocol.content.type != "picture" || protocol.content.real_photos.empty()) {
    images.photo = ReadFieldImage(protocol, photo_field, photo_path, 1, 10, kMaxPhotoSidePx);
    // The photo not shown is still a photo of the scene: check it decodes too.
    if (!protocol.scene.board_free.empty() && !board_free)
      ReadFieldImage(protocol, "/scene/board_free", protocol.scene.board_free, 1, 10, kMaxPhotoSidePx);
    if (board_free) ReadFieldImage(protocol, "/scene/background", protocol.scene.background, 1, 10, kMaxPhotoSidePx);
  }
  if (protocol.content.type == "picture") {
    images.picture = ReadFieldImage(protocol, "/content/image",
                                    protocol.content.image.empty() ? render::ResolveStimulus("face")
                                                                   : protocol.content.image,
                                    -1, 10, kMaxPhotoSidePx);
    return images;
  }
  if (!scene) throw InputError(At(protocol, "/scene/calib"), "a " + protocol.content.type + " needs a calibration");
  // The objects are drawn in the calibrated camera's view of this photo.
  try {
    scene->RequireSameSize(images.photo, photo_path.string());
  } catch (const std::exception& e) {
    throw InputError(At(protocol, photo_field), std::string(e.what()) + " (the calibration " +
                                                    protocol.scene.calib.string() + " is of another photo)");
  }
  const std::string& name = protocol.content.texture;
  const bool shipped = name == "grid" || name == "soccer" || name == "wood";
  std::filesystem::path texture;
  try {
    texture = render::ResolveStimulus(name);
  } catch (const std::exception& e) {
    throw InputError(At(protocol, shipped ? "/content/type" : "/content/texture"), e.what());
  }
  images.texture = ReadFieldImage(protocol, shipped ? "/content/type" : "/content/texture", texture, -1, 64,
                                  kMaxTextureSidePx);
  // A grid card of another count of cells than the shipped 5 x 5 is drawn here, at the shipped card's resolution.
  if (name == "grid" && protocol.content.cells != 5)
    images.texture = render::GridBoard(images.texture.cols, protocol.content.cells);
  // An image on a card of a given size: its pixels keep their shape, or the card says another.
  if (protocol.content.type == "grid" && !shipped) {
    const protocol::Content& c = protocol.content;
    const double w = c.size_mm > 0 ? c.size_mm : 2 * scene->board.square_mm, h = c.card_height_mm > 0 ? c.card_height_mm : w;
    const double image = double(images.texture.rows) / images.texture.cols;
    if (std::abs(h / w - image) > 0.02 * image)
    {
      auto mm = [](double v) {
        char text[32];
        std::snprintf(text, sizeof text, "%g", v);
        return std::string(text);
      };
      throw InputError(At(protocol, "/content/size_mm"),
                       "a card of " + mm(w) + " x " + mm(h) + " mm would stretch the " +
                           std::to_string(images.texture.cols) + " x " + std::to_string(images.texture.rows) +
                           " px texture; give \"size_mm\": [width, height] in its proportions (height = " +
                           mm(std::round(w * image * 10) / 10) + " mm at this width)");
    }
  }
  return images;
}

void CheckRealPhotos(const protocol::Protocol& protocol, const std::vector<TrialScene>& scenes,
                     std::set<double>* checked) {
  if (protocol.content.real_photos.empty()) return;
  for (const TrialScene& scene : scenes)
    if (scene.content == "picture" && checked->insert(scene.distance_m).second) {
      const cv::Mat photo = ReadFieldImage(protocol, "/content/real_photos",
                                           protocol::RealPhotoFor(protocol.content, scene.distance_m), 1, 10,
                                           kMaxPhotoSidePx);
      // The real blur is worked out on the camera's whole image: a photo of another shape is not that image.
      if (const auto& camera = protocol.content.real_camera;
          camera && std::abs(double(photo.cols) / photo.rows -
                             double(camera->image_width_px) / camera->image_height_px) >
                        0.01 * camera->image_width_px / camera->image_height_px)
      {
        char sizes[160];
        std::snprintf(sizes, sizeof sizes, "its image is %dx%d px, but the real photo is %dx%d", camera->image_width_px,
                      camera->image_height_px, photo.cols, photo.rows);
        throw InputError(At(protocol, "/content/real_camera/camera"),
                         std::string(sizes) + " (another shape: not a whole photo of that camera): " +
                             protocol::RealPhotoFor(protocol.content, scene.distance_m).string());
      }
    }
}

StimulusRenderer::StimulusRenderer(const protocol::Protocol& protocol, const std::optional<calib::SceneCalib>& scene,
                                   const StimulusImages& images, const Presentation& presentation)
    : protocol_(protocol), scene_(scene), presentation_(presentation) {
  photo_ = images.photo;
  if (protocol.content.type == "picture") {
    picture_ = images.picture;
    // Every adjustment level's low-passed picture up front (~0.1 s each on the CPU): stepping through the levels
    // in a trial then never stalls a frame on a Butterworth filter.
    for (const auto& block : protocol.blocks)
      if (block.adjust)
        for (double level : block.adjust->levels) UpperHalf(level);
    return;
  }
  if (!scene_) scene_ = LoadProtocolScene(protocol);
  texture_ = render::SurfaceTexture(images.texture);
  compositor_ = std::make_unique<render::FrameCompositor>(scene_->camera, scene_->rvec, scene_->tvec, photo_,
                                                          presentation.view);
}

StimulusRenderer::~StimulusRenderer() = default;

const cv::Mat& StimulusRenderer::UpperHalf(double level) {
  auto cached = std::find_if(upper_cache_.begin(), upper_cache_.end(),
                             [&](const auto& entry) { return entry.first == level; });
  if (cached != upper_cache_.end()) return cached->second;
  const render::DepthMatchingLayout& l = presentation_.layout;
  upper_cache_.emplace_back(level, render::PictureOnGrey(picture_, l.upper.size(), l.picture.height, level));
  return upper_cache_.back().second;
}

cv::Size StimulusRenderer::FrameSize() const {
  if (compositor_) return {presentation_.window_width_px, presentation_.window_height_px};
  return presentation_.layout.frame;
}

render::FrameView StimulusRenderer::View() const {
  return compositor_ ? compositor_->view() : presentation_.view;
}

void StimulusRenderer::Prepare(const TrialScene& trial) {
  if (!compositor_) {
    const double distance_m = protocol_.content.real_photos.empty() ? 0 : trial.distance_m;
    if (lower_.empty() || distance_m != lower_distance_m_) {
      const cv::Mat photo = protocol_.content.real_photos.empty()
                                ? photo_
                                : ReadImage(protocol::RealPhotoFor(protocol_.content, trial.distance_m), 1);
      lower_ = presentation_.layout.LowerHalf(photo);
      lower_distance_m_ = distance_m;
    }
    return;
  }
  const render::FrameView v = presentation_.ViewFor(protocol_, *scene_, trial);
  compositor_->Place(v.x_px, v.y_px);  // redraws the base only when the place changed
}

void StimulusRenderer::Compose(const TrialScene& trial, double t_s, double level) {
  if (t_s <= 0) Prepare(trial);  // a trial's first frame: nothing to do when the runner prepared it
  if (!compositor_) {
    render::StackDepthMatchingFrame(UpperHalf(level), lower_, &picture_frame_);
    picture_stale_ = true;
    return;
  }
  shown_ = ObjectsAt(protocol_, *scene_, trial, t_s);
  objects_.clear();  // kept between frames: its storage is reused
  for (auto& shown : shown_) {
    if (!shown) continue;
    shown->object.texture = texture_;
    objects_.push_back(*shown);
  }
  compositor_->Compose(objects_);
}

void StimulusRenderer::Present(int width_px, int height_px) {
  if (compositor_) {
    compositor_->Present(width_px, height_px);
    return;
  }
  if (!picture_shown_) picture_shown_ = std::make_unique<render::WindowImage>(picture_frame_);
  else if (picture_stale_) picture_shown_->Update(picture_frame_);
  picture_stale_ = false;
  picture_shown_->Present(width_px, height_px);
}

void StimulusRenderer::Finish() {
  if (compositor_) compositor_->Finish();
}

cv::Mat StimulusRenderer::Read() {
  if (compositor_) return compositor_->Read();
  // The picture's frame where the window shows it, on the grey field.
  const render::FrameView& v = presentation_.view;
  cv::Mat window(v.height_px, v.width_px, CV_8UC3, cv::Scalar::all(128));
  cv::Mat bgr = picture_frame_;
  if (bgr.channels() == 4) cv::cvtColor(bgr, bgr, cv::COLOR_BGRA2BGR);
  else if (bgr.channels() == 1) cv::cvtColor(bgr, bgr, cv::COLOR_GRAY2BGR);
  bgr.copyTo(window(cv::Rect(v.x_px, v.y_px, bgr.cols, bgr.rows)));
  return window;
}

}  // namespace blurcue::session
