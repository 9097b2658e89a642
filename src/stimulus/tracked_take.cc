#include "stimulus/tracked_take.h"

#include <algorithm>
#include <map>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <sstream>

#include <opencv2/calib3d.hpp>

#include "core/csv.h"
#include "core/error.h"
#include "core/image.h"
#include "core/names.h"
#include "core/typed.h"
#include "optics/thin_lens.h"
#include "scene/stimuli.h"
#include "track/frames.h"
#include "track/take.h"

namespace blurcue::stimulus {
namespace {

constexpr size_t kMaxFrames = 1000000;

// A field of a track.csv row as a number; the error names the file, the line and the column.
double NumberField(const std::string& file, const CsvRecord& row, size_t column, const std::string& name) {
  const std::optional<double> v = column < row.fields.size() ? ParseDecimal(row.fields[column]) : std::nullopt;
  if (!v || !std::isfinite(*v))
    throw InputError(file + ": line " + std::to_string(row.line) + ", " + name,
                     "must be a number, got " + Echo(column < row.fields.size() ? row.fields[column] : ""));
  return *v;
}

track::FrameStatus ParseStatus(const std::string& where, const std::string& text) {
  std::vector<std::string> words;
  for (track::FrameStatus s : {track::FrameStatus::kFound, track::FrameStatus::kTracked, track::FrameStatus::kLost}) {
    if (text == track::Name(s)) return s;
    words.push_back(track::Name(s));
  }
  throw InputError(where, "must be found, tracked or lost, got " + Echo(text) + DidYouMean(text, words));
}

// The image position of a board point at a frame's pose (the calibration's camera and distortion).
cv::Point2d Project(const calib::SceneCalib& c, const cv::Vec3d& board_mm) {
  std::vector<cv::Point3d> points = {cv::Point3d(board_mm)};
  std::vector<cv::Point2d> image;
  cv::projectPoints(points, c.rvec, c.tvec, cv::Matx33d(c.camera.Intrinsics().data()), c.camera.dist_coeffs, image);
  return image[0];
}

// The nearest frame with a pose before (step -1) or after (step +1) `index`; -1 when there is none.
int NeighbourWithPose(const TrackedTake& take, int index, int step) {
  for (int i = index + step; i >= 0 && i < int(take.frames.size()); i += step)
    if (take.frames[size_t(i)].calib) return i;
  return -1;
}

// Two cameras are one when everything that shapes the image is the same.
bool SameCamera(const Camera& a, const Camera& b) {
  return a.image_width_px == b.image_width_px && a.image_height_px == b.image_height_px &&
         a.focal_length_mm == b.focal_length_mm && a.sensor_width_mm == b.sensor_width_mm &&
         a.sensor_height_mm == b.sensor_height_mm && a.f_number == b.f_number && a.Intrinsics() == b.Intrinsics() &&
         a.dist_coeffs == b.dist_coeffs;
}

// A calibration names the frame, time and status track wrote it for, and the frame's signature: each must be the row's.
void CheckCalibIsTheRows(const Json& json, const std::string& path, const TrackedFrame& f, const std::string& time_text) {
  const std::string again = " (track the take again)";
  if (!json.contains("frame") || !json["frame"].is_number_integer() || json["frame"].get<int64_t>() != f.index)
    throw InputError(path + ": /frame", "must be " + std::to_string(f.index) + ", the frame of its row in track.csv, got " +
                                            (json.contains("frame") ? Echo(json["frame"].dump(), false) : "nothing") +
                                            ": a calibration of another frame" + again);
  if (!json.contains("time_s") || !json["time_s"].is_number() ||
      !(std::abs(json["time_s"].get<double>() - f.time_s) <= 2e-6))
    throw InputError(path + ": /time_s", "must be " + time_text + " s, the time of frame " + std::to_string(f.index) +
                                             " in track.csv, got " +
                                             (json.contains("time_s") ? Echo(json["time_s"].dump(), false) : "nothing") +
                                             again);
  if (!json.contains("track_status") || json["track_status"] != track::Name(f.status))
    throw InputError(path + ": /track_status", std::string("must be ") + track::Name(f.status) +
                                                   ", frame " + std::to_string(f.index) + "'s status in track.csv, got " +
                                                   (json.contains("track_status")
                                                        ? Echo(json["track_status"].dump(), false)
                                                        : "nothing") + again);
  const Json* sig = json.contains("frame_signature") ? &json["frame_signature"] : nullptr;
  bool ok = sig && sig->is_array() && sig->size() == 64;
  for (size_t i = 0; ok && i < sig->size(); ++i) ok = (*sig)[i].is_number() && (*sig)[i].get<double>() >= 0 && (*sig)[i].get<double>() <= 255;
  if (!ok)
    throw InputError(path + ": /frame_signature",
                     "must be the frame's 64 grey means (0-255) that blurcue track writes (this calibration was made by an "
                     "older blurcue, or edited)" + again);
}

// A take has one lens model (track/take.h): each frame's calibration states it, and track.csv's row prints it. A
// frame whose model is another (a hand edit: focus 500 mm in a take focused at 339.6) would draw its objects with
// other blur than its neighbours; refused naming the file and the field. `first` is the take's first posed frame's
// calibration (nullptr for that frame itself).
void RequireTakesModel(const calib::SceneCalib& c, const std::string& path, const calib::SceneCalib* first,
                       const std::string& first_name, const std::vector<std::string>& header, const CsvRecord& row) {
  const optics::FittedModel& m = c.model;
  auto differ = [](double a, double b, double tolerance) {
    if (std::isinf(a) || std::isinf(b)) return a != b;
    return !(std::abs(a - b) <= tolerance * std::max(1.0, std::abs(b)));
  };
  if (first) {
    const optics::FittedModel& t = first->model;
    const std::pair<const char*, std::pair<double, double>> fields[] = {{"focus_mm", {m.focus_mm, t.focus_mm}},
                                                                        {"aperture_mm", {m.aperture_mm, t.aperture_mm}},
                                                                        {"floor_px", {m.floor_px, t.floor_px}}};
    for (const auto& [name, v] : fields)
      if (differ(v.first, v.second, 1e-9))
        throw InputError(path + ": /model/" + name, "must be the take's " + Num(v.second) + " (" + first_name +
                                                        "'s: one lens model for the whole take), got " + Num(v.first));
    if (m.kind != t.kind)
      throw InputError(path + ": /model/kind", "must be the take's \"" + t.kind + "\" (" + first_name + "'s), got \"" +
                                                   m.kind + "\"");
  }
  // track.csv prints the model to 3 and 5 decimals (track/take.cc).
  const std::pair<const char*, std::pair<double, double>> printed[] = {{"focus_mm", {m.focus_mm, 0.0005}},
                                                                       {"aperture_mm", {m.aperture_mm, 0.000005}}};
  for (const auto& [name, v] : printed) {
    const auto it = std::find(header.begin(), header.end(), name);
    if (it == header.end()) continue;
    const std::string& text = row.fields[size_t(it - header.begin())];
    const std::optional<double> csv = text == "inf" ? std::optional<double>(std::numeric_limits<double>::infinity()) : ParseDecimal(text);
    const bool same = csv && (std::isinf(*csv) || std::isinf(v.first) ? *csv == v.first
                                                                       : std::abs(*csv - v.first) <= 1.01 * v.second);
    if (!same)
      throw InputError(path + ": /model/" + name, "must be the take's " + Echo(text, false) + " (track.csv line " +
                                                      std::to_string(row.line) + "), got " + Num(v.first));
  }
}

// track.csv's row prints the frame's pose (rvec to 8 decimals, tvec to 4: track/take.cc); a calibration whose pose
// is not its row's (a hand edit of either) would draw the objects where the table says the board is not.
void RequireRowsPose(const calib::SceneCalib& c, const std::string& path, const std::vector<std::string>& header,
                     const CsvRecord& row) {
  static const char* const kNames[] = {"rvec_x", "rvec_y", "rvec_z", "tvec_x_mm", "tvec_y_mm", "tvec_z_mm"};
  for (int k = 0; k < 6; ++k) {
    const auto it = std::find(header.begin(), header.end(), kNames[k]);
    if (it == header.end()) continue;
    const std::string& text = row.fields[size_t(it - header.begin())];
    const double value = k < 3 ? c.rvec[k] : c.tvec[k - 3];
    const double half_step = k < 3 ? 0.5e-8 : 0.5e-4;
    const std::optional<double> csv = ParseDecimal(text);
    if (!csv || !(std::abs(*csv - value) <= 1.01 * half_step))
      throw InputError(path + (k < 3 ? ": /pose/rvec/" : ": /pose/tvec/") + std::to_string(k % 3),
                       "must be " + Echo(text, false) + ", the pose of its row in track.csv (line " +
                           std::to_string(row.line) + ", " + kNames[k] + "), got " + Num(value) +
                           ": the calibration or track.csv was edited (track the take again)");
  }
}

const std::vector<std::string> kBallKeys = {"kind", "name", "x_mm", "y_mm", "radius_mm", "texture"};
const std::vector<std::string> kCardKeys = {"kind", "name", "x_mm", "y_mm", "width_mm", "height_mm", "rotation_deg",
                                            "texture"};

double NumberIn(const Json& o, const std::string& key, const std::string& where, double fallback, double lo,
                double hi, bool required) {
  if (!o.contains(key)) {
    if (required) throw InputError(where + "/" + key, "missing (a number in mm)");
    return fallback;
  }
  const Json& v = o.at(key);
  if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() < lo || v.get<double>() > hi)
    throw InputError(where + "/" + key, "must be a number in [" + Num(lo) + ", " + Num(hi) + "], got " +
                                            Echo(v.dump(), false));
  return v.get<double>();
}

}  // namespace

const Camera& TrackedTake::camera() const {
  for (const TrackedFrame& f : frames)
    if (f.calib) return f.calib->camera;
  throw Error(ErrorKind::kInput, "the take has no frame with a pose (every frame is lost)");
}

const Board& TrackedTake::board() const {
  for (const TrackedFrame& f : frames)
    if (f.calib) return f.calib->board;
  throw Error(ErrorKind::kInput, "the take has no frame with a pose (every frame is lost)");
}

double TrackedTake::FramesPerSecond() const {
  if (frames.size() < 2 || !(frames[1].time_s > frames[0].time_s)) return 0;
  return 1 / (frames[1].time_s - frames[0].time_s);
}

TrackedTake LoadTrackedTake(const std::filesystem::path& dir) {
  const std::filesystem::path csv_path = dir / "track.csv";
  const std::string file = csv_path.string();
  if (std::filesystem::is_regular_file(dir))
    throw InputError(dir.string(), "is a file: give the folder that holds track.csv (the --out of blurcue track)");
  if (!std::filesystem::is_directory(dir)) throw InputError(dir.string(), "no such folder (the --out of blurcue track)");
  if (!std::filesystem::exists(csv_path)) throw InputError(file, "does not exist: is this a folder blurcue track wrote?");
  const CsvText csv = ParseCsv(ReadTextFile(csv_path, "a track.csv"), kMaxFrames + 1);
  if (!csv.problems.empty())
    throw InputError(file + ": line " + std::to_string(csv.problems.front().line), csv.problems.front().message);
  if (csv.records.empty()) throw InputError(file, "is empty (no header)");
  RequireFullRecords(csv, file);
  const std::vector<std::string>& header = csv.records.front().fields;
  auto column = [&](const char* name) {
    const auto it = std::find(header.begin(), header.end(), name);
    if (it == header.end()) throw InputError(file, std::string("no column '") + name + "' in its header");
    return size_t(it - header.begin());
  };
  const size_t c_frame = column(track::kTrackColumns[0].name), c_time = column("time_s"), c_status = column("status");
  TrackedTake take;
  int first_posed = -1;  // the take's camera is this frame's
  for (size_t k = 1; k < csv.records.size(); ++k) {
    const CsvRecord& row = csv.records[k];
    TrackedFrame f;
    const double index = NumberField(file, row, c_frame, "frame");
    if (index != double(take.frames.size()))
      throw InputError(file + ": line " + std::to_string(row.line) + ", frame",
                       "must be " + std::to_string(take.frames.size()) + " (frames in order from 0), got " +
                           Echo(row.fields[c_frame], false));
    f.index = int(index);
    f.time_s = NumberField(file, row, c_time, "time_s");
    // Times increase, by at least a millisecond (at most 1000 frames a second, as a simulated clock may run) and from
    // 0 to at most a day: the motion between frames is their poses' change over their time apart.
    const std::string at_time = file + ": line " + std::to_string(row.line) + ", time_s";
    if (!(f.time_s >= 0 && f.time_s <= 86400))
      throw InputError(at_time, "must be in [0, 86400] s, got " + Echo(row.fields[c_time], false));
    if (!take.frames.empty() && !(f.time_s >= take.frames.back().time_s + 0.001 - 1e-9))
      throw InputError(at_time, "must be at least 1 ms after the frame before's " + Num(take.frames.back().time_s) +
                                    " s (frames in time order, at most 1000 a second), got " +
                                    Echo(row.fields[c_time], false));
    f.status = ParseStatus(file + ": line " + std::to_string(row.line) + ", status",
                           c_status < row.fields.size() ? row.fields[c_status] : "");
    const std::filesystem::path calib_path = dir / track::CalibFileName(f.index);
    if (f.status != track::FrameStatus::kLost) {
      const Json json = ReadJsonFile(calib_path);
      f.calib = calib::SceneCalibFromJson(json, calib_path.string() + ": ");
      CheckCalibIsTheRows(json, calib_path.string(), f, row.fields[c_time]);
      f.signature = json["frame_signature"].get<std::vector<double>>();
      RequireTakesModel(*f.calib, calib_path.string(), first_posed >= 0 ? &*take.frames[size_t(first_posed)].calib
                                                                        : nullptr,
                        track::CalibFileName(std::max(first_posed, 0)), header, row);
      RequireRowsPose(*f.calib, calib_path.string(), header, row);
      if (first_posed >= 0 && !SameCamera(take.frames[size_t(first_posed)].calib->camera, f.calib->camera))
        throw InputError(calib_path.string() + ": /camera",
                         "is not the camera of " + track::CalibFileName(first_posed) +
                             " (one camera films a take; this calibration is of another take or another camera)");
      if (first_posed < 0) first_posed = f.index;
    } else if (std::filesystem::exists(calib_path)) {
      throw InputError(file + ": line " + std::to_string(row.line) + ", status",
                       "says frame " + std::to_string(f.index) + " is lost, but " + calib_path.filename().string() +
                           " holds its calibration: track.csv was edited, or the folder mixes two takes (track "
                           "the take again)");
    }
    take.frames.push_back(std::move(f));
  }
  if (take.frames.empty()) throw InputError(file, "has no frames (only a header)");
  // A calibration past the last row: track.csv lost its last rows (cut, or a hand edit), and the take would end early.
  if (const std::filesystem::path next = dir / track::CalibFileName(int(take.frames.size()));
      std::filesystem::exists(next))
    throw InputError(file, "has " + std::to_string(take.frames.size()) + " frames, but " + next.filename().string() +
                               " holds a calibration of frame " + std::to_string(take.frames.size()) +
                               ": track.csv was cut short or edited (track the take again)");
  (void)take.camera();  // at least one pose
  return take;
}

void CheckTakeFrame(const TrackedTake& take, int index, const cv::Mat& image, const std::string& video,
                    const std::string& track_dir) {
  const Camera& camera = take.camera();
  const std::string frame = "frame " + std::to_string(index);
  if (image.cols != camera.image_width_px || image.rows != camera.image_height_px)
    throw InputError(video, frame + " is " + std::to_string(image.cols) + " x " + std::to_string(image.rows) +
                                " px; the take " + track_dir + " tracked is " + std::to_string(camera.image_width_px) +
                                " x " + std::to_string(camera.image_height_px) + " px (the track of another take?)");
  if (index >= int(take.frames.size()) || !take.frames[size_t(index)].calib) return;
  const double d = track::SignatureDistance(track::FrameSignature(image), take.frames[size_t(index)].signature);
  if (d > track::kMaxSignatureDistance)
    throw InputError(video, frame + " is not the frame " + track_dir + " tracked (its grey levels differ by up to " +
                                Num(d) + " on an 8 x 8 grid, more than " + Num(track::kMaxSignatureDistance) +
                                "): the track of another take, or the video changed since blurcue track ran");
}

scene::VirtualObject BallAt(double x_mm, double y_mm, double radius_mm) {
  scene::VirtualObject o;
  o.kind = scene::VirtualObject::Kind::kBall;
  o.size_mm = radius_mm;
  o.center_board_mm = {x_mm, y_mm, radius_mm};  // resting on the board (+z towards the camera's side)
  return o;
}

scene::VirtualObject StandingCardAt(double x_mm, double y_mm, double width_mm, double height_mm, double rotation_deg) {
  scene::VirtualObject o;
  o.kind = scene::VirtualObject::Kind::kCard;
  o.size_mm = width_mm;
  o.card_height_mm = height_mm;
  o.standing = true;
  o.rotation_deg = rotation_deg;
  o.center_board_mm = {x_mm, y_mm, height_mm / 2};
  return o;
}

std::vector<PlacedObject> PlacedObjectsFromJson(const Json& json, const std::string& where) {
  if (!json.is_object() || !json.contains("objects"))
    throw InputError(where, "must be an object with \"objects\": [...] (docs/ar.md)");
  for (const auto& [key, value] : json.items())
    if (key != "objects") throw InputError(where + "/" + key, "unknown key" + DidYouMean(key, {"objects"}));
  const Json& list = json.at("objects");
  if (!list.is_array() || list.empty()) throw InputError(where + "/objects", "must be a non-empty array of objects");
  if (list.size() > kMaxPlacedObjects)
    throw InputError(where + "/objects", "holds " + std::to_string(list.size()) + " objects: at most " +
                                             std::to_string(kMaxPlacedObjects) + " a run");
  std::vector<PlacedObject> out;
  int balls = 0, cards = 0;
  // One texture per image, however many objects wear it: decoded once, and one GL texture (its identity).
  std::map<std::string, scene::SurfaceTexture> textures;
  for (size_t i = 0; i < list.size(); ++i) {
    const std::string at = where + "/objects/" + std::to_string(i);
    const Json& o = list[i];
    if (!o.is_object()) throw InputError(at, "must be an object, got " + Echo(o.dump(), false));
    const std::string kind = o.contains("kind") && o.at("kind").is_string() ? o.at("kind").get<std::string>() : "";
    if (kind != "ball" && kind != "card")
      throw InputError(at + "/kind", "must be \"ball\" or \"card\", got " +
                                         Echo(o.contains("kind") ? o.at("kind").dump() : "nothing", false) +
                                         DidYouMean(kind, {"ball", "card"}));
    const std::vector<std::string>& keys = kind == "ball" ? kBallKeys : kCardKeys;
    for (const auto& [key, value] : o.items())
      if (std::find(keys.begin(), keys.end(), key) == keys.end())
        throw InputError(at + "/" + JsonPointerToken(key), "unknown key for a " + kind + DidYouMean(key, keys));
    const double x = NumberIn(o, "x_mm", at, 0, -1e5, 1e5, true), y = NumberIn(o, "y_mm", at, 0, -1e5, 1e5, true);
    PlacedObject p;
    std::string texture;
    if (kind == "ball") {
      p.object = BallAt(x, y, NumberIn(o, "radius_mm", at, 10, 0.1, 1e4, false));
      p.name = "ball" + std::to_string(++balls);
      texture = "soccer";
    } else {
      const double w = NumberIn(o, "width_mm", at, 50, 0.1, 1e4, false);
      p.object = StandingCardAt(x, y, w, NumberIn(o, "height_mm", at, w, 0.1, 1e4, false),
                                NumberIn(o, "rotation_deg", at, 0, -360, 360, false));
      p.name = "card" + std::to_string(++cards);
      texture = "wood";
    }
    if (o.contains("name")) {
      // A name goes into the CSV as it is: letters, digits, '-' and '_' need no quoting anywhere.
      const bool ok = o.at("name").is_string() && !o.at("name").get<std::string>().empty() &&
                      o.at("name").get<std::string>().size() <= 40 &&
                      o.at("name").get<std::string>().find_first_not_of(
                          "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_") == std::string::npos;
      if (!ok)
        throw InputError(at + "/name", "must be 1-40 letters, digits, '-' or '_', got " + Echo(o.at("name").dump(), false));
      p.name = o.at("name").get<std::string>();
    }
    if (o.contains("texture")) {
      if (!o.at("texture").is_string()) throw InputError(at + "/texture", "must be a string");
      texture = o.at("texture").get<std::string>();
    }
    for (const PlacedObject& q : out)
      if (q.name == p.name) throw InputError(at + "/name", "\"" + p.name + "\" names two objects");
    auto known = textures.find(texture);
    if (known == textures.end())
      known = textures.emplace(texture, scene::SurfaceTexture(ReadImage(scene::ResolveStimulus(texture)))).first;
    p.object.texture = known->second;
    out.push_back(std::move(p));
  }
  return out;
}

std::vector<PlacedObject> LoadPlacedObjects(const std::filesystem::path& path) {
  return PlacedObjectsFromJson(ReadJsonFile(path), path.string() + ": ");
}

std::string ExposureBeyondFrame(double exposure_ms, double fps) {
  if (!(fps > 0) || exposure_ms <= 1000 / fps * 1.001) return "";
  return "longer than a frame of the take (" + Num(std::round(1e5 / fps) / 100) + " ms at " +
         Num(std::round(fps * 100) / 100) + " fps)";
}

cv::Vec2d StreakPx(const TrackedTake& take, int index, const cv::Vec3d& board_mm, double exposure_ms) {
  if (exposure_ms <= 0 || index < 0 || index >= int(take.frames.size()) || !take.frames[size_t(index)].calib)
    return {0, 0};
  const int before = NeighbourWithPose(take, index, -1), after = NeighbourWithPose(take, index, +1);
  // Central difference where both neighbours have a pose: exact for motion linear in time, and centred on this
  // frame, as the streak is (from -m/2 to +m/2 about the object's place).
  const int a = before >= 0 ? before : index, b = after >= 0 ? after : index;
  const double dt = take.frames[size_t(b)].time_s - take.frames[size_t(a)].time_s;
  if (a == b || !(dt > 0)) return {0, 0};
  const cv::Point2d pa = Project(*take.frames[size_t(a)].calib, board_mm);
  const cv::Point2d pb = Project(*take.frames[size_t(b)].calib, board_mm);
  const double s = exposure_ms / 1000 / dt;
  return {(pb.x - pa.x) * s, (pb.y - pa.y) * s};
}

bool SeenInAnyFrame(const TrackedTake& take, const scene::VirtualObject& object) {
  const Camera& camera = take.camera();
  const cv::Rect photo(0, 0, camera.image_width_px, camera.image_height_px);
  for (const TrackedFrame& f : take.frames) {
    if (!f.calib) continue;
    try {
      if (!(scene::FootprintOf(camera, f.calib->rvec, f.calib->tvec, object).bounds & photo).empty()) return true;
    } catch (const Error&) {  // behind the camera in this frame: not seen in it
    }
  }
  return false;
}

TrackedFramePlan PlanTrackedFrame(const TrackedTake& take, int index, const std::vector<PlacedObject>& objects,
                                  const TakeBlur& blur) {
  TrackedFramePlan plan;
  if (index < 0 || index >= int(take.frames.size()) || !take.frames[size_t(index)].calib) return plan;
  const TrackedFrame& frame = take.frames[size_t(index)];
  const calib::SceneCalib& c = *frame.calib;
  for (const PlacedObject& p : objects) {
    // The frame's own number (a live view's two-frame window holds frames of any number at places 0 and 1).
    const std::string who = p.name + " in frame " + std::to_string(frame.index);
    DrawnObject d;
    d.name = p.name;
    d.screen_px = Project(c, p.object.center_board_mm);
    const cv::Vec3d centre = c.ToCamera(p.object.center_board_mm);
    d.depth_mm = centre[2];
    try {
      d.r_px = calib::BlurAtPx(c, blur.source, centre, blur.fixed_r_px);
    } catch (const Error& e) {
      throw Error(e.kind(), who + ": " + e.what());
    }
    d.floor_sigma_px = calib::FloorSigmaPx(c, blur.source, centre);
    d.motion_px = StreakPx(take, index, p.object.center_board_mm, blur.exposure_ms);
    const double streak = cv::norm(d.motion_px);
    if (!(d.r_px >= 0 && d.r_px <= optics::kMaxBlurRadiusPx && streak <= optics::kMaxBlurRadiusPx))
      throw Error(ErrorKind::kDomain, who + ": blur r " + Num(d.r_px) + " px, streak " + Num(streak) +
                                          " px; each must be in [0, " + Num(optics::kMaxBlurRadiusPx) + "] px");
    scene::BlurredObject o;
    o.object = p.object;
    o.method = blur.method;
    o.r_px = d.r_px;
    o.floor_sigma_px = d.floor_sigma_px;
    o.shape = calib::ShapeAt(c, blur.source, centre);
    o.motion_px = d.motion_px;
    plan.objects.push_back(std::move(o));
    plan.drawn.push_back(std::move(d));
  }
  return plan;
}

const std::vector<DrawnColumn> kDrawnColumns = {
    {"frame", "frame index from 0 (the take's, as in track.csv)"},
    {"time_s", "the frame's time, s (track.csv's)"},
    {"status", "track.csv's status: found, tracked or lost (lost: drawn without objects); untracked: a frame of INPUT "
               "beyond track.csv, drawn without objects"},
    {"object", "the object's name (empty on a frame drawn without objects)"},
    {"screen_x_px", "its centre's projection at the frame's pose, image px from the left (pixel centres at integers)"},
    {"screen_y_px", "... from the top"},
    {"depth_mm", "its centre's camera z (depth), mm"},
    {"r_px", "its blur without the motion: defocus x lens floor, 2 x the std of the PSF's line-spread function, px"},
    {"floor_sigma_px", "the lens floor (std, px) inside r_px"},
    {"motion_x_px", "the motion streak: the centre's image velocity x the exposure, px (x right)"},
    {"motion_y_px", "... (y down)"},
};

std::string DrawnCsvHeader() {
  std::string line;
  for (const DrawnColumn& c : kDrawnColumns) line += (line.empty() ? "" : ",") + std::string(c.name);
  return line + "\n";
}

std::string DrawnCsvRows(int frame, double time_s, const std::string& status, const std::vector<DrawnObject>& drawn) {
  std::ostringstream out;
  char head[96];
  std::snprintf(head, sizeof head, "%d,%.6f,%s,", frame, time_s, status.c_str());
  if (drawn.empty()) out << head << ",,,,,,,\n";
  for (const DrawnObject& d : drawn) {
    char row[256];
    std::snprintf(row, sizeof row, "%.4f,%.4f,%.3f,%.4f,%.4f,%.4f,%.4f", d.screen_px.x, d.screen_px.y, d.depth_mm,
                  d.r_px, d.floor_sigma_px, d.motion_px[0], d.motion_px[1]);
    out << head << d.name << "," << row << "\n";
  }
  return out.str();
}

}  // namespace blurcue::stimulus
