#include "calib/scene_blur.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <limits>
#include <sstream>

#include <opencv2/calib3d.hpp>

#include "calib/calib_whole.h"
#include "core/distortion.h"
#include "core/error.h"
#include "core/names.h"
#include "core/typed.h"
#include "optics/thin_lens.h"

namespace blurcue::calib {
namespace {

// A number of calib.json in [lo, hi] (unit for the message); NaN and infinity fail too.
double Ranged(const Json& obj, const std::string& key, const std::string& where, double lo, double hi,
              const std::string& unit) {
  const double v = RequireNumber(obj, key, where);
  if (!(v >= lo && v <= hi))
    throw InputError(where + "/" + key, "must be in [" + Num(lo) + ", " + Num(hi) + "]" +
                                            (unit.empty() ? "" : " " + unit) + ", got " + Num(v));
  return v;
}

// A whole number of calib.json in [lo, hi], compared before it is narrowed, so 4294967303 is refused, not wrapped.
int RangedInt(const Json& obj, const std::string& key, const std::string& where, int lo, int hi) {
  const double v = Ranged(obj, key, where, lo, hi, "");
  if (!obj[key].is_number_integer()) throw InputError(where + "/" + key, "must be an integer, got " + obj[key].dump());
  return static_cast<int>(v);
}

// Three numbers, each in [-limit, limit] (a rotation vector in radians, a translation or point in mm).
cv::Vec3d Vec3(const Json& obj, const std::string& key, const std::string& where, double limit,
               const std::string& unit) {
  const Json& v = obj.contains(key) ? obj[key] : Json();
  if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() || !v[2].is_number())
    throw InputError(where + "/" + key, "must be an array of 3 numbers, got " + v.dump());
  cv::Vec3d out;
  for (int i = 0; i < 3; ++i) {
    out[i] = v[i].get<double>();
    if (!(std::abs(out[i]) <= limit))
      throw InputError(where + "/" + key + "/" + std::to_string(i),
                       "must be in [" + Num(-limit) + ", " + Num(limit) + "] " + unit + ", got " + Num(out[i]));
  }
  return out;
}

// Depths and distances in calib.json: at most 1000 m, far beyond any table-top scene.
constexpr double kMaxDistanceMm = 1e6;

const Json& Object(const Json& obj, const std::string& key, const std::string& where) {
  if (!obj.contains(key) || !obj[key].is_object()) throw InputError(where + "/" + key, "must be an object");
  return obj[key];
}

// calib.json is written by `blurcue calibrate` (CalibToJson) and `track` (a frame's calib-NNNN.json adds its
// frame's fields); a key neither writes is a hand edit the reader would ignore: refused, naming the nearest.
void KnownKeys(const Json& obj, const std::string& where, const std::vector<std::string>& known) {
  for (auto it = obj.begin(); it != obj.end(); ++it)
    if (std::find(known.begin(), known.end(), it.key()) == known.end())
      throw InputError(where + "/" + it.key(), "is not a field of a blurcue calibration" + DidYouMean(it.key(), known));
}

const std::vector<std::string> kTopKeys = {"format", "version", "software", "camera", "board", "pose",
                                           "reference_edge", "reference", "model", "r_units", "timing_ms", "edges",
                                           "phase_check",
                                           // a tracked frame's (track/take.cc)
                                           "photo", "frame", "time_s", "track_status", "frame_signature",
                                           "lens_model"};
// The smaller objects' fields, each as CalibToJson writes them; phase_check's are for the reader of the file (only its
// earlier model_undetermined is read), named so that a misspelt one is not taken for read.
const std::vector<std::string> kBoardKeys = {"cols", "rows", "square_mm"};
const std::vector<std::string> kPoseKeys = {"rvec", "tvec", "reprojection_error_px"};
const std::vector<std::string> kReferenceKeys = {"u_mm", "r_px"};
const std::vector<std::string> kTimingKeys = {"detect", "measure", "estimate"};
const std::vector<std::string> kUndeterminedKeys = {"u_mm", "worst_se_rel", "why"};
const std::vector<std::string> kPhaseCheckKeys = {"limited_sections", "every_phase_sections", "flagged",
                                                  "held_the_model", "chosen", "chi2_per_point", "variance_px2",
                                                  "families", "summary", "note", "model_undetermined"};
const std::vector<std::string> kModelKeys = {"kind", "focus_mm", "aperture_mm", "floor_px", "cancel_px2", "floor_determined",
                                             "rms_px", "loo_rms_px", "samples_used", "outliers", "choice",
                                             "sections_left_out", "fitted_to", "undetermined"};
const std::vector<std::string> kEdgeKeys = {"index", "u_mm", "usable_sections", "sections"};
const std::vector<std::string> kSectionKeys = {"index", "u_mm", "midpoint_camera_mm", "image_px", "r_px", "r_thesis_px",
                                               "r_estimated_px", "r_fitted_px", "ok", "flags", "psf", "disc_r_px",
                                               "floor_sigma_px", "shape_ambiguous", "fit_rms_rel", "step_linear",
                                               "thesis_ok", "r_estimated_note", "crowded_why", "stretch",
                                               "phase", "phase_why", "r_se_px", "r_fitted_se_px"};
const std::vector<std::string> kModelKinds = {"thin_lens", "thin_lens+floor"};

// A boolean field (absent: `absent`).
bool Flag(const Json& obj, const std::string& key, const std::string& where, bool absent) {
  if (!obj.contains(key)) return absent;
  if (!obj[key].is_boolean()) throw InputError(where + "/" + key, "must be true or false, got " + obj[key].dump());
  return obj[key].get<bool>();
}

// A section's flags as calib.json lists them ("phase_limited, flaw"); empty where it lists none (a message's words).
std::string FlagsText(const Json& sec) {
  std::string text;
  if (sec.contains("flags") && sec["flags"].is_array())
    for (const Json& flag : sec["flags"])
      if (flag.is_string()) text += (text.empty() ? "" : ", ") + flag.get<std::string>();
  return text;
}

// "FILE: POINTER: " of a message about the calibration (a scene built in code names none).
std::string At(const SceneCalib& scene, const std::string& pointer) {
  return (scene.file.empty() ? std::string("the calibration") : scene.file) + ": " + pointer + ": ";
}

// A measured source with no value here: the calibration holds none, so it is an input error naming calib.json, the
// field and its value (exit 3), not "nothing found" (exit 4): another source, or another photo, is the remedy.
constexpr const char* kOtherSources = "so its measured blur is unknown; fitted (the lens model) or estimated "
                                      "(eq. 3.7) give one";

// The flags of the sections `of`, counted ("7 flagged phase_limited"; "" when none is flagged).
std::string FlagCounts(const std::vector<const SceneCalib::Section*>& of) {
  std::map<std::string, int> n;
  for (const SceneCalib::Section* s : of) n[s->flags.empty() ? "with no flag" : "flagged " + s->flags] += 1;
  std::string text;
  for (const auto& [flags, count] : n) text += (text.empty() ? "" : ", ") + std::to_string(count) + " " + flags;
  return text;
}

[[noreturn]] void NoMeasuredEdge(const SceneCalib& scene, int edge) {
  std::vector<const SceneCalib::Section*> listed;
  for (const auto& s : scene.sections)
    if (s.edge == edge) listed.push_back(&s);
  const std::string who = "edge " + std::to_string(edge) + " (the nearest) has no usable measured section";
  if (listed.empty() || listed.front()->pointer.empty())
    throw InputError((scene.file.empty() ? std::string("the calibration") : scene.file) + ": /edges",
                     who + " (" + std::to_string(listed.size()) + " of its sections listed, none usable), " +
                         kOtherSources);
  const std::string& p = listed.front()->pointer;
  throw Error(ErrorKind::kInput, At(scene, p.substr(0, p.find("/sections/"))) + who + ": \"ok\" is false in all " +
                                     std::to_string(listed.size()) + " of its sections (" + FlagCounts(listed) + "), " +
                                     kOtherSources);
}

[[noreturn]] void NoMeasuredSection(const SceneCalib& scene, const SceneCalib::Section& s) {
  const std::string who = "edge " + std::to_string(s.edge) + " section " + std::to_string(s.section) +
                          " (the nearest) is not usable, ";
  if (s.pointer.empty())
    throw Error(ErrorKind::kInput, (scene.file.empty() ? std::string("the calibration") : scene.file) + ": " + who +
                                       kOtherSources);
  throw Error(ErrorKind::kInput, At(scene, s.pointer + "/ok") + "is false (" +
                                     (s.flags.empty() ? std::string("no flag") : "flagged " + s.flags) + "): " + who +
                                     kOtherSources);
}

}  // namespace

cv::Vec3d SceneCalib::ToCamera(const cv::Vec3d& board_mm) const {
  cv::Matx33d rot;
  cv::Rodrigues(rvec, rot);
  return rot * board_mm + tvec;
}

void SceneCalib::RequireSameSize(const cv::Mat& photo, const std::string& photo_path) const {
  if (photo.cols != camera.image_width_px || photo.rows != camera.image_height_px)
    throw InputError(photo_path, "is " + std::to_string(photo.cols) + "x" + std::to_string(photo.rows) +
                                     " but the scene was calibrated on " + std::to_string(camera.image_width_px) +
                                     "x" + std::to_string(camera.image_height_px));
}

namespace {
// calib.json's model.undetermined (null where calibrate named no depth): its depths and standard error. Earlier
// calibrations kept it in phase_check.model_undetermined; one naming depths there is refused (its depths would go
// unsaid), one naming none is read as none.
void ReadUndetermined(const Json& j, const std::string& where, SceneCalib* s) {
  if (const auto check = j.find("phase_check"); check != j.end()) {
    if (!check->is_object()) throw InputError(where + "/phase_check", "must be an object, got " + check->dump());
    KnownKeys(*check, where + "/phase_check", kPhaseCheckKeys);
    if (const auto old = check->find("model_undetermined"); old != check->end() && !old->is_null())
      throw InputError(where + "/phase_check/model_undetermined",
                       "is now read from /model/undetermined (a calibration written before kept it here, "
                       "where its depths would go unsaid): calibrate the photo again, or move the field there");
  }
  const Json& model = j.at("model");  // read and checked already
  const auto und = model.find("undetermined");
  if (und == model.end() || und->is_null()) return;
  const std::string uw = where + "/model/undetermined";
  if (!und->is_object()) throw InputError(uw, "must be an object or null, got " + und->dump());
  KnownKeys(*und, uw, kUndeterminedKeys);
  if (const auto why = und->find("why"); why != und->end() && !why->is_string())
    throw InputError(uw + "/why", "must be the reason in words (a string), got " + why->dump());
  const auto u = und->find("u_mm");
  if (u == und->end() || !u->is_array() || u->size() != 2 || !(*u)[0].is_number() || !(*u)[1].is_number() ||
      !((*u)[0].get<double>() > s->camera.focal_length_mm) || !((*u)[0].get<double>() <= (*u)[1].get<double>()) ||
      !((*u)[1].get<double>() <= kMaxDistanceMm))
    throw InputError(uw + "/u_mm", "must be [near, far] depths in mm, beyond the focal length (" +
                                       Num(s->camera.focal_length_mm) + " mm), near <= far, got " +
                                       (u == und->end() ? std::string("nothing") : u->dump()));
  s->undetermined.lo_mm = (*u)[0].get<double>();
  s->undetermined.hi_mm = (*u)[1].get<double>();
  // Named depths are where it exceeds 5 % (calibrate's kModelSeRel): a smaller one contradicts them.
  s->undetermined.worst_se_rel = Ranged(*und, "worst_se_rel", uw, 0.05, 1e6, "(a share, over 0.05 where depths are named)");
}
}  // namespace

SceneCalib SceneCalibFromJson(const Json& j, const std::string& where) {
  if (!j.is_object())  // `where` is "path: "
    throw Error(ErrorKind::kInput, where + "must be a JSON object (a calibration), got " + j.type_name());
  if (!j.contains("format") || j["format"] != "blurcue-calib")
    throw InputError(where + "/format", "must be \"blurcue-calib\" (a file written by blurcue calibrate)");
  KnownKeys(j, where, kTopKeys);
  if (j.contains("version") && j["version"] != 1)
    throw InputError(where + "/version", "must be 1 (this blurcue reads calibrations of format version 1), got " +
                                             j["version"].dump());
  SceneCalib s;
  // The file alone, for a message: `where` is "path: ".
  const bool colon = where.size() >= 2 && where.compare(where.size() - 2, 2, ": ") == 0;
  s.file = colon ? where.substr(0, where.size() - 2) : where;
  s.camera = CameraFromJson(Object(j, "camera", where), where + "/camera");
  const Json& board = Object(j, "board", where);
  KnownKeys(board, where + "/board", kBoardKeys);
  s.board.cols = RangedInt(board, "cols", where + "/board", 2, 100);
  s.board.rows = RangedInt(board, "rows", where + "/board", 2, 100);
  s.board.square_mm = Ranged(board, "square_mm", where + "/board", 1, 1000, "mm");
  s.board.Validate(where + "/board");
  const Json& pose = Object(j, "pose", where);
  KnownKeys(pose, where + "/pose", kPoseKeys);
  s.rvec = Vec3(pose, "rvec", where + "/pose", 4 * M_PI, "rad");
  s.tvec = Vec3(pose, "tvec", where + "/pose", kMaxDistanceMm, "mm");
  // The board in front of the lens: a pose that put it behind drew objects at negative depths, exit 0.
  for (const double x : {0.0, s.board.cols * s.board.square_mm})
    for (const double y : {0.0, s.board.rows * s.board.square_mm})
      if (!(s.ToCamera({x, y, 0})[2] > s.camera.focal_length_mm))
        throw InputError(where + "/pose", "must put the whole board in front of the lens (beyond its focal length), "
                                          "got rvec " + pose["rvec"].dump() + ", tvec " + pose["tvec"].dump());
  if (const auto timing = j.find("timing_ms"); timing != j.end()) {
    if (!timing->is_object()) throw InputError(where + "/timing_ms", "must be an object, got " + timing->dump());
    KnownKeys(*timing, where + "/timing_ms", kTimingKeys);
  }
  s.reference_edge = RangedInt(j, "reference_edge", where, 1, s.board.EdgeCount());
  const Json& ref = Object(j, "reference", where);
  KnownKeys(ref, where + "/reference", kReferenceKeys);
  s.reference_u_mm = Ranged(ref, "u_mm", where + "/reference", 0, kMaxDistanceMm, "mm");
  s.reference_r_px = Ranged(ref, "r_px", where + "/reference", 0, optics::kMaxBlurRadiusPx, "px");
  const Json& model = Object(j, "model", where);
  const std::string mw = where + "/model";
  KnownKeys(model, mw, kModelKeys);
  if (!model.contains("kind") || !model["kind"].is_string() ||
      std::find(kModelKinds.begin(), kModelKinds.end(), model["kind"].get<std::string>()) == kModelKinds.end())
    throw InputError(mw + "/kind", "must be \"thin_lens\" or \"thin_lens+floor\", got " +
                                       (model.contains("kind") ? model["kind"].dump() : std::string("nothing")) +
                                       (model.contains("kind") && model["kind"].is_string()
                                            ? DidYouMean(model["kind"].get<std::string>(), kModelKinds)
                                            : ""));
  s.model.kind = model["kind"].get<std::string>();
  s.model.focus_mm = model.contains("focus_mm") && model["focus_mm"] == "infinity"
                         ? std::numeric_limits<double>::infinity()
                         : Ranged(model, "focus_mm", where + "/model", 0, kMaxDistanceMm, "mm");
  s.model.aperture_mm = Ranged(model, "aperture_mm", where + "/model", 0, 1000, "mm");
  // The floor belongs to its model: the floor model states it (a missing one is not taken as 0), the thin lens has
  // none (a floor beside it would be drawn though the model says there is none).
  const bool floored = s.model.kind == "thin_lens+floor";
  if (floored || model.contains("floor_px"))
    s.model.floor_px = Ranged(model, "floor_px", mw, 0, optics::kMaxBlurRadiusPx, "px");
  if (!floored && s.model.floor_px != 0)
    throw InputError(mw + "/floor_px", "must be 0 for model kind \"thin_lens\" (no floor), got " +
                                           Num(s.model.floor_px) + "; a floor needs kind \"thin_lens+floor\"");
  s.model.floor_determined = Flag(model, "floor_determined", mw, !floored);
  // A sharpening that cancels more than the floor (optics::FittedModel::cancel_px2); 0 where calib.json predates it.
  if (model.contains("cancel_px2"))
    s.model.cancel_px2 = Ranged(model, "cancel_px2", mw, -optics::kMaxBlurRadiusPx * optics::kMaxBlurRadiusPx, 0, "px^2");
  // The thin lens forms an image of its focus plane only beyond its focal length.
  if (const double f_mm = s.camera.focal_length_mm; !(s.model.focus_mm > f_mm))
    throw InputError(mw + "/focus_mm", "must be beyond the camera's focal length (" + Num(f_mm) +
                                           " mm): a thin lens forms no real image nearer, got " +
                                           Num(s.model.focus_mm));
  if (!(s.reference_u_mm > s.camera.focal_length_mm))
    throw InputError(where + "/reference/u_mm", "must be beyond the camera's focal length (" +
                                                    Num(s.camera.focal_length_mm) + " mm), got " +
                                                    Num(s.reference_u_mm));
  if (!j.contains("edges") || !j["edges"].is_array()) throw InputError(where + "/edges", "must be an array");
  // An edge or a section listed twice would be averaged with the other copy, or stand in for a missing one: both
  // are refused, so each edge's measured blur is its own sections' and nothing else's.
  std::map<int, std::string> edge_seen;
  for (size_t e = 0; e < j["edges"].size(); ++e) {
    const Json& edge = j["edges"][e];
    const std::string ew = where + "/edges/" + std::to_string(e);
    if (!edge.is_object()) throw InputError(ew, "must be an object");
    KnownKeys(edge, ew, kEdgeKeys);
    const int index = RangedInt(edge, "index", ew, 1, s.board.EdgeCount());
    if (const auto [it, fresh] = edge_seen.emplace(index, "/edges/" + std::to_string(e)); !fresh)
      throw InputError(ew + "/index", "edge " + std::to_string(index) + " is listed twice (also at " + it->second +
                                          ")");
    if (!edge.contains("sections") || !edge["sections"].is_array())
      throw InputError(ew + "/sections", "must be an array");
    std::map<int, std::string> section_seen;
    for (size_t k = 0; k < edge["sections"].size(); ++k) {
      const Json& sec = edge["sections"][k];
      const std::string sw = ew + "/sections/" + std::to_string(k);
      if (!sec.is_object()) throw InputError(sw, "must be an object");
      KnownKeys(sec, sw, kSectionKeys);
      SceneCalib::Section out;
      out.edge = index;
      out.section = RangedInt(sec, "index", sw, 1, s.board.SectionCount());
      if (const auto [it, fresh] = section_seen.emplace(out.section, "/sections/" + std::to_string(k)); !fresh)
        throw InputError(sw + "/index", "section " + std::to_string(out.section) + " of edge " +
                                            std::to_string(index) + " is listed twice (also at " + it->second + ")");
      out.midpoint_camera_mm = Vec3(sec, "midpoint_camera_mm", sw, kMaxDistanceMm, "mm");
      out.ok = Flag(sec, "ok", sw, false);
      // A section the fit gave up on keeps whatever number it had; only usable ones feed a blur.
      if (const auto ph = sec.find("phase"); ph != sec.end() && ph->is_object())
        out.pooled = Flag(*ph, "joins_fit", sw + "/phase", false) && !out.ok;  // a non-boolean is refused
      out.r_px = out.ok || out.pooled ? Ranged(sec, "r_px", sw, 0, optics::kMaxBlurRadiusPx, "px")
                                      : RequireNumber(sec, "r_px", sw);
      out.pointer = "/edges/" + std::to_string(e) + "/sections/" + std::to_string(k);
      out.flags = FlagsText(sec);
      s.sections.push_back(out);
    }
  }
  ReadUndetermined(j, where, &s);
  RequireWholeCalib(j, s, where);
  return s;
}

int NearestEdge(const SceneCalib& scene, const cv::Vec3d& p) {
  const Board& board = scene.board;
  int nearest = 0;
  double best_d = 1e300;
  for (int edge = 1; edge <= board.EdgeCount(); ++edge) {
    const cv::Vec3d a = scene.ToCamera(cv::Vec3d(board.SectionStart(edge, 1).data()));
    const cv::Vec3d b = scene.ToCamera(cv::Vec3d(board.SectionEnd(edge, board.SectionCount()).data()));
    const double d = cv::norm((p - a).cross((b - a) / cv::norm(b - a)));
    if (d < best_d) best_d = d, nearest = edge;
  }
  return nearest;
}

std::string PooledNote(const SceneCalib& scene, BlurSource source, int edge) {
  if (source != BlurSource::kMeasured) return "";
  int ok = 0, pooled = 0;
  double sum = 0;
  for (const auto& s : scene.sections)
    if (s.edge == edge) ok += s.ok, pooled += s.pooled, sum += s.pooled ? s.r_px : 0;
  if (ok > 0 || pooled == 0) return "";
  char text[400];
  std::snprintf(text, sizeof text,
                "the measured blur at edge %d (%.2f px) is the mean of %d readings none of which is usable alone "
                "(phase_limited, pooled into the lens fit: %s /edges/%d/sections/*/phase_why); `fitted` gives the "
                "model's value there",
                edge, sum / pooled, pooled, scene.file.empty() ? "the calibration" : scene.file.c_str(), edge - 1);
  return text;
}

std::string BlurFrom(const SceneCalib& scene, BlurSource source) {
  const std::string file = scene.file.empty() ? "the calibration" : scene.file;
  switch (source) {
    case BlurSource::kFitted: return " (the lens model, " + file + " /model)";
    case BlurSource::kEstimated: return " (eq. 3.7 from the reference edge, " + file + " /reference and /model)";
    case BlurSource::kMeasured:
    case BlurSource::kMeasuredSection: return " (the sections' readings, " + file + " /edges)";
    default: return "";
  }
}

std::string UndeterminedNote(const SceneCalib& scene, BlurSource source, double u_mm) {
  const ModelUndetermined& und = scene.undetermined;
  if (source != BlurSource::kFitted || !und.Inside(u_mm)) return "";
  char text[400];
  std::snprintf(text, sizeof text,
                "the fitted blur at %.0f mm is the lens model's estimate, not a result within 5 %%: the model is "
                "not determined within 5 %% at %.0f-%.0f mm (its error up to %s; why: %s /model/undetermined)",
                u_mm, und.lo_mm, und.hi_mm, und.Reach().c_str(),
                scene.file.empty() ? "the calibration" : scene.file.c_str());
  return text;
}

SceneCalib LoadSceneCalib(const std::filesystem::path& path) {
  return SceneCalibFromJson(ReadJsonFile(path), path.string() + ": ");
}

BlurSource ParseBlurSource(const std::string& text, double* fixed_r_px, const std::string& option) {
  for (const BlurSource source : kBlurSources)
    if (source != BlurSource::kFixed && ToString(source) == text) return source;
  const std::optional<double> r = ParseDecimal(text);
  if (r && *r >= 0 && *r <= optics::kMaxBlurRadiusPx) {
    if (fixed_r_px) *fixed_r_px = *r;
    return BlurSource::kFixed;
  }
  std::string words;
  for (const std::string& word : BlurSourceWords()) words += (words.empty() ? "" : ", ") + word;
  throw Error(ErrorKind::kUsage, (option.empty() ? "" : option + ": ") + "blur source must be " + words + " or a radius in [0, " +
                                     std::to_string(int(optics::kMaxBlurRadiusPx)) + "] px, got " + Echo(text) +
                                     DidYouMean(text, BlurSourceWords()));
}

double StretchAt(const SceneCalib& scene, const cv::Vec3d& p) {
  const LensDistortion distortion(scene.camera);
  if (distortion.Identity() || !(p[2] > 0)) return 1;
  const std::array<double, 9> k = scene.camera.Intrinsics();
  return distortion.StretchIsotropic({k[0] * p[0] / p[2] + k[2], k[4] * p[1] / p[2] + k[5]});
}

double BlurAtPx(const SceneCalib& scene, BlurSource source, const cv::Vec3d& p, double fixed_r_px) {
  const optics::Lens lens = optics::Lens::FromCamera(scene.camera);
  switch (source) {
    case BlurSource::kNone: return 0;
    case BlurSource::kFixed: return fixed_r_px;
    case BlurSource::kEstimated: return optics::Eq37Px(lens, scene.reference_u_mm, scene.reference_r_px, p[2]);
    // The model is in ideal px; the photo's blur at the point is that times the distortion's stretch there.
    case BlurSource::kFitted: return scene.model.PredictPx(lens, p[2]) * StretchAt(scene, p);
    case BlurSource::kMeasuredSection: {
      // The nearest section, usable or not: a flagged one has no measured value, and the next usable one's (another
      // edge's, perhaps) would be recorded as this place's, so it is an error, as for `measured`.
      const SceneCalib::Section* best = nullptr;
      double best_d = 1e300;
      for (const auto& s : scene.sections) {
        const double d = cv::norm(s.midpoint_camera_mm - p);
        if (d < best_d) best_d = d, best = &s;
      }
      if (!best)
        throw Error(ErrorKind::kInput, At(scene, "/edges") + "lists no section, so no measured blur is known; fitted "
                                                             "(the lens model) or estimated (eq. 3.7) give one");
      if (!best->ok) NoMeasuredSection(scene, *best);
      return best->r_px;
    }
    case BlurSource::kMeasured: {
      // The edge whose line passes nearest the point, from the board and its pose (every edge the board has, measured
      // or not); its value is the mean r of its usable sections. An edge with none has no measured value: another
      // edge's would be recorded as this one's, so it is an error, not a fallback.
      const int nearest = NearestEdge(scene, p);
      double sum = 0;
      int usable = 0;
      for (const auto& s : scene.sections)
        if (s.edge == nearest) usable += s.ok || s.pooled, sum += s.ok || s.pooled ? s.r_px : 0;
      if (usable == 0) NoMeasuredEdge(scene, nearest);
      return sum / usable;
    }
  }
  return 0;
}

namespace {

// Whether a source is the scene's own blur (drawn with the photo's floor and stretch).
bool SceneOwn(BlurSource source) {
  switch (source) {
    case BlurSource::kMeasured:
    case BlurSource::kMeasuredSection:
    case BlurSource::kFitted: return true;
    case BlurSource::kEstimated:
    case BlurSource::kFixed:
    case BlurSource::kNone: return false;
  }
  return false;
}

}  // namespace

double FloorSigmaPx(const SceneCalib& scene, BlurSource source, const cv::Vec3d& p) {
  return SceneOwn(source) ? scene.model.floor_px / 2 * StretchAt(scene, p) : 0.0;
}

cv::Matx22d ShapeAt(const SceneCalib& scene, BlurSource source, const cv::Vec3d& p) {
  const cv::Matx22d round(1, 0, 0, 1);
  const LensDistortion distortion(scene.camera);
  if (!SceneOwn(source) || distortion.Identity() || !(p[2] > 0)) return round;
  const std::array<double, 9> k = scene.camera.Intrinsics();
  const Jacobian2 j = distortion.JacobianAt({k[0] * p[0] / p[2] + k[2], k[4] * p[1] / p[2] + k[5]});
  const double det = j[0] * j[3] - j[1] * j[2];
  if (!(det > 0)) return round;  // a map folded over there (synth and calibrate refuse such a lens)
  const double s = 1 / std::sqrt(det);
  return cv::Matx22d(j[0] * s, j[1] * s, j[2] * s, j[3] * s);
}

double BlurAlongSightPx(const SceneCalib& scene, BlurSource source, const cv::Vec3d& centre, double z_mm,
                        double fixed_r_px) {
  try {
    return BlurAtPx(scene, source, centre * (z_mm / centre[2]), fixed_r_px);
  } catch (const Error&) {
    return BlurAtPx(scene, source, centre, fixed_r_px);
  }
}

}  // namespace blurcue::calib
