#include "stimulus/stimulus.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <vector>

#include <opencv2/calib3d.hpp>

#include "core/error.h"
#include "scene/objects.h"
#include "stimulus/internal.h"

namespace blurcue::stimulus {
namespace {

constexpr int kLeftSection = 3, kRightSection = 5;  // the balls roll side by side, one section apart

using protocol::FindLevel;
using protocol::Side;

// `where` names the field that chose the source ("FILE: /pointer"), made only when there is a problem to name. A
// fixed radius on the screen is converted to photo px by `presentation`.
// The side's blur source as the calibration evaluates it (one vocabulary, core/blur_source.h), with a fixed radius in
// photo px.
BlurSource Source(const std::optional<protocol::BlurSpec>& spec, double* fixed,
                  const std::function<std::string()>& where, const Presentation* presentation) {
  if (!spec) throw InputError(where(), "the trial shows no blur source on this side, got null");
  if (spec->source != BlurSource::kFixed) return spec->source;
  const double r = spec->radius.number;
  switch (spec->unit) {
    case protocol::RadiusUnit::kPhotoPx: *fixed = r; break;
    case protocol::RadiusUnit::kScreenPx:
    case protocol::RadiusUnit::kArcmin:
      if (!presentation || presentation->scale <= 0)
        throw InputError(where(), "a radius on the screen needs the display it is shown on, got " +
                                      protocol::ToJson(spec).dump());
      *fixed = (spec->unit == protocol::RadiusUnit::kArcmin ? display::ScreenPxOfArcmin(presentation->profile, r) : r) /
               presentation->scale;
      break;
  }
  return BlurSource::kFixed;
}

// Board-frame placement of the two objects of a pair (scene's poses on the board; x and y in mm where the trial
// says so).
// `place` is the side whose place the object takes (in an intervals trial the right side's object takes the left's).
scene::VirtualObject Card(const calib::SceneCalib& s, const TrialScene& t, Side place) {
  scene::VirtualObject o = scene::CardBesideBoard(s.board, 1, place == Side::kLeft, t.card_width_mm);
  o.card_height_mm = t.card_height_mm;
  o.standing = t.standing;
  o.rotation_deg = t.rotation_deg;
  const double x = t.side(place).x_mm;
  // Its centre at the placement; a standing card's lowest edge rests at height_mm above the table.
  const double h = o.card_height_mm > 0 ? o.card_height_mm : o.size_mm;
  o.center_board_mm = {std::isnan(x) ? o.center_board_mm[0] : x, t.from_y_mm, t.height_mm + (t.standing ? h / 2 : 0)};
  return o;
}
scene::VirtualObject Ball(const calib::SceneCalib& s, const TrialScene& t, double y_mm, double radius_mm, Side place) {
  scene::VirtualObject o =
      scene::BallOnBoard(s.board, place == Side::kLeft ? kLeftSection : kRightSection, y_mm, radius_mm, t.from_y_mm);
  const double x = t.side(place).x_mm;
  if (!std::isnan(x)) o.center_board_mm[0] = x;
  o.center_board_mm[2] += t.height_mm;
  return o;
}

// The streak a ball centred at y_mm leaves over the trial's exposure while it rolls (photo px): where its centre's
// image goes from half an exposure before to half after, through the calibrated camera (its distortion included).
cv::Vec2d StreakAtPx(const calib::SceneCalib& s, const TrialScene& t, double y_mm, double radius_mm, Side place) {
  if (!(t.exposure_ms > 0 && t.speed_mm_s > 0)) return {0, 0};
  const double half = 0.5 * t.speed_mm_s * t.exposure_ms / 1000 * (t.to_y_mm >= t.from_y_mm ? 1 : -1);
  std::vector<cv::Point3d> ends = {cv::Point3d(Ball(s, t, y_mm - half, radius_mm, place).center_board_mm),
                                   cv::Point3d(Ball(s, t, y_mm + half, radius_mm, place).center_board_mm)};
  std::vector<cv::Point2d> image;
  cv::projectPoints(ends, s.rvec, s.tvec, cv::Matx33d(s.camera.Intrinsics().data()), s.camera.dist_coeffs, image);
  return {image[1].x - image[0].x, image[1].y - image[0].y};
}

// An object's centre at board_mm: its depth u (camera z, mm) and its image's place below the principal point (photo
// px, down positive), through the calibrated camera (its distortion included) - where the record says it is.
struct ObjectPlace {
  double u_mm = 0, below_axis_px = 0;
};
ObjectPlace PlaceOf(const calib::SceneCalib& s, const cv::Vec3d& board_mm) {
  std::vector<cv::Point2d> image;
  const std::array<double, 9> k = s.camera.Intrinsics();
  cv::projectPoints(std::vector<cv::Point3d>{cv::Point3d(board_mm)}, s.rvec, s.tvec, cv::Matx33d(k.data()),
                    s.camera.dist_coeffs, image);
  return {s.ToCamera(board_mm)[2], image[0].y - k[5]};
}

// The protocol's kernel as the renderer names its blur method: the one place the two vocabularies meet (render knows
// nothing of protocols).
std::string RenderMethod(protocol::Kernel kernel) {
  switch (kernel) {
    case protocol::Kernel::kGaussian: return "gaussian";
    case protocol::Kernel::kDisc: return "disc";
  }
  return "gaussian";
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

// A placement must show: each object, at the start and at the end of its run, must land in the photo.
void CheckInPhoto(const protocol::Protocol& protocol, const protocol::Trial& trial, const calib::SceneCalib& scene,
                  const TrialScene& t) {
  const cv::Rect photo(0, 0, scene.camera.image_width_px, scene.camera.image_height_px);
  for (const auto& objects : RunEnds(protocol, scene, t)) {
    for (const Side side : protocol::Vocabulary<Side>::values) {
      const auto& object = objects[protocol::Index(side)];
      // An intervals trial shows the right side's object at the left's place (IntervalScene): the left's check is its.
      if (!object || (side == Side::kRight && t.intervals > 0)) continue;
      if ((scene::FootprintOf(scene.camera, scene.rvec, scene.tvec, object->object).bounds & photo).empty()) {
        // The level that placed it: its side's x (left_x_mm, right_x_mm), else the edge.
        const std::string level = t.content == protocol::ContentType::kGrid
                                      ? (std::isnan(t.side(side).x_mm) ? "edge" : ToString(side) + "_x_mm")
                                      : "speed_cm_s";
        throw InputError(protocol.file.string() + ": " + protocol::LevelPointer(protocol, trial, level),
                         "the " + ToString(side) + " " + ToString(t.content) + " at (" +
                             std::to_string(int(std::lround(object->object.center_board_mm[0]))) + ", " +
                             std::to_string(int(std::lround(object->object.center_board_mm[1]))) +
                             ") mm on the board lies outside the " + std::to_string(photo.width) + " x " +
                             std::to_string(photo.height) + " photo (trial " + std::to_string(trial.index) + ")");
      }
    }
  }
}

}  // namespace

namespace {

// The real picture's blur (depth matching): the thin lens of the camera that took its photo (content.real_camera).
void DescribePicture(const protocol::Protocol& protocol, const protocol::Trial& trial, const std::string& trial_text,
                     TrialScene* t) {
  const protocol::LevelValue* d = FindLevel(trial.levels, "distance_m");
  t->distance_m = d && d->IsNumber() ? d->number : 1.0;
  if (const auto& camera = protocol.content.real_camera) {
    try {
      t->r_scene_px = optics::BlurRadiusPx(optics::Lens::FromCamera(*camera), protocol.content.real_focus_m * 1000,
                                           t->distance_m * 1000);
      // As synth-pictures refuses to make such a photo: a blur past any kernel is a wrong focus or camera.
      if (!(t->r_scene_px <= optics::kMaxBlurRadiusPx))
        throw Error(ErrorKind::kDomain, "the real picture at " + protocol::LevelText(t->distance_m) +
                                            " m would be blurred by " + std::to_string(std::lround(t->r_scene_px)) +
                                            " px, more than the largest blur (" +
                                            std::to_string(int(optics::kMaxBlurRadiusPx)) + " px)");
    } catch (const Error& e) {
      throw InputError(At(protocol, "/content/real_camera"), std::string(e.what()) + trial_text);
    }
  }
}

// A pair trial being described over its calibrated scene: its levels read as the board and millimetres they stand
// for, radii evaluated there, and problems named by the protocol field that asked for what cannot be shown, with the
// trial as a detail.
struct PairDescription {
  const protocol::Protocol& protocol;
  const protocol::Trial& trial;
  const calib::SceneCalib& scene;
  std::string trial_text;

  // Where a side's source was chosen (for the scene's own blur, the calibration): looked up only for a message.
  std::string Field(std::optional<Side> side) const {
    return At(protocol, side ? protocol::SidePointer(protocol, trial, *side) : "/scene/calib");
  }
  // The radius of `source` at board_mm (photo px). One that cannot be evaluated (eq. 3.7 nearer than focus, no usable
  // measured section) is a problem of the source the protocol chose with this calibration: an input error naming
  // that field.
  double RadiusAt(const cv::Vec3d& board_mm, calib::BlurSource source, double fixed, std::optional<Side> side) const {
    try {
      const double r = calib::BlurAtPx(scene, source, scene.ToCamera(board_mm), fixed);
      if (!std::isfinite(r) || r < 0) throw Error(ErrorKind::kDomain, "radius " + std::to_string(r) + " px");
      return r;
    } catch (const Error& e) {
      // An object placed at or behind the lens (a card raised 1 m over a table the camera looks down on) is the
      // placement's problem, not the blur source's.
      const double u_mm = scene.ToCamera(board_mm)[2];
      if (!(u_mm > scene.camera.focal_length_mm))
        throw InputError(PlacementField(), HeightText() + "places the " + protocol::ToString(protocol.content.type) +
                                               " at u = " + Num(u_mm) + " mm from the lens (f = " +
                                               Num(scene.camera.focal_length_mm) + " mm): " +
                                               (u_mm <= 0 ? "behind the camera" : "nearer than its focal length") +
                                               ", where no blur exists" + trial_text);
      throw InputError(Field(side), ToString(source) + " blur cannot be evaluated with " +
                                        protocol.scene.calib.string() + trial_text + ": " + e.what());
    }
  }
  // "is 1000 mm: " when the object's height placed it (PlacementField names a height), else "".
  std::string HeightText() const {
    const std::optional<double> level = NumberLevel("height_mm");
    if (!level && protocol.content.height_mm == 0) return "";
    return "is " + Num(level.value_or(protocol.content.height_mm)) + " mm: ";
  }
  // The field that placed the object: its height (a level, or content.height_mm), else the level that put it along
  // the board; looked up only for a message.
  std::string PlacementField() const {
    if (NumberLevel("height_mm")) return At(protocol, protocol::LevelPointer(protocol, trial, "height_mm"));
    if (protocol.content.height_mm != 0) return At(protocol, "/content/height_mm");
    for (const char* name : {"left_x_mm", "right_x_mm", "y_mm", "edge"})
      if (FindLevel(trial.levels, name)) return At(protocol, protocol::LevelPointer(protocol, trial, name));
    return At(protocol, "/content");
  }
  // Edges and sections are the calibrated board's: its own count, whatever its size.
  int Edges() const { return scene.board.EdgeCount(); }
  // An integer level `name` naming an edge or a section (1..most) of the calibrated board; none when not an integer.
  std::optional<int> BoardLevel(const char* name, int most) const {
    const protocol::LevelValue* v = FindLevel(trial.levels, name);
    if (!v || v->kind != protocol::LevelValue::Kind::kInteger) return std::nullopt;
    if (!(v->number >= 1 && v->number <= most))
      throw InputError(At(protocol, protocol::LevelPointer(protocol, trial, name)),
                       std::string(name) + " " + v->text + " is not on the calibrated board (" +
                           protocol::BoardLevelsText(scene.board.cols, scene.board.rows) + ")" + trial_text);
    return int(v->number);
  }
  // A number level `name` (mm, deg), none when the trial has no such number.
  std::optional<double> NumberLevel(const std::string& name) const {
    const protocol::LevelValue* v = FindLevel(trial.levels, name);
    return v && v->IsNumber() ? std::optional<double>(v->number) : std::nullopt;
  }
};

// Where each side's object is shown, so where its radius is evaluated: its own place, but the right side's in an
// intervals trial at the left object's (IntervalScene shows each side alone there). Evaluated at its own place, a
// place-dependent source (measured_section, estimated, fitted) gave the right interval a radius of somewhere not shown.
std::array<Side, 2> PlacesOf(const TrialScene& t) {
  return {Side::kLeft, t.intervals > 0 ? Side::kLeft : Side::kRight};
}

// Two grid cards at an edge (or y_mm): each side's radius, floor and place at its card's centre.
void DescribeGrid(const PairDescription& pair, TrialScene* t) {
  const auto edge = pair.BoardLevel("edge", pair.Edges());
  const auto y = pair.NumberLevel("y_mm");
  if (!edge && !y)
    throw InputError(At(pair.protocol, protocol::LevelPointer(pair.protocol, pair.trial, "edge")),
                     "a grid needs an integer level edge or a y_mm" + pair.trial_text);
  t->edge = edge ? *edge : 0;
  t->from_y_mm = t->to_y_mm = y ? *y : (*edge - 1) * pair.scene.board.square_mm;
  const std::array<Side, 2> place_of = PlacesOf(*t);
  std::array<cv::Vec3d, 2> at;  // each card's centre (board mm)
  for (size_t k = 0; k < 2; ++k) at[k] = Card(pair.scene, *t, place_of[k]).center_board_mm;
  for (const Side side : protocol::Vocabulary<Side>::values) {
    SideShown& shown = t->side(side);
    shown.r_px = pair.RadiusAt(at[protocol::Index(side)], shown.source, shown.fixed_px, side);
  }
  for (const Side side : protocol::Vocabulary<Side>::values) {
    SideShown& shown = t->side(side);
    const ObjectPlace place = PlaceOf(pair.scene, at[protocol::Index(side)]);
    shown.u_mm = place.u_mm, shown.below_axis_px = place.below_axis_px;
    // The floor at the card's place (the distortion's stretch there; ObjectsAt draws the same).
    shown.floor_sigma_px = calib::FloorSigmaPx(pair.scene, shown.source, pair.scene.ToCamera(at[protocol::Index(side)]));
  }
  t->r_scene_px = 0.5 * (pair.RadiusAt(at[0], calib::BlurSource::kFitted, 0, std::nullopt) +
                         pair.RadiusAt(at[1], calib::BlurSource::kFitted, 0, std::nullopt));
}

// Balls: their run from the levels - a section run (edge s to s + 1, wiped on arrival), explicit edges, the whole
// board, or at rest at an edge. A ball without a speed rests where it starts, and its radii are those of that place,
// not of a run.
void DescribeBallRun(const PairDescription& pair, TrialScene* t) {
  const protocol::Trial& trial = pair.trial;
  const double s = pair.scene.board.square_mm;
  const int edges = pair.Edges();
  int from = 1, to = edges;
  const protocol::LevelValue* speed = FindLevel(trial.levels, "speed_cm_s");
  t->speed_mm_s = speed && speed->IsNumber() ? 10 * speed->number : 0;
  const auto edge = pair.BoardLevel("edge", edges);
  const auto rest_y = pair.NumberLevel("y_mm");
  if (edge || rest_y) {
    if (t->speed_mm_s > 0 || FindLevel(trial.levels, "section") || FindLevel(trial.levels, "from_edge") ||
        FindLevel(trial.levels, "to_edge") || FindLevel(trial.levels, "from_y_mm") ||
        FindLevel(trial.levels, "to_y_mm") || (edge && rest_y))
      throw InputError(At(pair.protocol, protocol::LevelPointer(pair.protocol, trial, edge ? "edge" : "y_mm")),
                       "a ball at an edge (or y_mm) rests there: it takes no speed_cm_s, section, from/to edge or "
                       "y_mm, and not both edge and y_mm" + pair.trial_text);
    if (edge) from = to = *edge;
  } else if (const auto section = pair.BoardLevel("section", edges - 1)) {
    from = *section;
    to = from + 1;
    t->wipe_at_end = true;
  } else {
    if (const auto f = pair.BoardLevel("from_edge", edges)) from = *f;
    if (const auto e = pair.BoardLevel("to_edge", edges)) to = *e;
  }
  // Without a speed the ball rests where it starts: an end or a section it would run to is never shown (it would be
  // recorded all the same).
  if (t->speed_mm_s <= 0)
    for (const char* run_level : {"section", "to_edge", "to_y_mm"})
      if (FindLevel(trial.levels, run_level))
        throw InputError(At(pair.protocol, protocol::LevelPointer(pair.protocol, trial, run_level)),
                         std::string("a ball without a speed_cm_s rests where it starts: ") + run_level +
                             " describes a run it never makes (give a speed, or place it with edge, y_mm or "
                             "from_edge)" + pair.trial_text);
  t->from_y_mm = rest_y ? *rest_y : pair.NumberLevel("from_y_mm").value_or((from - 1) * s);
  t->to_y_mm = rest_y ? *rest_y : pair.NumberLevel("to_y_mm").value_or((to - 1) * s);
  if (t->speed_mm_s <= 0) t->to_y_mm = t->from_y_mm;
}

// Each side's radius, floor, place and streak averaged over the balls' run (what the observer sees on the whole),
// sampled evenly along it; every edge the run passes is evaluated too.
void AverageOverBallRun(const PairDescription& pair, TrialScene* t) {
  const calib::SceneCalib& scene = pair.scene;
  const std::array<Side, 2> place_of = PlacesOf(*t);
  const int samples = 21;
  const double radius = pair.protocol.content.radius_mm;
  for (int i = 0; i < samples; ++i) {
    const double y = t->from_y_mm + (t->to_y_mm - t->from_y_mm) * i / (samples - 1);
    std::array<cv::Vec3d, 2> at;  // each ball's centre (board mm)
    for (size_t k = 0; k < 2; ++k) at[k] = Ball(scene, *t, y, radius, place_of[k]).center_board_mm;
    for (const Side side : protocol::Vocabulary<Side>::values) {
      SideShown& shown = t->side(side);
      shown.r_px += pair.RadiusAt(at[protocol::Index(side)], shown.source, shown.fixed_px, side) / samples;
    }
    for (const Side side : protocol::Vocabulary<Side>::values) {
      SideShown& shown = t->side(side);
      shown.floor_sigma_px += calib::FloorSigmaPx(scene, shown.source, scene.ToCamera(at[protocol::Index(side)])) /
                              samples;
    }
    t->r_scene_px += 0.5 * (pair.RadiusAt(at[0], calib::BlurSource::kFitted, 0, std::nullopt) +
                            pair.RadiusAt(at[1], calib::BlurSource::kFitted, 0, std::nullopt)) / samples;
    for (const Side side : protocol::Vocabulary<Side>::values) {
      SideShown& shown = t->side(side);
      const ObjectPlace place = PlaceOf(scene, at[protocol::Index(side)]);
      shown.u_mm += place.u_mm / samples;
      shown.below_axis_px += place.below_axis_px / samples;
      shown.motion_px += StreakAtPx(scene, *t, y, radius, place_of[protocol::Index(side)]) / samples;
    }
  }
  // Every edge the run passes, too: the samples step over edges on a long board, and a frame there must have a
  // radius (a measured source is its nearest edge's value, refused for an edge with no usable section).
  for (int k = 1; k <= pair.Edges(); ++k) {
    const double y = (k - 1) * scene.board.square_mm;
    if (y < std::min(t->from_y_mm, t->to_y_mm) || y > std::max(t->from_y_mm, t->to_y_mm)) continue;
    for (const Side side : protocol::Vocabulary<Side>::values) {
      const SideShown& shown = t->side(side);
      pair.RadiusAt(Ball(scene, *t, y, radius, place_of[protocol::Index(side)]).center_board_mm, shown.source,
                    shown.fixed_px, side);
    }
  }
}

}  // namespace

TrialScene DescribeTrial(const protocol::Protocol& protocol, const protocol::Trial& trial,
                         const calib::SceneCalib* scene, const Presentation* presentation) {
  TrialScene t;
  t.content = protocol.content.type;
  t.left_only = protocol.layout == protocol::Layout::kSingle;
  t.intervals = protocol::IntervalCount(protocol);
  t.kernel = protocol.content.kernel;
  t.brightness = protocol.content.brightness;
  t.exposure_ms = protocol.content.exposure_ms;
  t.video = protocol.scene.IsVideo();
  t.contrast = protocol.content.contrast;
  t.white_balance = protocol.content.white_balance;
  // Problems name the protocol field that asked for what cannot be shown, and the trial as a detail.
  const std::string trial_text = " (trial " + std::to_string(trial.index) + ", block " + trial.block + ")";
  if (t.content == protocol::ContentType::kPicture) {
    DescribePicture(protocol, trial, trial_text, &t);
    return t;
  }
  if (!scene) throw InputError(protocol.file.string(), "/scene/calib: a " + protocol::ToString(t.content) + " needs a calibration");
  const PairDescription pair{protocol, trial, *scene, trial_text};
  for (const Side side : protocol::Vocabulary<Side>::values) {
    SideShown& shown = t.side(side);
    shown.source = Source(side == Side::kLeft ? trial.left : trial.right, &shown.fixed_px,
                          [&] { return pair.Field(side); }, presentation);
  }
  for (const Side side : protocol::Vocabulary<Side>::values)
    if (auto x = pair.NumberLevel(ToString(side) + "_x_mm")) t.side(side).x_mm = *x;
  t.height_mm = pair.NumberLevel("height_mm").value_or(protocol.content.height_mm);
  if (t.content == protocol::ContentType::kGrid) {
    t.card_width_mm = protocol.content.size_mm;
    t.card_height_mm = protocol.content.card_height_mm;
    t.standing = protocol.content.standing;
    t.rotation_deg = pair.NumberLevel("rotation_deg").value_or(protocol.content.rotation_deg);
    DescribeGrid(pair, &t);
  } else {
    DescribeBallRun(pair, &t);
    AverageOverBallRun(pair, &t);
  }
  CheckInPhoto(protocol, trial, *scene, t);
  return t;
}

std::array<std::optional<scene::BlurredObject>, 2> ObjectsAt(const protocol::Protocol& protocol,
                                                              const calib::SceneCalib& s, const TrialScene& trial,
                                                              double t_s) {
  std::array<std::optional<scene::BlurredObject>, 2> shown;
  for (const Side side : protocol::Vocabulary<Side>::values) {
    if (side == Side::kRight && trial.left_only) continue;
    scene::BlurredObject b;
    scene::VirtualObject& o = b.object;
    const SideShown& shown_side = trial.side(side);
    const calib::BlurSource source = shown_side.source;
    const double fixed = shown_side.fixed_px, gain = shown_side.gain, add = shown_side.add_px;
    if (trial.content == protocol::ContentType::kGrid) {
      o = Card(s, trial, side);
    } else {
      const double y = trial.BallYMm(t_s);
      if (!std::isfinite(y)) continue;  // wiped at the end of a section
      o = Ball(s, trial, y, protocol.content.radius_mm, side);
      // Rolling (onset to arrival): the streak of its velocity there over the exposure; at rest, none.
      if (t_s >= 0 && t_s < trial.MotionS()) b.motion_px = StreakAtPx(s, trial, y, protocol.content.radius_mm, side);
    }
    // The scene's floor and stretch at the object's place: its PSF is the photo's there (docs/distortion.md).
    b.floor_sigma_px = calib::FloorSigmaPx(s, source, s.ToCamera(o.center_board_mm));
    b.shape = calib::ShapeAt(s, source, s.ToCamera(o.center_board_mm));
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
    b.method = RenderMethod(trial.kernel);
    b.r_px = gain * calib::BlurAtPx(s, source, s.ToCamera(o.center_board_mm), fixed) + add;
    shown[protocol::Index(side)] = std::move(b);
  }
  return shown;
}
bool IntervalShowsRight(const protocol::Trial& trial, const TrialScene& scene, int i) {
  if (scene.intervals == 2) return i == 1;
  return protocol::TraitsOf(trial.task).answer == protocol::TaskAnswer::kSide && protocol::TestInterval(trial) == i + 1;
}

TrialScene IntervalScene(const TrialScene& scene, bool right) {
  TrialScene s = scene;
  s.left_only = true;
  if (right) {
    // The right side's object at the left's place: the left's x (its place), the right's all else.
    const double x_mm = s.side(Side::kLeft).x_mm;
    const double size_deg = s.side(Side::kLeft).size_deg;
    s.side(Side::kLeft) = s.side(Side::kRight);
    s.side(Side::kLeft).x_mm = x_mm;
    s.side(Side::kLeft).size_deg = size_deg;
  }
  return s;
}

void ApplyLevel(const protocol::Procedure& procedure, const protocol::Trial& trial, double level,
                const Presentation& presentation, TrialScene* scene) {
  SideShown& test = scene->side(protocol::TestSide(trial).value_or(Side::kRight));
  double& gain = test.gain;
  double& add = test.add_px;
  double& r = test.r_px;
  const double reference = (r - add) / gain;  // as DescribeTrial made it
  if (procedure.variable == protocol::ProcedureVariable::kRelativeDifference) {
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
  if (trial->content == protocol::ContentType::kPicture) return;
  const protocol::Content& c = protocol.content;
  const double threshold = c.depth_blur_threshold_unit == protocol::ThresholdUnit::kArcmin
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
      const scene::Footprint f = scene::FootprintOf(s.camera, s.rvec, s.tvec, object->object);
      span = std::max(span, presentation.ScreenPx(std::abs(object->r_of_depth_px(f.z_max_mm) -
                                                           object->r_of_depth_px(f.z_min_mm))));
    }
  trial->r_span_screen_px = span;
  trial->per_pixel = span >= threshold;
  const auto& onset = ends[0];
  for (size_t side = 0; side < 2; ++side)
    trial->sides[side].size_deg =
        onset[side] ? display::ArcminOfScreenPx(presentation.profile,
                                                presentation.ScreenPx(ExtentPx(scene::OutlineOf(
                                                    s.camera, s.rvec, s.tvec, onset[side]->object)))) /
                          60
                    : 0;
}


void CheckBlurOnScreen(const protocol::Protocol& protocol, const protocol::Trial& trial, const calib::SceneCalib& s,
                       const Presentation& presentation, const TrialScene& scene, const std::string& level_pointer,
                       const std::string& level_text) {
  if (scene.content == protocol::ContentType::kPicture) return;
  const double most = optics::kMaxBlurRadiusPx;
  const std::string trial_text = " (trial " + std::to_string(trial.index) + ", block " + trial.block + ")";
  const std::string largest = ", more than the largest blur drawn (" + Num(most) + " px)";
  // The per-pixel plan's objects: each one's radius at its nearest and farthest depth is what some pixel of it gets.
  TrialScene as_per_pixel = scene;
  as_per_pixel.per_pixel = true;
  for (const auto& objects : RunEnds(protocol, s, as_per_pixel))
    for (const Side side : protocol::Vocabulary<Side>::values) {
      const auto& object = objects[protocol::Index(side)];
      if (!object) continue;
      const scene::Footprint f = scene::FootprintOf(s.camera, s.rvec, s.tvec, object->object);
      const double r_px =
          std::max({object->r_px, object->r_of_depth_px(f.z_min_mm), object->r_of_depth_px(f.z_max_mm)});
      const double r = presentation.ScreenPx(r_px), streak = presentation.ScreenPx(cv::norm(object->motion_px));
      const std::string what = "the " + ToString(side) + " " + protocol::ToString(scene.content);
      const std::string scale = " (" + Num(presentation.scale) + " screen px per photo px)";
      const std::string radius = Num(r_px) + " photo px, " + Num(r) + " px on the screen" + scale + largest;
      if (!(r <= most) && level_text.empty())
        throw InputError(At(protocol, protocol::SidePointer(protocol, trial, side)),
                         what + " would be blurred by " + radius + trial_text);
      if (!(r <= most))  // the test side's, whichever it is
        throw InputError(At(protocol, level_pointer),
                         "at " + level_text + ", a radius of " + radius + ", for " + what + trial_text);
      if (!(streak <= most))
        throw InputError(At(protocol, "/content/exposure_ms"),
                         "is " + Num(scene.exposure_ms) + " ms: " + what + " rolling at " + Num(scene.speed_mm_s / 10) +
                             " cm/s would be streaked over " + Num(streak) + " px on the screen" + scale + largest +
                             trial_text);
    }
}

}  // namespace blurcue::stimulus
