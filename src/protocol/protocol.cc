#include "protocol/protocol.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <cmath>
#include <functional>
#include <map>
#include <set>

#include "core/error.h"
#include "core/limits.h"
#include "core/typed.h"

namespace blurcue::protocol {
namespace fs = std::filesystem;

std::string ToString(Task task) {
  switch (task) {
    case Task::kAdjustment: return "adjustment";
    case Task::kYesNo: return "yes_no";
    case Task::kRating: return "rating";
    default: return "forced_choice";
  }
}

std::string ToString(Procedure::Kind kind) {
  return kind == Procedure::Kind::kQuestPlus ? "quest_plus" : "staircase";
}

std::string ToString(Counterbalance counterbalance) {
  switch (counterbalance) {
    case Counterbalance::kSwapCopies: return "swap_copies";
    case Counterbalance::kByParticipant: return "by_participant";
    case Counterbalance::kNone: break;
  }
  return "none";
}

namespace {

// Edges a board can have: 101 for a board 100 squares long (the thesis's 7 x 10 board has 11, figure 4.10). A
// session checks its levels against the calibrated board's own count (session/stimulus.cc DescribeTrial).
const int kEdges = 101;

// Limits that keep validation itself linear and its report readable whatever the file holds.
const size_t kMaxProblems = 50;         // reported; the rest are counted
const size_t kMaxBlocks = 100;
const size_t kMaxFactors = 16;
const size_t kMaxLevels = 1000;         // per factor: more than a sitting could show
const size_t kMaxAdjustLevels = 50;     // each is low-passed up front: ~0.1 s apiece at 1280 px, ~1 s at 4K
const size_t kMaxTextChars = 2000;      // instructions: about what a screen holds
const size_t kMaxPathChars = 4096;

std::string Escape(const std::string& key) { return JsonPointerToken(key); }

// Appends `value` as compact JSON, stopping once `out` is longer than `limit`: a problem quotes what it got
// without writing out a 16 MiB value first.
void DumpBounded(const Json& value, size_t limit, std::string* out, int depth = 0) {
  if (out->size() > limit) return;
  if (depth > kMaxJsonDepth) {
    *out += "...";
    return;
  }
  if (value.is_array() || value.is_object()) {
    const bool array = value.is_array();
    *out += array ? '[' : '{';
    bool first = true;
    for (const auto& [key, item] : value.items()) {
      if (out->size() > limit) break;
      if (!first) *out += ',';
      first = false;
      if (!array) *out += Json(key).dump(-1, ' ', false, Json::error_handler_t::replace) + ':';
      DumpBounded(item, limit, out, depth + 1);
    }
    *out += array ? ']' : '}';
    return;
  }
  if (value.is_string() && value.get_ref<const std::string&>().size() > limit + 4) {
    // Cut at a character boundary (UTF-8 continuation bytes are 10xxxxxx): half a character cannot be dumped.
    // Cut past the limit, so that the caller sees the value was longer than it shows.
    const std::string& text = value.get_ref<const std::string&>();
    size_t cut = limit + 4;
    while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) --cut;
    *out += Json(text.substr(0, cut)).dump(-1, ' ', false, Json::error_handler_t::replace);
    return;
  }
  *out += value.dump(-1, ' ', false, Json::error_handler_t::replace);
}

std::string Got(const Json& value) {
  std::string text;
  DumpBounded(value, 80, &text);
  if (text.size() > 80) {
    // Cut at a character boundary (UTF-8 continuation bytes are 10xxxxxx).
    size_t cut = 77;
    while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) --cut;
    text = text.substr(0, cut) + "...";
  }
  return text;
}

// "[0.1, 100] cm/s": a closed range and its unit.
std::string Range(double lo, double hi, const std::string& unit) {
  char text[96];
  std::snprintf(text, sizeof text, "[%.10g, %.10g]", lo, hi);
  return text + (unit.empty() ? "" : " " + unit);
}

size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// A fixed blur radius: the thesis's measured radii reach ~17 px; 100 px blurs a whole object away.
const double kMaxFixedRadiusPx = 100;

bool IsBlurSource(const Json& v) {
  if (v.is_number()) return std::isfinite(v.get<double>()) && v.get<double>() >= 0 && v.get<double>() <= kMaxFixedRadiusPx;
  // A fixed radius on the screen: {"screen_px": r} or {"arcmin": r} (converted by the presentation and the profile).
  if (v.is_object() && v.size() == 1) {
    const bool arcmin = v.contains("arcmin");
    const Json& r = arcmin ? v["arcmin"] : v.contains("screen_px") ? v["screen_px"] : v.front();
    return (arcmin || v.contains("screen_px")) && r.is_number() && std::isfinite(r.get<double>()) &&
           r.get<double>() >= 0 && r.get<double>() <= (arcmin ? 600 : kMaxFixedRadiusPx);
  }
  if (!v.is_string()) return false;
  static const std::set<std::string> kNames = {"none", "measured", "measured_section", "estimated", "fitted"};
  return kNames.count(v.get<std::string>()) > 0;
}

// Names whose values CheckLevelValue knows: a level of a factor so named is that value, never an object.
bool IsValueName(const std::string& name) {
  static const std::set<std::string> kNames = {"edge",       "from_edge",  "to_edge", "section",   "speed_cm_s",
                                               "distance_m", "cutoff",     "left",    "right",     "y_mm",   "object",
                                               "from_y_mm",  "to_y_mm",    "left_x_mm", "right_x_mm",
                                               "height_mm",  "rotation_deg"};
  return kNames.count(name) > 0;
}

bool IsKeyName(const std::string& key) {
  static const std::set<std::string> kNamed = {"Left", "Right", "Up", "Down", "Space", "Return", "Tab", "Backspace"};
  if (kNamed.count(key)) return true;
  if (key.size() == 1) return (key[0] >= 'A' && key[0] <= 'Z') || (key[0] >= '0' && key[0] <= '9');
  if (key.size() >= 2 && key.size() <= 3 && key[0] == 'F') {
    const int n = std::atoi(key.c_str() + 1);
    return n >= 1 && n <= 12 && std::to_string(n) == key.substr(1);
  }
  return key.size() == 4 && key.rfind("KP_", 0) == 0 && key[3] >= '0' && key[3] <= '9';
}

// Walks the JSON once, filling a Protocol and collecting every problem rather than stopping at the first.
class Parser {
 public:
  Parser(const fs::path& file, const ValidateOptions& options) : file_(file), options_(options) {
    base_ = file.has_parent_path() ? file.parent_path() : fs::path(".");
  }

  std::vector<std::string> problems;  // each once, in first order, at most kMaxProblems
  size_t more_problems = 0;           // found beyond kMaxProblems

  // Fields inherited by several blocks are checked once per block: each message is kept once.
  void Problem(const std::string& ptr, const std::string& what) {
    ++calls_;
    std::string line = file_.string() + ": " + (ptr.empty() ? "/" : ptr) + ": " + what;
    if (!reported_.insert(line).second) return;
    if (problems.size() < kMaxProblems) problems.push_back(std::move(line));
    else ++more_problems;
  }
  void Problem(const std::string& ptr, const std::string& what, const Json& got) {
    Problem(ptr, what + ", got " + Got(got));
  }

  // True if `v` is an object; reports keys outside `known` (with the nearest known key as a hint).
  bool Object(const Json& v, const std::string& ptr, const std::vector<std::string>& known) {
    if (!v.is_object()) {
      Problem(ptr, "must be an object", v);
      return false;
    }
    for (const auto& [key, value] : v.items()) {
      if (std::find(known.begin(), known.end(), key) != known.end()) continue;
      std::string hint;
      size_t best = 3;
      for (const auto& k : known) {
        const size_t d = EditDistance(key, k);
        if (d < best) best = d, hint = k;
      }
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      Problem(ptr + "/" + Escape(key),
              "unknown key" + (hint.empty() ? " (known: " + list + ")" : " (did you mean \"" + hint + "\"?)"), value);
    }
    return true;
  }

  const Json* Field(const Json& obj, const std::string& key, const std::string& ptr, bool required) {
    if (!obj.is_object()) return nullptr;
    auto it = obj.find(key);
    if (it == obj.end()) {
      if (required) Problem(ptr + "/" + Escape(key), "is required but missing");
      return nullptr;
    }
    return &*it;
  }

  std::optional<std::string> String(const Json& obj, const std::string& key, const std::string& ptr, bool required,
                                    const std::vector<std::string>& allowed = {}) {
    const Json* v = Field(obj, key, ptr, required);
    if (!v) return std::nullopt;
    const std::string p = ptr + "/" + Escape(key);
    if (!v->is_string()) {
      Problem(p, "must be a string", *v);
      return std::nullopt;
    }
    const std::string s = v->get<std::string>();
    if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), s) == allowed.end()) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : " | ") + a;
      Problem(p, "must be one of " + list, *v);
      return std::nullopt;
    }
    return s;
  }

  // An integer in [min, max]; `unit` (e.g. "px", "trials") goes into the message.
  std::optional<int> Int(const Json& obj, const std::string& key, const std::string& ptr, bool required, int min,
                         int max, const std::string& unit = "") {
    const Json* v = Field(obj, key, ptr, required);
    if (!v) return std::nullopt;
    const std::string p = ptr + "/" + Escape(key);
    const std::string range = "an integer in " + Range(min, max, unit);
    if (!v->is_number_integer()) {
      Problem(p, "must be " + range, *v);
      return std::nullopt;
    }
    if (!IntegerIn(*v, min, max)) {
      Problem(p, "must be " + range, *v);
      return std::nullopt;
    }
    return static_cast<int>(v->get<int64_t>());
  }

  // A finite number in [min, max]; `unit` goes into the message.
  std::optional<double> Number(const Json& obj, const std::string& key, const std::string& ptr, bool required,
                               double min, double max, const std::string& unit) {
    const Json* v = Field(obj, key, ptr, required);
    if (!v) return std::nullopt;
    const std::string p = ptr + "/" + Escape(key);
    if (!NumberIn(*v, min, max)) {
      Problem(p, "must be a number in " + Range(min, max, unit), *v);
      return std::nullopt;
    }
    return v->get<double>();
  }

  // True for an integer in [min, max], whether stored signed or unsigned (never wrapped).
  static bool IntegerIn(const Json& v, int64_t min, int64_t max) {
    if (v.is_number_unsigned()) return v.get<uint64_t>() <= static_cast<uint64_t>(std::max<int64_t>(max, 0)) &&
                                       static_cast<int64_t>(v.get<uint64_t>()) >= min;
    return v.is_number_integer() && v.get<int64_t>() >= min && v.get<int64_t>() <= max;
  }
  static bool NumberIn(const Json& v, double min, double max) {
    if (!v.is_number()) return false;
    const double x = v.get<double>();
    return std::isfinite(x) && x >= min && x <= max;
  }

  // A string of at most `max_chars` bytes; `one_line`: without control characters (names, keys, paths).
  std::optional<std::string> Text(const Json& obj, const std::string& key, const std::string& ptr, bool required,
                                  size_t max_chars, bool one_line) {
    const auto s = String(obj, key, ptr, required);
    if (!s) return std::nullopt;
    const std::string p = ptr + "/" + Escape(key);
    if (s->size() > max_chars) {
      Problem(p, "must be at most " + std::to_string(max_chars) + " characters, got " + std::to_string(s->size()));
      return std::nullopt;
    }
    if (one_line && !IsPrintableUtf8(*s)) {
      Problem(p, "must not contain control characters (line breaks, tabs, NUL)", Json(*s));
      return std::nullopt;
    }
    return s;
  }

  std::optional<bool> Bool(const Json& obj, const std::string& key, const std::string& ptr) {
    const Json* v = Field(obj, key, ptr, false);
    if (!v) return std::nullopt;
    if (!v->is_boolean()) {
      Problem(ptr + "/" + Escape(key), "must be true or false", *v);
      return std::nullopt;
    }
    return v->get<bool>();
  }

  // A path relative to the protocol file's folder; checked for existence unless options say otherwise.
  fs::path Path(const Json& obj, const std::string& key, const std::string& ptr, bool required) {
    const auto s = Text(obj, key, ptr, required, kMaxPathChars, true);
    if (!s) return {};
    if (s->empty()) {
      Problem(ptr + "/" + Escape(key), "must name a file", Json(*s));
      return {};
    }
    const fs::path resolved = (base_ / *s).lexically_normal();
    if (options_.check_files) CheckFile(resolved, ptr + "/" + Escape(key), Json(*s));
    return resolved;
  }

  // A regular file: not missing, not a folder, not a device (/dev/zero) or FIFO that a reader would wait on.
  // What is in it (an image that decodes, a calibration that parses) is checked before a session: PrepareSession.
  bool CheckFile(const fs::path& resolved, const std::string& ptr, const Json& got) {
    std::error_code ec;
    const fs::file_status status = fs::status(resolved, ec);
    if (status.type() == fs::file_type::not_found)
      Problem(ptr, "no such file: " + resolved.string(), got);
    else if (ec)
      Problem(ptr, "cannot look at " + resolved.string() + ": " + ec.message(), got);
    else if (status.type() == fs::file_type::directory)
      Problem(ptr, "is a folder, not a file: " + resolved.string(), got);
    else if (status.type() != fs::file_type::regular)
      Problem(ptr, "is not a regular file (a device, FIFO or socket): " + resolved.string(), got);
    else
      return true;
    return false;
  }

  Protocol Parse(const Json& json);

 private:
  void ParseScene(const Json& v, const std::string& ptr, Protocol* p);
  void ParseContent(const Json& v, const std::string& ptr, Protocol* p);
  std::vector<Factor> ParseFactors(const Json& v, const std::string& ptr);
  void CheckLevelValue(const std::string& name, const Json& v, const std::string& ptr);
  std::optional<Adjustment> ParseAdjust(const Json& v, const std::string& ptr);
  void ParseRealCamera(const Json& v, const std::string& ptr, const Json& content, Protocol* p);
  std::optional<Procedure> ParseProcedure(const Json& v, const std::string& ptr);
  std::vector<Factor> ParseConditions(const Json& v, const std::string& ptr);
  void ParseInfo(const Json& v, const std::string& ptr, Protocol* p);
  void ParseGroups(const Json& v, const Json& top, const std::string& ptr, Protocol* p);
  void ParseSides(const Json& v, const std::string& ptr);
  // Fills `b` from `obj` at `ptr`, falling back to the protocol-level defaults in `top`.
  void ParseBlock(const Json& obj, const std::string& ptr, const Json& top, Block* b);
  void ParseResponses(const Json& v, const std::string& ptr, const std::set<Task>& tasks, const Protocol& p,
                      Responses* r);
  void CheckDesign(const Protocol& p);
  static bool Provides(const Block& b, const std::string& name);

  fs::path file_, base_;
  ValidateOptions options_;
  std::set<std::string> reported_;
  size_t calls_ = 0;  // problems found, repeats included
};

void Parser::ParseScene(const Json& v, const std::string& ptr, Protocol* p) {
  if (!Object(v, ptr, {"background", "board_free", "calib", "show"})) return;
  p->scene.background = Path(v, "background", ptr, true);
  p->scene.board_free = Path(v, "board_free", ptr, false);
  p->scene.calib = Path(v, "calib", ptr, false);
  if (auto show = String(v, "show", ptr, false, {"background", "board_free"})) p->scene.show = *show;
  if (p->scene.show == "board_free" && !v.contains("board_free"))
    Problem(ptr + "/show", "names the board-free photo but /scene/board_free is missing", v["show"]);
}

void Parser::ParseContent(const Json& v, const std::string& ptr, Protocol* p) {
  if (!v.is_object()) {
    Problem(ptr, "must be an object", v);
    return;
  }
  const auto type = String(v, "type", ptr, true, {"grid", "ball", "picture"});
  if (!type) return;
  p->content.type = *type;
  if (*type == "grid" || *type == "ball") {
    if (auto k = String(v, "kernel", ptr, false, {"gaussian", "disc"})) p->content.kernel = *k;
    // The thesis matched the virtual object to the scene by eye; a factor of 4 either way is far beyond that.
    if (auto x = Number(v, "brightness", ptr, false, 0.25, 4, "(a factor)")) p->content.brightness = *x;
    if (auto x = Number(v, "contrast", ptr, false, 0.25, 4, "(a factor)")) p->content.contrast = *x;
    if (const Json* t = Field(v, "depth_blur_threshold", ptr, false)) {
      const std::string at = ptr + "/depth_blur_threshold";
      if (t->is_object() && t->size() == 1 && (t->contains("screen_px") || t->contains("arcmin"))) {
        const bool px = t->contains("screen_px");
        if (auto x = Number(*t, px ? "screen_px" : "arcmin", at, true, 0, px ? 100 : 600, px ? "screen px" : "arcmin"))
          p->content.depth_blur_threshold = *x, p->content.depth_blur_threshold_unit = px ? "screen_px" : "arcmin";
      } else {
        Problem(at, "must be {\"screen_px\": N} or {\"arcmin\": N}", *t);
      }
    }
    if (const Json* wb = Field(v, "white_balance", ptr, false)) {
      if (wb->is_array() && wb->size() == 3 && std::all_of(wb->begin(), wb->end(), [](const Json& g) {
            return NumberIn(g, 0.25, 4);
          }))
        for (size_t c = 0; c < 3; ++c) p->content.white_balance[c] = (*wb)[c].get<double>();
      else
        Problem(ptr + "/white_balance", "must be [red, green, blue] gains, each in " + Range(0.25, 4, "(a factor)"),
                *wb);
    }
  }
  if (*type == "grid" || *type == "ball") {
    // The card's face or the ball's surface: a shipped texture by name, or an image file.
    const bool grid = *type == "grid";
    p->content.texture = grid ? "grid" : "soccer";
    if (auto t = Text(v, "texture", ptr, false, kMaxPathChars, true)) {
      if (grid ? *t == "grid" : (*t == "soccer" || *t == "wood")) p->content.texture = *t;
      else p->content.texture = Path(v, "texture", ptr, true).string();
    }
  }
  if (*type == "grid" || *type == "ball") {
    // Raised above the table: up to a metre.
    if (auto h = Number(v, "height_mm", ptr, false, 0, 1000, "mm")) p->content.height_mm = *h;
  }
  if (*type == "grid") {
    Object(v, ptr, {"type", "cells", "texture", "kernel", "brightness", "contrast", "white_balance",
                    "depth_blur_threshold", "size_mm", "pose", "rotation_deg", "height_mm"});
    if (auto n = Int(v, "cells", ptr, false, 1, 20, "cells per side")) p->content.cells = *n;
    if (v.contains("cells") && p->content.texture != "grid")
      Problem(ptr + "/cells", "draws the grid card; an image texture has no cells", v["cells"]);
    // A card from 5 mm to half a metre: one side (a square), or [width, height].
    if (const Json* size = Field(v, "size_mm", ptr, false)) {
      if (NumberIn(*size, 5, 500))
        p->content.size_mm = size->get<double>();
      else if (size->is_array() && size->size() == 2 && NumberIn((*size)[0], 5, 500) && NumberIn((*size)[1], 5, 500))
        p->content.size_mm = (*size)[0].get<double>(), p->content.card_height_mm = (*size)[1].get<double>();
      else
        Problem(ptr + "/size_mm", "must be the card's side in " + Range(5, 500, "mm") + " or [width, height]", *size);
    }
    if (auto pose = String(v, "pose", ptr, false, {"lying", "standing"})) p->content.standing = *pose == "standing";
    if (auto r = Number(v, "rotation_deg", ptr, false, -180, 180, "deg")) p->content.rotation_deg = *r;
  } else if (*type == "ball") {
    Object(v, ptr, {"type", "texture", "radius_mm", "kernel", "brightness", "contrast", "white_balance",
                    "depth_blur_threshold", "height_mm"});
    // A ball rolls on the board's 25 mm squares: from a marble to a football.
    if (auto r = Number(v, "radius_mm", ptr, false, 1, 150, "mm")) p->content.radius_mm = *r;
  } else {
    Object(v, ptr, {"type", "image", "real_photos", "real_camera"});
    p->content.image = Path(v, "image", ptr, true);
    if (auto pattern = Text(v, "real_photos", ptr, false, kMaxPathChars, true)) {
      if (pattern->find("{distance_m}") == std::string::npos)
        Problem(ptr + "/real_photos", "must contain {distance_m} (one photo per distance)", Json(*pattern));
      else
        p->content.real_photos = (base_ / *pattern).lexically_normal().string();
    }
    if (const Json* real = Field(v, "real_camera", ptr, false)) ParseRealCamera(*real, ptr + "/real_camera", v, p);
  }
}

// content.real_camera: the camera (camera.json) that took the real photos and its focus distance.
void Parser::ParseRealCamera(const Json& v, const std::string& ptr, const Json& content, Protocol* p) {
  if (!content.contains("real_photos")) {
    Problem(ptr, "describes the camera of content.real_photos, which this protocol does not name", v);
    return;
  }
  if (!Object(v, ptr, {"camera", "focus_m"})) return;
  const size_t problems_before = calls_;
  p->content.real_camera_file = Path(v, "camera", ptr, true);
  const bool camera_file_ok = calls_ == problems_before;
  // From a hand's breadth to a kilometre (the thin lens needs it beyond the focal length: checked per distance).
  if (auto focus = Number(v, "focus_m", ptr, true, 0.01, 1000, "m")) p->content.real_focus_m = *focus;
  if (!options_.check_files || p->content.real_camera_file.empty() || !camera_file_ok) return;
  try {
    p->content.real_camera = LoadCamera(p->content.real_camera_file);
  } catch (const Error& e) {
    Problem(ptr + "/camera", e.what(), v["camera"]);
  }
}

// Checks a value by the name it goes by (a factor's name, or a key of an object level).
void Parser::CheckLevelValue(const std::string& name, const Json& v, const std::string& ptr) {
  auto integer_in = [&](int lo, int hi, const std::string& what) {
    if (!IntegerIn(v, lo, hi)) Problem(ptr, what + " must be an integer in " + Range(lo, hi, ""), v);
  };
  auto number_in = [&](double lo, double hi, const std::string& unit, const std::string& what) {
    if (!NumberIn(v, lo, hi)) Problem(ptr, what + " must be a number in " + Range(lo, hi, unit), v);
  };
  if (name == "edge" || name == "from_edge" || name == "to_edge") integer_in(1, kEdges, "an edge");
  else if (name == "section") integer_in(1, kEdges - 1, "a section (edge s to s + 1)");
  // A place on the board in mm (x across it from its left edge, y along it from edge 1): up to 10 m away.
  else if (name == "y_mm" || name == "from_y_mm" || name == "to_y_mm" || name == "left_x_mm" || name == "right_x_mm")
    number_in(-10000, 10000, "mm", "a place on the board");
  // The thesis rolled at 1.8 and 3 cm/s; 1 mm/s takes 4 minutes over the board, 1 m/s a quarter second.
  else if (name == "speed_cm_s") number_in(0.1, 100, "cm/s", "a speed");
  else if (name == "height_mm") number_in(0, 1000, "mm", "a height above the table");
  else if (name == "rotation_deg") number_in(-180, 180, "deg", "a rotation about the vertical");
  else if (name == "distance_m") number_in(0.1, 100, "m", "a distance");
  // Cycles per picture width; 0 shows the picture unfiltered.
  else if (name == "cutoff") number_in(0, 1000, "cycles per picture width", "a cut-off");
  else if (name == "left" || name == "right" || name == "object") {
    if (!IsBlurSource(v))
      Problem(ptr, "a blur source must be none, measured, measured_section, estimated, fitted, a radius in " +
                       Range(0, kMaxFixedRadiusPx, "photo px") + ", {\"screen_px\": r} with r in " +
                       Range(0, kMaxFixedRadiusPx, "") + " or {\"arcmin\": r} with r in " + Range(0, 600, ""), v);
  } else if (v.is_number() && !std::isfinite(v.get<double>())) {
    Problem(ptr, "must be a finite number", v);
  }
}

std::vector<Factor> Parser::ParseFactors(const Json& v, const std::string& ptr) {
  std::vector<Factor> factors;
  if (!v.is_object()) {
    Problem(ptr, "must be an object mapping factor names to lists of levels", v);
    return factors;
  }
  if (v.empty()) Problem(ptr, "must name at least one factor", v);
  if (v.size() > kMaxFactors) {
    Problem(ptr, "may name at most " + std::to_string(kMaxFactors) + " factors, got " + std::to_string(v.size()));
    return factors;
  }
  int carrying_sides = 0;
  for (const auto& [name, levels] : v.items()) {
    const std::string fp = ptr + "/" + Escape(name);
    if (name.empty() || name.size() > kMaxNameChars || !IsPrintableUtf8(name)) {
      Problem(fp, "a factor name must be 1 to " + std::to_string(kMaxNameChars) +
                      " characters without control characters", Json(name));
      continue;
    }
    if (!levels.is_array()) {
      Problem(fp, "must be a list of levels", levels);
      continue;
    }
    if (levels.empty()) {
      Problem(fp, "must list at least one level", levels);
      continue;
    }
    if (levels.size() > kMaxLevels) {
      Problem(fp, "may list at most " + std::to_string(kMaxLevels) + " levels, got " + std::to_string(levels.size()));
      continue;
    }
    Factor f{name, {}};
    bool sides = false;
    std::map<std::string, size_t> seen;  // a level's text -> its first index
    for (size_t i = 0; i < levels.size(); ++i) {
      const Json& level = levels[i];
      const std::string lp = fp + "/" + std::to_string(i);
      if (!level.is_number() && !level.is_string() && !level.is_object()) {
        Problem(lp, "a level must be a number, a string or an object", level);
        continue;
      }
      // Repeats found by the text of each level (numbers by value: 2 and 2.0 are one level), in linear time.
      const std::string text = level.is_number() ? Json(level.get<double>()).dump() : level.dump();
      if (const auto [first, fresh] = seen.emplace(text, i); !fresh)
        Problem(lp, "repeats level " + std::to_string(first->second), level);
      // A factor named for a value (edge, speed_cm_s, ...) holds that value itself; any other factor's object
      // levels carry named values.
      if (level.is_object() && !IsValueName(name)) {
        for (const auto& [key, value] : level.items()) {
          if (value.is_object() || value.is_array()) Problem(lp + "/" + Escape(key), "must be a number or a string", value);
          else CheckLevelValue(key, value, lp + "/" + Escape(key));
        }
        const bool l = level.contains("left"), r = level.contains("right");
        if (l != r) Problem(lp, std::string("has \"") + (l ? "left" : "right") + "\" but no \"" + (l ? "right" : "left") + "\"", level);
        if (level.contains("object") && (l || r))
          Problem(lp, "has an \"object\" (layout single) and left/right (a pair): give one or the other", level);
        if ((l && r) || level.contains("object")) sides = true;
        if (level.contains("from_edge") && level.contains("to_edge") && level["from_edge"].is_number_integer() &&
            level["to_edge"].is_number_integer() && level["from_edge"] == level["to_edge"])
          Problem(lp, "from_edge and to_edge must differ", level);
      } else {
        CheckLevelValue(name, level, lp);
      }
      f.levels.push_back(level);
    }
    if (sides) ++carrying_sides;
    factors.push_back(std::move(f));
  }
  if (carrying_sides > 1) Problem(ptr, "at most one factor may carry left and right", v);
  return factors;
}

std::optional<Adjustment> Parser::ParseAdjust(const Json& v, const std::string& ptr) {
  if (!Object(v, ptr, {"parameter", "levels", "order"})) return std::nullopt;
  Adjustment a;
  // The renderer steps through Butterworth cut-offs of a picture; no other parameter is drawn.
  if (auto s = String(v, "parameter", ptr, false, {"cutoff"})) a.parameter = *s;
  if (auto s = String(v, "order", ptr, false, {"shuffled", "ascending", "descending"})) a.order = *s;
  const Json* levels = Field(v, "levels", ptr, true);
  if (!levels) return a;
  if (!levels->is_array() || levels->size() < 2 || levels->size() > kMaxAdjustLevels) {
    Problem(ptr + "/levels", "must be a list of 2 to " + std::to_string(kMaxAdjustLevels) + " numbers", *levels);
    return a;
  }
  for (size_t i = 0; i < levels->size(); ++i) {
    const Json& x = (*levels)[i];
    const std::string lp = ptr + "/levels/" + std::to_string(i);
    if (!x.is_number()) {
      Problem(lp, "must be a number", x);
      continue;
    }
    CheckLevelValue(a.parameter, x, lp);
    if (std::find(a.levels.begin(), a.levels.end(), x.get<double>()) != a.levels.end())
      Problem(lp, "repeats an earlier level", x);
    a.levels.push_back(x.get<double>());
  }
  return a;
}

// A conditions table instead of factors: a CSV file whose header names the levels (edge, speed_cm_s, left, right,
// any label) and whose every row is one design row - for designs that are not full crossings. It becomes one factor
// "row" whose levels are the rows as objects (numbers read as numbers), checked like any level: a problem names
// /.../conditions/row/K/COLUMN, K counting the table's data rows from 0.
std::vector<Factor> Parser::ParseConditions(const Json& v, const std::string& ptr) {
  const auto text = Text(v, "conditions", ptr.substr(0, ptr.rfind('/')), true, kMaxPathChars, true);
  if (!text) return {};
  const fs::path file = (base_ / *text).lexically_normal();
  if (!CheckFile(file, ptr, Json(*text))) return {};
  std::string csv;
  try {
    csv = ReadTextFile(file);
  } catch (const std::exception& e) {
    Problem(ptr, e.what(), Json(*text));
    return {};
  }
  // Comma-separated, double quotes around a field that holds commas or quotes ("" for one quote); a field does not
  // span lines, so a quote still open at the line's end is an error (it used to swallow the rest of the line).
  struct Row {
    std::vector<std::string> fields{1};
    size_t line = 0;      // in the file, from 1
    bool closed = true;   // every quote closed
  };
  auto split = [](const std::string& line, size_t number) {
    Row row;
    row.line = number;
    bool quoted = false;
    for (size_t i = 0; i < line.size(); ++i) {
      const char c = line[i];
      if (quoted && c == '"' && i + 1 < line.size() && line[i + 1] == '"') row.fields.back() += '"', ++i;
      else if (c == '"') quoted = !quoted;
      else if (c == ',' && !quoted) row.fields.emplace_back();
      else row.fields.back() += c;
    }
    row.closed = !quoted;
    return row;
  };
  std::vector<Row> rows;
  size_t start = 0, number = 0;
  while (start <= csv.size()) {
    size_t end = csv.find('\n', start);
    if (end == std::string::npos) end = csv.size();
    std::string line = csv.substr(start, end - start);
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!line.empty()) rows.push_back(split(line, number));
    start = end + 1;
    if (rows.size() > size_t(kMaxTrials) + 1) break;
  }
  const std::string where = file.string();
  if (rows.size() < 2) {
    Problem(ptr, where + ": needs a header and at least one row", Json(*text));
    return {};
  }
  if (rows.size() > size_t(kMaxTrials) + 1) {
    Problem(ptr, where + ": more than " + std::to_string(kMaxTrials) + " rows", Json(*text));
    return {};
  }
  const std::string unclosed = ": a quoted field is not closed (a field cannot span lines; write \"\" for a quote)";
  if (!rows.front().closed) {
    Problem(ptr, where + " line " + std::to_string(rows.front().line) + unclosed, Json(*text));
    return {};
  }
  const std::vector<std::string>& header = rows.front().fields;
  std::set<std::string> names;
  for (const auto& name : header)
    if (name.empty() || name.size() > kMaxNameChars || !IsPrintableUtf8(name) || !names.insert(name).second) {
      Problem(ptr, where + ": the header must name each column once, 1-100 characters, got \"" + name + "\"",
              Json(*text));
      return {};
    }
  Factor factor;
  factor.name = "row";
  for (size_t r = 1; r < rows.size(); ++r) {
    const std::string rp = ptr + "/row/" + std::to_string(r - 1);
    const std::string line = where + " line " + std::to_string(rows[r].line);
    if (!rows[r].closed) {
      Problem(rp, line + unclosed, Json(*text));
      continue;
    }
    if (rows[r].fields.size() != header.size()) {
      Problem(rp, line + ": has " + std::to_string(rows[r].fields.size()) + " fields, the header " +
                      std::to_string(header.size()), Json(*text));
      continue;
    }
    Json level = Json::object();
    bool printable = true;
    for (size_t c = 0; c < header.size(); ++c) {
      const std::string& cell = rows[r].fields[c];
      const std::string cp = rp + "/" + Escape(header[c]);
      // A cell becomes a level, a label in the record, the tables and the report: text they can all hold as it
      // is. A Latin-1 byte or a NUL used to reach the record raw, or to stop validate with a JSON library error.
      if (!IsPrintableUtf8(cell)) {
        Problem(cp, line + ", column " + std::to_string(c + 1) + " (" + header[c] +
                        "): must be printable UTF-8 text (no control characters; save the file as UTF-8), got " +
                        Echo(cell));
        printable = false;
        continue;
      }
      const std::optional<double> number = ParseDecimal(cell);
      level[header[c]] = IsWholeDecimal(cell) && std::abs(*number) < 9e15 ? Json(int64_t(*number))
                         : number                                       ? Json(*number)
                                                                        : Json(cell);
      if (cell.empty()) Problem(cp, "is empty", Json(cell));
      else CheckLevelValue(header[c], level[header[c]], cp);
    }
    if (!printable) continue;
    factor.levels.push_back(std::move(level));
  }
  return {factor};
}

void Parser::ParseInfo(const Json& v, const std::string& ptr, Protocol* p) {
  if (!v.is_array() || v.size() > 20) {
    Problem(ptr, "must be a list of at most 20 fields ({\"key\": ..., \"type\": ...})", v);
    return;
  }
  std::set<std::string> keys;
  for (size_t i = 0; i < v.size(); ++i) {
    const std::string fp = ptr + "/" + std::to_string(i);
    const Json& f = v[i];
    if (!Object(f, fp, {"key", "type", "min", "max", "choices", "required", "prompt"})) continue;
    InfoField field;
    if (auto k = Text(f, "key", fp, true, 40, true)) {
      const bool ok = !k->empty() && std::all_of(k->begin(), k->end(), [](char c) {
        return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
      });
      if (!ok) Problem(fp + "/key", "must be 1-40 characters of a-z, 0-9 and _", Json(*k));
      else if (!keys.insert(*k).second) Problem(fp + "/key", "repeats an earlier key", Json(*k));
      field.key = *k;
    }
    if (auto t = String(f, "type", fp, false, {"integer", "number", "choice", "text"})) field.type = *t;
    const bool numeric = field.type == "integer" || field.type == "number";
    if (numeric) {
      auto lo = Number(f, "min", fp, true, -1e9, 1e9, ""), hi = Number(f, "max", fp, true, -1e9, 1e9, "");
      if (lo && hi && *lo >= *hi) Problem(fp + "/max", "must be larger than min", f["max"]);
      field.min = lo.value_or(0), field.max = hi.value_or(0);
    } else {
      for (const char* k : {"min", "max"})
        if (f.contains(k)) Problem(fp + "/" + k, "is for an integer or number field, not " + field.type, f[k]);
    }
    if (field.type == "choice") {
      const Json* c = Field(f, "choices", fp, true);
      if (c && (!c->is_array() || c->empty() || c->size() > 20))
        Problem(fp + "/choices", "must be a list of 1 to 20 answers", *c);
      else if (c)
        for (size_t k = 0; k < c->size(); ++k) {
          const Json& choice = (*c)[k];
          if (!choice.is_string() || choice.get<std::string>().empty() || choice.get<std::string>().size() > 100 ||
              !IsPrintableUtf8(choice.get<std::string>()) ||
              std::count(field.choices.begin(), field.choices.end(), choice.get<std::string>()))
            Problem(fp + "/choices/" + std::to_string(k), "must be a new answer of 1-100 characters", choice);
          else
            field.choices.push_back(choice.get<std::string>());
        }
    } else if (f.contains("choices")) {
      Problem(fp + "/choices", "is for a choice field, not " + field.type, f["choices"]);
    }
    if (auto r = Bool(f, "required", fp)) field.required = *r;
    if (auto s = Text(f, "prompt", fp, false, 200, true)) field.prompt = *s;
    p->participant_info.push_back(std::move(field));
  }
}

void Parser::ParseGroups(const Json& v, const Json& top, const std::string& ptr, Protocol* p) {
  if (!Object(v, ptr, {"names", "assign"})) return;
  Groups g;
  if (auto a = String(v, "assign", ptr, false, {"by_number", "balanced"})) g.assign = *a;
  const Json* names = Field(v, "names", ptr, true);
  if (names && (!names->is_array() || names->size() < 2 || names->size() > 20)) {
    Problem(ptr + "/names", "must be a list of 2 to 20 group names", *names);
    return;
  }
  if (names)
    for (size_t i = 0; i < names->size(); ++i) {
      const Json& n = (*names)[i];
      if (!n.is_string() || n.get<std::string>().empty() || n.get<std::string>().size() > kMaxNameChars ||
          !IsPrintableUtf8(n.get<std::string>()) ||
          std::count(g.names.begin(), g.names.end(), n.get<std::string>()))
        Problem(ptr + "/names/" + std::to_string(i), "must be a new name of 1-100 characters", n);
      else
        g.names.push_back(n.get<std::string>());
    }
  p->groups = g;
  (void)top;
}

std::optional<Procedure> Parser::ParseProcedure(const Json& v, const std::string& ptr) {
  if (!v.is_object()) {
    Problem(ptr, "must be an object (type staircase or quest_plus)", v);
    return std::nullopt;
  }
  const auto type = String(v, "type", ptr, true, {"staircase", "quest_plus"});
  if (!type) return std::nullopt;
  Procedure pr;
  pr.kind = *type == "quest_plus" ? Procedure::Kind::kQuestPlus : Procedure::Kind::kStaircase;
  const bool quest = pr.kind == Procedure::Kind::kQuestPlus;
  if (quest)
    Object(v, ptr, {"type", "variable", "reference", "trials", "stimuli", "threshold", "slope", "lapse", "guess"});
  else
    Object(v, ptr, {"type", "variable", "reference", "trials", "start", "min", "max", "up", "down", "steps", "stop"});
  if (auto s = String(v, "variable", ptr, true, {"relative_difference", "difference_arcmin"})) pr.variable = *s;
  // What the level can be: up to 20 times more blur, or up to 10 degrees more.
  const bool relative = pr.variable == "relative_difference";
  const double hi = relative ? 20 : 600;
  const std::string unit = relative ? "(times the reference)" : "arcmin";
  if (const Json* r = Field(v, "reference", ptr, true)) {
    CheckLevelValue("left", *r, ptr + "/reference");
    pr.reference = *r;
  }
  if (auto n = Int(v, "trials", ptr, true, 1, 1000, "trials per crossing")) pr.trials = *n;
  // A list of 1 to `most` numbers in [lo, hi], ascending when `ascending`.
  auto numbers = [&](const std::string& key, size_t most, double lo, double hi_, bool ascending,
                     std::vector<double>* out) {
    const Json* a = Field(v, key, ptr, true);
    if (!a) return;
    const std::string at = ptr + "/" + key;
    if (!a->is_array() || a->empty() || a->size() > most) {
      Problem(at, "must be a list of 1 to " + std::to_string(most) + " numbers", *a);
      return;
    }
    for (size_t i = 0; i < a->size(); ++i) {
      const Json& x = (*a)[i];
      if (!NumberIn(x, lo, hi_)) {
        Problem(at + "/" + std::to_string(i), "must be a number in " + Range(lo, hi_, ""), x);
        return;
      }
      if (ascending && !out->empty() && x.get<double>() <= out->back()) {
        Problem(at + "/" + std::to_string(i), "must be larger than the one before (ascending, no repeats)", x);
        return;
      }
      out->push_back(x.get<double>());
    }
  };
  if (quest) {
    numbers("stimuli", 200, 0, hi, true, &pr.stimuli);
    numbers("threshold", 100, 1e-6, hi, true, &pr.thresholds);
    numbers("slope", 50, 0.1, 50, true, &pr.slopes);
    numbers("lapse", 20, 0, 0.5, true, &pr.lapses);
    if (auto g = Number(v, "guess", ptr, false, 0, 0.99, "")) pr.guess = *g, pr.guess_given = true;
    const double grid = double(pr.thresholds.size()) * double(pr.slopes.size()) * double(pr.lapses.size());
    if (grid * double(pr.stimuli.size()) > 2e6)
      Problem(ptr, "the parameter grid (" + std::to_string(int64_t(grid)) + " points) x " +
                       std::to_string(pr.stimuli.size()) + " stimuli exceeds 2,000,000 (each trial weighs all)");
    for (double lapse : pr.lapses)
      if (pr.guess + lapse >= 1) Problem(ptr + "/lapse", "guess + lapse must be below 1", Json(lapse));
  } else {
    if (auto x = Number(v, "min", ptr, true, 0, hi, unit)) pr.min = *x;
    if (auto x = Number(v, "max", ptr, true, 0, hi, unit)) pr.max = *x;
    if (auto x = Number(v, "start", ptr, true, 0, hi, unit)) pr.start = *x;
    if (pr.min >= pr.max) Problem(ptr + "/max", "must be larger than min", v.value("max", Json()));
    else if (pr.start < pr.min || pr.start > pr.max)
      Problem(ptr + "/start", "must lie in [min, max]", v.value("start", Json()));
    if (auto n = Int(v, "up", ptr, false, 1, 5, "wrong answers in a row")) pr.up = *n;
    if (auto n = Int(v, "down", ptr, false, 1, 5, "correct answers in a row")) pr.down = *n;
    numbers("steps", 20, 1e-6, hi, false, &pr.steps);
    // A stop rule: the staircase ends after this many reversals; its remaining trials are recorded as skipped.
    if (const Json* stop = Field(v, "stop", ptr, false)) {
      if (Object(*stop, ptr + "/stop", {"reversals"}))
        if (auto n = Int(*stop, "reversals", ptr + "/stop", true, 1, 100, "reversals")) {
          pr.stop_reversals = *n;
          if (*n >= pr.trials)
            Problem(ptr + "/stop/reversals", "can never be reached within " + std::to_string(pr.trials) +
                                                 " trials (a reversal needs a trial)", Json(*n));
        }
    }
  }
  return pr;
}

void Parser::ParseSides(const Json& v, const std::string& ptr) {
  // The single layout shows one "object"; the others a pair, left and right.
  if (v.is_object() && v.contains("object")) {
    if (Object(v, ptr, {"object"})) CheckLevelValue("object", v["object"], ptr + "/object");
    return;
  }
  if (!Object(v, ptr, {"left", "right", "object"})) return;
  for (const char* side : {"left", "right"}) {
    if (const Json* s = Field(v, side, ptr, true)) CheckLevelValue(side, *s, ptr + "/" + side);
  }
}

void Parser::ParseBlock(const Json& obj, const std::string& ptr, const Json& top, Block* b) {
  // A field of the block, else of the protocol: the object that holds it and that object's pointer. Inherited
  // fields are checked again per block; Problem() keeps each message once.
  struct Source {
    const Json* holder = nullptr;
    std::string ptr;
  };
  auto pick = [&](const std::string& key) -> Source {
    if (obj.is_object() && obj.contains(key)) return {&obj, ptr};
    if (top.is_object() && top.contains(key)) return {&top, ""};
    return {};
  };
  if (const Source s = pick("task"); !s.holder) {
    Problem(ptr + "/task", "is required (here or at /task) but missing");
  } else if (b->task_pointer = s.ptr + "/task";
             auto t = String(*s.holder, "task", s.ptr, true, {"forced_choice", "adjustment", "yes_no", "rating"})) {
    b->task = *t == "adjustment" ? Task::kAdjustment
              : *t == "yes_no"   ? Task::kYesNo
              : *t == "rating"   ? Task::kRating
                                 : Task::kForcedChoice;
  }
  b->pointer = ptr;
  const size_t calls_before_factors = calls_;
  const Source factors = pick("factors"), conditions = pick("conditions");
  if (factors.holder && conditions.holder)
    Problem(conditions.ptr + "/conditions", "give either factors or a conditions table, not both",
            (*conditions.holder)["conditions"]);
  else if (conditions.holder)
    b->factors = ParseConditions(*conditions.holder, conditions.ptr + "/conditions"),
    b->factors_pointer = conditions.ptr + "/conditions";
  else if (!factors.holder)
    Problem(ptr + "/factors", "is required (here or at /factors; or a conditions table) but missing");
  else
    b->factors = ParseFactors((*factors.holder)["factors"], factors.ptr + "/factors"),
    b->factors_pointer = factors.ptr + "/factors";
  const bool factors_ok = calls_ == calls_before_factors;
  if (const Source s = pick("repetitions"); s.holder) {
    if (auto n = Int(*s.holder, "repetitions", s.ptr, true, 1, kMaxTrials, "repetitions")) b->repetitions = *n;
  }
  if (const Source s = pick("counterbalance"); s.holder) {
    b->counterbalance_pointer = s.ptr + "/counterbalance";
    if (auto c = String(*s.holder, "counterbalance", s.ptr, true, {"swap_copies", "by_participant", "none"}))
      b->counterbalance = *c == "swap_copies"      ? Counterbalance::kSwapCopies
                          : *c == "by_participant" ? Counterbalance::kByParticipant
                                                   : Counterbalance::kNone;
  }
  const Source sides = pick("sides");
  if (sides.holder) {
    ParseSides((*sides.holder)["sides"], sides.ptr + "/sides");
    b->sides = (*sides.holder)["sides"];
    b->sides_pointer = sides.ptr + "/sides";
  }
  const Source adjust = pick("adjust");
  if (adjust.holder && b->task == Task::kAdjustment)
    b->adjust = ParseAdjust((*adjust.holder)["adjust"], adjust.ptr + "/adjust");
  if (obj.is_object() && obj.contains("procedure")) {
    b->procedure = ParseProcedure(obj["procedure"], ptr + "/procedure");
    // The procedure says what each side shows and how often: the design fields that would say it too are refused.
    if (b->task != Task::kForcedChoice)
      Problem(b->task_pointer, "must be forced_choice for a procedure (which side is more blurred?)",
              Json(ToString(b->task)));
    if (sides.holder) Problem(sides.ptr + "/sides", "is given but the procedure shows its reference on both sides",
                              (*sides.holder)["sides"]);
    if (b->repetitions != 1) Problem(ptr + "/procedure/trials", "sets how often each crossing runs: leave out "
                                                                "repetitions", Json(b->repetitions));
    if (b->counterbalance != Counterbalance::kNone)
      Problem(b->counterbalance_pointer, "must be none for a procedure (the test side is drawn at random per trial)",
              Json(ToString(b->counterbalance)));
  }
  if (auto s = Text(obj, "instructions", ptr, false, kMaxTextChars, false)) b->instructions = *s;
  if (auto s = Bool(obj, "shuffle", ptr)) b->shuffle = *s;
  if (auto s = Bool(obj, "practice", ptr)) b->practice = *s;
  // Practice until a criterion: the share correct in one run of the design, and how many runs at most.
  if (const Json* c = Field(obj, "criterion", ptr, false)) {
    const std::string at = ptr + "/criterion";
    if (Object(*c, at, {"correct", "max_repeats"})) {
      Block::Criterion criterion;
      if (auto x = Number(*c, "correct", at, true, 0.01, 1, "")) criterion.correct = *x;
      if (auto n = Int(*c, "max_repeats", at, true, 2, 20, "runs of the design")) criterion.max_repeats = *n;
      b->criterion = criterion;
    }
    if (!b->practice) Problem(at, "is for a practice block (\"practice\": true): a scored block runs once", *c);
    if (b->task != Task::kForcedChoice || b->procedure)
      Problem(at, "needs answers that are right or wrong: a forced choice without a procedure", *c);
  }
  if (const Json* g = Field(obj, "groups", ptr, false)) {
    if (!g->is_array() || g->empty())
      Problem(ptr + "/groups", "must be a list of the protocol's group names", *g);
    else
      for (size_t i = 0; i < g->size(); ++i) {
        if ((*g)[i].is_string()) b->groups.push_back((*g)[i].get<std::string>());
        else Problem(ptr + "/groups/" + std::to_string(i), "must be a group name", (*g)[i]);
      }
  }

  // What is shown left and right must be known for a comparison, and for any left/right counterbalancing.
  bool factor_sides = false;
  for (const auto& f : b->factors)
    for (const auto& level : f.levels)
      factor_sides = factor_sides || (level.is_object() && (level.contains("left") || level.contains("object")));
  const std::string where = ptr.empty() ? "/" : ptr;
  if (factor_sides && sides.holder)
    Problem(sides.ptr + "/sides", "is given but a factor's levels already carry the sides (left and right, or object)",
            (*sides.holder)["sides"]);
  const bool needs_sides =
      !b->procedure && (b->task == Task::kForcedChoice || b->counterbalance != Counterbalance::kNone);
  if (needs_sides && factors_ok && !factor_sides && !sides.holder)
    Problem(where, "needs what is shown left and right: a \"sides\" object or a factor whose levels have left and "
                   "right (a forced choice or left/right counterbalancing compares two sides)");
  if ((b->task == Task::kYesNo || b->task == Task::kRating) && factors_ok && !factor_sides && !sides.holder)
    Problem(where, "needs the object shown: \"sides\": {\"object\": SOURCE} or a factor whose levels have an object "
                   "(a " + ToString(b->task) + " trial shows one object)");
  if (b->task == Task::kAdjustment && !adjust.holder)
    Problem(ptr + "/adjust", "is required for the adjustment task (here or at /adjust) but missing");
}

void Parser::ParseResponses(const Json& v, const std::string& ptr, const std::set<Task>& tasks, const Protocol& p,
                            Responses* r) {
  // Defaults that suit a keyboard: arrows to choose or step, Return to accept, Y / N, digits for scales and intervals.
  *r = Responses{};
  r->left = "Left", r->right = "Right", r->cant_tell = "Down", r->previous = "Left", r->next = "Right",
  r->accept = "Return";
  r->rating = {"1", "2", "3", "4", "5"};
  for (int i = 1; i <= p.alternatives; ++i) r->alternatives.push_back(std::to_string(i));
  // Odd one out names one of its intervals: there is no "can't tell" unless a key is given for it.
  if (p.layout == "odd_one_out") r->cant_tell = "";
  if (v.is_null()) return;
  if (!Object(v, ptr, {"left", "right", "cant_tell", "previous", "next", "accept", "yes", "no", "rating",
                       "alternatives", "prompt", "after_motion"}))
    return;
  auto key_name = [&](const Json& value, const std::string& at) -> std::optional<std::string> {
    if (!value.is_string()) return Problem(at, "must be a key name", value), std::nullopt;
    const std::string s = value.get<std::string>();
    if (s == "Escape") return Problem(at, "Escape is reserved for pausing a session", value), std::nullopt;
    if (!IsKeyName(s))
      return Problem(at, "must be a key name: A-Z, 0-9, Left, Right, Up, Down, Space, Return, Tab, Backspace, F1-F12 "
                         "or KP_0-KP_9", value), std::nullopt;
    return s;
  };
  std::map<std::string, std::string*> slots = {{"left", &r->left},         {"right", &r->right},
                                               {"cant_tell", &r->cant_tell}, {"previous", &r->previous},
                                               {"next", &r->next},         {"accept", &r->accept},
                                               {"yes", &r->yes},           {"no", &r->no}};
  for (auto& [key, slot] : slots) {
    if (!v.contains(key)) continue;
    // "cant_tell": null makes a strict 2AFC: no key answers can't tell.
    if (key == "cant_tell" && v[key].is_null()) {
      *slot = "";
      continue;
    }
    if (auto s = key_name(v[key], ptr + "/" + key)) *slot = *s;
  }
  // Key lists: one key per point of a rating scale (2 to 9), one per interval of an odd-one-out trial.
  auto key_list = [&](const char* key, size_t min, size_t max, std::vector<std::string>* out) {
    if (!v.contains(key)) return;
    const Json& list = v[key];
    const std::string at = ptr + "/" + key;
    if (!list.is_array() || list.size() < min || list.size() > max)
      return Problem(at, "must be a list of " + std::to_string(min) + (min == max ? "" : " to " + std::to_string(max)) +
                             " key names", list);
    out->clear();
    for (size_t i = 0; i < list.size(); ++i)
      if (auto s = key_name(list[i], at + "/" + std::to_string(i))) out->push_back(*s);
  };
  key_list("rating", 2, 9, &r->rating);
  key_list("alternatives", size_t(std::max(p.alternatives, 1)), size_t(std::max(p.alternatives, 1)), &r->alternatives);
  if (auto s = Text(v, "prompt", ptr, false, 200, true)) {
    if (s->empty()) Problem(ptr + "/prompt", "must not be empty (leave it out for no prompt)", Json(*s));
    r->prompt = *s;
  }
  if (auto b = Bool(v, "after_motion", ptr)) r->after_motion = *b;
  // Keys for a task no block has would be read by nothing.
  auto unused = [&](const char* key, bool used, const std::string& why) {
    if (v.contains(key) && !used) Problem(ptr + "/" + key, why, v[key]);
  };
  unused("yes", tasks.count(Task::kYesNo), "is for the task yes_no, which no block has");
  unused("no", tasks.count(Task::kYesNo), "is for the task yes_no, which no block has");
  unused("rating", tasks.count(Task::kRating), "is for the task rating, which no block has");
  unused("alternatives", p.layout == "odd_one_out", "is for the layout odd_one_out");
  const bool choice = tasks.count(Task::kForcedChoice) > 0, sides = choice && p.layout != "odd_one_out";
  unused("left", sides, choice ? "is not read by the layout odd_one_out (its intervals have /responses/alternatives)"
                               : "is for the task forced_choice, which no block has");
  unused("right", sides, choice ? "is not read by the layout odd_one_out (its intervals have /responses/alternatives)"
                                : "is for the task forced_choice, which no block has");
  unused("cant_tell", choice, "is for the task forced_choice, which no block has");
  for (const char* key : {"previous", "next", "accept"})
    unused(key, tasks.count(Task::kAdjustment) > 0, "is for the task adjustment, which no block has");
  auto distinct = [&](const std::vector<std::pair<std::string, std::string>>& set) {
    for (size_t i = 0; i < set.size(); ++i)
      for (size_t j = 0; j < i; ++j)
        if (set[i].second == set[j].second)
          Problem(ptr + "/" + set[i].first, "is the same key as /responses/" + set[j].first, Json(set[i].second));
  };
  if (tasks.count(Task::kForcedChoice))
    distinct(r->cant_tell.empty() ? std::vector<std::pair<std::string, std::string>>{{"left", r->left}, {"right", r->right}}
                                  : std::vector<std::pair<std::string, std::string>>{
                                        {"left", r->left}, {"right", r->right}, {"cant_tell", r->cant_tell}});
  if (tasks.count(Task::kAdjustment))
    distinct({{"previous", r->previous}, {"next", r->next}, {"accept", r->accept}});
  if (tasks.count(Task::kYesNo)) distinct({{"yes", r->yes}, {"no", r->no}});
  auto distinct_list = [&](const char* key, const std::vector<std::string>& keys) {
    for (size_t i = 0; i < keys.size(); ++i)
      for (size_t j = 0; j < i; ++j)
        if (keys[i] == keys[j])
          Problem(ptr + "/" + key + "/" + std::to_string(i), "is the same key as /responses/" + std::string(key) + "/" + std::to_string(j),
                  Json(keys[i]));
  };
  if (tasks.count(Task::kRating)) distinct_list("rating", r->rating);
  if (p.layout == "odd_one_out") distinct_list("alternatives", r->alternatives);
}

Protocol Parser::Parse(const Json& json) {
  Protocol p;
  p.file = file_;
  if (!Object(json, "",
              {"$schema", "name", "version", "description", "scene", "content", "task", "factors", "conditions",
               "repetitions", "counterbalance", "sides", "adjust", "blocks", "block_order", "practice", "instructions",
               "breaks", "responses", "timing", "display", "participant_info", "groups", "layout", "alternatives"}))
    return p;
  if (auto s = Text(json, "name", "", true, kMaxNameChars, true)) {
    if (s->empty()) Problem("/name", "must not be empty", Json(*s));
    p.name = *s;
  }
  if (auto n = Int(json, "version", "", true, 1, 1000000)) p.version = *n;
  if (auto s = Text(json, "description", "", false, 5 * kMaxTextChars, false)) p.description = *s;
  if (auto s = Text(json, "instructions", "", false, kMaxTextChars, false)) p.instructions = *s;
  if (const Json* v = Field(json, "content", "", true)) ParseContent(*v, "/content", &p);
  // A depth matching with real photos shows no scene photo: its lower half is the real photo of each distance.
  const bool real_photos = p.content.type == "picture" && json.contains("content") && json["content"].is_object() &&
                           json["content"].contains("real_photos");
  if (const Json* v = Field(json, "scene", "", !real_photos)) {
    if (real_photos)
      Problem("/scene", "is not shown: with content.real_photos the lower half shows the real photo of each distance", *v);
    else
      ParseScene(*v, "/scene", &p);
  }
  if (p.content.type == "picture" && json.contains("scene") && json["scene"].is_object() &&
      json["scene"].contains("calib"))
    Problem("/scene/calib", "is not read by a picture (the real picture's blur comes from /content/real_camera)",
            json["scene"]["calib"]);
  if (json.contains("scene") && json["scene"].is_object() && !json["scene"].contains("calib") &&
      (p.content.type == "grid" || p.content.type == "ball"))
    Problem("/scene/calib", "is required for a " + p.content.type + " (its blur comes from the calibration) but missing");

  // Protocol-level design fields are checked where they are written even when no block inherits them.
  if (json.contains("factors")) ParseFactors(json["factors"], "/factors");
  if (json.contains("sides")) ParseSides(json["sides"], "/sides");
  if (json.contains("adjust")) ParseAdjust(json["adjust"], "/adjust");
  if (json.contains("repetitions")) Int(json, "repetitions", "", true, 1, kMaxTrials, "repetitions");
  if (json.contains("counterbalance"))
    String(json, "counterbalance", "", true, {"swap_copies", "by_participant", "none"});
  if (json.contains("task")) String(json, "task", "", true, {"forced_choice", "adjustment", "yes_no", "rating"});

  const Json* blocks = Field(json, "blocks", "", false);
  if (!blocks) {
    Block b;
    b.name = "main";
    ParseBlock(Json::object(), "", json, &b);
    p.blocks.push_back(std::move(b));
  } else if (!blocks->is_array() || blocks->empty() || blocks->size() > kMaxBlocks) {
    Problem("/blocks", "must be a list of 1 to " + std::to_string(kMaxBlocks) + " blocks", *blocks);
  } else {
    for (size_t i = 0; i < blocks->size(); ++i) {
      const Json& obj = (*blocks)[i];
      const std::string bp = "/blocks/" + std::to_string(i);
      if (!Object(obj, bp, {"name", "task", "factors", "conditions", "repetitions", "counterbalance", "sides",
                            "adjust", "procedure", "instructions", "shuffle", "groups", "practice", "criterion"}))
        continue;
      Block b;
      if (auto s = Text(obj, "name", bp, true, kMaxNameChars, true)) {
        if (s->empty()) Problem(bp + "/name", "must not be empty", Json(*s));
        for (const auto& other : p.blocks)
          if (other.name == *s) Problem(bp + "/name", "repeats the name of an earlier block", Json(*s));
        b.name = *s;
      }
      ParseBlock(obj, bp, json, &b);
      p.blocks.push_back(std::move(b));
    }
  }

  if (const Json* v = Field(json, "practice", "", false)) {
    if (Object(*v, "/practice", {"count", "block", "instructions"})) {
      if (auto n = Int(*v, "count", "/practice", true, 0, 1000, "trials")) p.practice.count = *n;
      if (auto s = Text(*v, "instructions", "/practice", false, kMaxTextChars, false)) p.practice.instructions = *s;
      p.practice.block = p.blocks.empty() ? "" : p.blocks.front().name;
      if (auto s = String(*v, "block", "/practice", false)) {
        bool found = false;
        for (const auto& b : p.blocks) found = found || b.name == *s;
        if (!found) Problem("/practice/block", "names no block of this protocol", Json(*s));
        p.practice.block = *s;
      }
    }
  }
  if (auto order = String(json, "block_order", "", false, {"fixed", "random", "latin_square"}))
    p.block_order = *order;
  if (auto layout = String(json, "layout", "", false, {"side_by_side", "two_intervals", "single", "odd_one_out"})) {
    p.layout = *layout;
    if (p.layout != "side_by_side" && p.content.type == "picture")
      Problem("/layout", "is for grids and balls; a picture is shown in its depth-matching frame", Json(*layout));
  }
  if (p.layout == "odd_one_out") p.alternatives = 3;
  if (json.contains("alternatives")) {
    if (auto n = Int(json, "alternatives", "", true, 3, 6, "intervals")) p.alternatives = *n;
    if (p.layout != "odd_one_out")
      Problem("/alternatives", "is for the layout odd_one_out (the intervals of an odd-one-out trial)", json["alternatives"]);
  }
  // QUEST+'s guess rate is the chance of a right answer by guessing: 1/n of an odd-one-out trial's n intervals.
  if (p.layout == "odd_one_out")
    for (auto& b : p.blocks)
      if (b.procedure && b.procedure->kind == Procedure::Kind::kQuestPlus) {
        if (!b.procedure->guess_given) b.procedure->guess = 1.0 / p.alternatives;
        else if (std::abs(b.procedure->guess - 1.0 / p.alternatives) > 1e-3)
          Problem(b.pointer + "/procedure/guess", "an odd-one-out trial of " + std::to_string(p.alternatives) +
                                                      " intervals is guessed right 1/" + std::to_string(p.alternatives) +
                                                      " of the time; leave guess out", Json(b.procedure->guess));
      }
  if (const Json* v = Field(json, "participant_info", "", false)) ParseInfo(*v, "/participant_info", &p);
  if (const Json* v = Field(json, "groups", "", false)) ParseGroups(*v, json, "/groups", &p);
  if (const Json* v = Field(json, "breaks", "", false)) {
    if (Object(*v, "/breaks", {"every_trials", "text"})) {
      if (auto n = Int(*v, "every_trials", "/breaks", true, 1, kMaxTrials, "trials")) p.break_every_trials = *n;
      if (auto s = Text(*v, "text", "/breaks", false, kMaxTextChars, false)) p.break_text = *s;
    }
  }
  // The real photos: one per distance the design shows.
  if (!p.content.real_photos.empty() && options_.check_files) {
    const std::set<double> distances = NumericLevels(p, "distance_m");
    if (distances.empty())
      Problem("/content/real_photos", "needs a factor distance_m to choose the photo by", Json(p.content.real_photos));
    for (double d : distances) {
      std::error_code ec;
      if (const fs::path photo = RealPhotoFor(p.content, d); !fs::is_regular_file(photo, ec))
        Problem("/content/real_photos", "no photo for distance_m " + Json(d).dump() + ": " + photo.string(),
                json["content"]["real_photos"]);
    }
  }
  std::set<Task> tasks;
  for (const auto& b : p.blocks) tasks.insert(b.task);
  const Json* responses = Field(json, "responses", "", false);
  ParseResponses(responses ? *responses : Json(), "/responses", tasks, p, &p.responses);
  if (const Json* v = Field(json, "timing", "", false)) {
    if (Object(*v, "/timing", {"stimulus_ms", "inter_trial_ms", "interval_ms", "isi_ms", "deadline_ms", "feedback_ms",
                               "fixation_ms"})) {
      if (const Json* s = Field(*v, "stimulus_ms", "/timing", false)) {
        // From about a frame to a minute.
        if (s->is_string() && *s == "until_response") p.timing.stimulus_ms = 0;
        else if (NumberIn(*s, 10, 60000)) p.timing.stimulus_ms = s->get<double>();
        else Problem("/timing/stimulus_ms", "must be a duration in " + Range(10, 60000, "ms") + " or \"until_response\"", *s);
      }
      if (auto x = Number(*v, "inter_trial_ms", "/timing", false, 0, 60000, "ms")) p.timing.inter_trial_ms = *x;
      if (auto x = Number(*v, "interval_ms", "/timing", false, 100, 10000, "ms")) p.timing.interval_ms = *x;
      if (auto x = Number(*v, "isi_ms", "/timing", false, 0, 10000, "ms")) p.timing.isi_ms = *x;
      if (auto x = Number(*v, "deadline_ms", "/timing", false, 100, 60000, "ms")) p.timing.deadline_ms = *x;
      if (auto x = Number(*v, "feedback_ms", "/timing", false, 100, 5000, "ms")) p.timing.feedback_ms = *x;
      if (auto x = Number(*v, "fixation_ms", "/timing", false, 100, 5000, "ms")) p.timing.fixation_ms = *x;
      // Feedback needs a correct answer: a procedure's, an odd one out's, or a practice run to a criterion's.
      const bool correct = p.layout == "odd_one_out" ||
                           std::any_of(p.blocks.begin(), p.blocks.end(),
                                       [](const Block& b) { return b.procedure || b.criterion; });
      if (v->contains("feedback_ms") && !correct)
        Problem("/timing/feedback_ms", "needs a correct answer: a block with a procedure or a criterion, or the "
                                       "layout odd_one_out, defines one", (*v)["feedback_ms"]);
      const bool adjustment = std::any_of(p.blocks.begin(), p.blocks.end(),
                                          [](const Block& b) { return b.task == Task::kAdjustment; });
      if (v->contains("deadline_ms") && adjustment)
        Problem("/timing/deadline_ms", "is for a forced choice, yes/no or rating; adjustment runs until a level is "
                                       "accepted", (*v)["deadline_ms"]);
      for (const char* key : {"interval_ms", "isi_ms"})
        if (v->contains(key) && IntervalCount(p) == 0)
          Problem(std::string("/timing/") + key, "is for the layouts two_intervals and odd_one_out", (*v)[key]);
      if (v->contains("stimulus_ms") && IntervalCount(p) > 0)
        Problem("/timing/stimulus_ms", "intervals are timed by interval_ms and isi_ms", (*v)["stimulus_ms"]);
    }
  }
  if (const Json* v = Field(json, "display", "", false)) {
    if (Object(*v, "/display", {"width_px", "height_px", "fullscreen", "monitor", "profile", "scale", "width_deg"})) {
      // From VGA's 320 x 240 to 4K UHD (a depth-matching frame as wide as the display is filtered on the CPU).
      if (auto n = Int(*v, "width_px", "/display", false, 320, 3840, "px")) p.display.width_px = *n;
      if (auto n = Int(*v, "height_px", "/display", false, 240, 2160, "px")) p.display.height_px = *n;
      if (auto b = Bool(*v, "fullscreen", "/display")) p.display.fullscreen = *b;
      if (auto n = Int(*v, "monitor", "/display", false, 0, 16)) p.display.monitor = *n;
      p.display.profile = Path(*v, "profile", "/display", false);
      // How the photo maps to the screen: fitted whole (the default), 1:1, a scale, or a width in degrees.
      if (const Json* s = Field(*v, "scale", "/display", false)) {
        if (s->is_string() && *s == "fit") p.display.scaling = Scaling::kFit;
        else if (s->is_string() && *s == "native") p.display.scaling = Scaling::kNative;
        else if (NumberIn(*s, 0.05, 8)) p.display.scaling = Scaling::kScale, p.display.scale = s->get<double>();
        else Problem("/display/scale", "must be \"fit\", \"native\" or screen px per photo px in " + Range(0.05, 8, ""), *s);
      }
      if (auto x = Number(*v, "width_deg", "/display", false, 0.5, 180, "deg")) {
        if (v->contains("scale")) Problem("/display/width_deg", "give either scale or width_deg, not both", *x);
        else p.display.scaling = Scaling::kDegrees, p.display.width_deg = *x;
      }
      if ((v->contains("scale") || v->contains("width_deg")) && p.content.type == "picture")
        Problem(v->contains("scale") ? "/display/scale" : "/display/width_deg",
                "a picture's frame is always fitted to the window at one screen px per frame px; leave it out",
                v->contains("scale") ? (*v)["scale"] : (*v)["width_deg"]);
    }
  }
  CheckDesign(p);
  return p;
}

// The design as a whole, once every field is valid: what each block shows fits the content, every trial has
// the levels its content needs, and the session's size is within the cap.
void Parser::CheckDesign(const Protocol& p) {
  if (calls_ > 0) return;  // a design built from fields with problems would only repeat them
  const std::string& type = p.content.type;
  // Groups: a block names only the protocol's groups, and every group runs at least one block.
  for (const auto& b : p.blocks)
    for (size_t i = 0; i < b.groups.size(); ++i)
      if (!p.groups || std::find(p.groups->names.begin(), p.groups->names.end(), b.groups[i]) == p.groups->names.end())
        Problem((b.pointer.empty() ? std::string() : b.pointer) + "/groups/" + std::to_string(i),
                p.groups ? "names no group of /groups/names" : "names a group but the protocol declares no /groups",
                Json(b.groups[i]));
  if (p.groups)
    for (const auto& g : p.groups->names)
      if (std::none_of(p.blocks.begin(), p.blocks.end(), [&](const Block& b) {
            return b.groups.empty() || std::count(b.groups.begin(), b.groups.end(), g);
          }))
        Problem("/groups/names", "group " + g + " runs no block", Json(g));
  for (const auto& b : p.blocks) {
    // The renderer draws a picture for adjustment (cut-offs) and a pair of grids or balls for forced choice.
    if (type == "picture" && b.task != Task::kAdjustment)
      Problem(b.task_pointer, "must be adjustment for a picture (forced_choice compares a pair of grids or balls)",
              Json(ToString(b.task)));
    if (type != "picture" && b.task == Task::kAdjustment)
      Problem(b.task_pointer, "must be forced_choice for a " + type + " (adjustment steps through the cut-offs of a "
                              "picture)", Json(ToString(b.task)));
    // A level that places or moves a stimulus is read only by the content it is for: anywhere else it would be
    // recorded but not shown.
    static const std::map<std::string, std::set<std::string>> kUses = {
        {"grid", {"edge", "y_mm", "left_x_mm", "right_x_mm", "height_mm", "rotation_deg"}},
        {"ball", {"edge", "from_edge", "to_edge", "section", "speed_cm_s", "y_mm", "from_y_mm", "to_y_mm",
                  "left_x_mm", "right_x_mm", "height_mm"}},
        {"picture", {"distance_m"}}};
    static const std::set<std::string> kStimulusLevels = {"edge",      "from_edge",  "to_edge",   "section",
                                                          "speed_cm_s", "distance_m", "y_mm",      "from_y_mm",
                                                          "to_y_mm",   "left_x_mm",  "right_x_mm", "height_mm",
                                                          "rotation_deg"};
    const auto uses = kUses.find(type);
    for (const auto& f : b.factors) {
      std::set<std::string> names{f.name};
      for (const auto& level : f.levels)
        if (level.is_object())
          for (const auto& [key, value] : level.items()) names.insert(key);
      for (const auto& name : names)
        if (kStimulusLevels.count(name) && uses != kUses.end() && !uses->second.count(name))
          Problem(b.factors_pointer + "/" + f.name,
                  "a " + type + " does not use " + name + " (it would be recorded but not shown); a " + type +
                      " uses " + [&] {
                        std::string list;
                        for (const auto& u : uses->second) list += (list.empty() ? "" : ", ") + u;
                        return list;
                      }());
    }
    // Every layout but side_by_side draws its objects - the single one, each interval's - at the left one's place,
    // and intervals hold them still: a level that places the right object, or ends a run in intervals, would be
    // recorded but not shown. Named at the factor, or at the first level (a conditions table's row) that gives it.
    if (uses != kUses.end() && type != "picture" && p.layout != "side_by_side") {
      std::vector<std::pair<std::string, std::string>> unshown = {
          {"right_x_mm", "the layout " + p.layout + " shows every object at the left one's place (move it with "
                         "left_x_mm): a right_x_mm level would be recorded but not shown"}};
      if (IntervalCount(p) > 0)
        for (const char* end : {"to_edge", "to_y_mm"})
          unshown.push_back({end, std::string("intervals show still objects, where a run would start: a ") + end +
                                      " level would be recorded but not shown"});
      for (const auto& [name, why] : unshown)
        for (const auto& f : b.factors) {
          if (f.name == name) {
            Problem(b.factors_pointer + "/" + JsonPointerToken(f.name), why, Json(f.levels));
            continue;
          }
          for (size_t i = 0; i < f.levels.size(); ++i)
            if (f.levels[i].is_object() && f.levels[i].contains(name)) {
              Problem(b.factors_pointer + "/" + JsonPointerToken(f.name) + "/" + std::to_string(i) + "/" + name, why,
                      f.levels[i][name]);
              break;
            }
        }
    }
    if (IntervalCount(p) > 0 && Provides(b, "speed_cm_s"))
      Problem(b.factors_pointer, "intervals show still objects: a speed_cm_s level would move them");
    // The layout decides the question: one object is answered yes/no or rated, a pair or N intervals chosen from.
    const bool one = b.task == Task::kYesNo || b.task == Task::kRating;
    if (p.layout == "single" && type != "picture" && !one)
      Problem(b.task_pointer, "must be yes_no or rating for the layout single (one object: nothing to choose between)",
              Json(ToString(b.task)));
    if (p.layout != "single" && one)
      Problem(b.task_pointer, "is for the layout single (one object); a " + p.layout + " trial is a forced choice",
              Json(ToString(b.task)));
    if (p.layout == "single" && b.counterbalance != Counterbalance::kNone)
      Problem(b.counterbalance_pointer, "must be none for the layout single (one object: no sides to swap)",
              Json(ToString(b.counterbalance)));
    if (p.layout == "single" && b.procedure)
      Problem(b.pointer + "/procedure", "needs a forced choice (layouts side_by_side, two_intervals, odd_one_out)");
    // "object" is the single layout's one source; a pair layout reads left and right.
    bool object = b.sides.is_object() && b.sides.contains("object");
    bool pair = b.sides.is_object() && (b.sides.contains("left") || b.sides.contains("right"));
    for (const auto& f : b.factors)
      for (const auto& level : f.levels) {
        object = object || (level.is_object() && level.contains("object"));
        pair = pair || (level.is_object() && level.contains("left"));
      }
    if (p.layout == "single" && pair)
      Problem(b.sides.is_object() ? b.sides_pointer : b.factors_pointer,
              "the layout single shows one object: give \"object\", not left and right");
    if (p.layout != "single" && object)
      Problem(b.sides.is_object() ? b.sides_pointer : b.factors_pointer,
              "\"object\" is for the layout single; a " + p.layout + " trial shows left and right");
    if (type == "grid" && !Provides(b, "edge") && !Provides(b, "y_mm"))
      Problem(b.factors_pointer, "a grid stands at an edge: needs a factor edge (or y_mm), or a factor whose every "
                                 "level has an edge (1..11 on the thesis's board)");
    if (type == "picture" && !p.content.real_photos.empty() && !Provides(b, "distance_m"))
      Problem(b.factors_pointer, "content.real_photos chooses the photo by distance: needs a factor distance_m, or "
                                 "a factor whose every level has a distance_m");
  }
  const int64_t trials = SessionTrials(p);
  if (trials > kMaxTrials) {
    // Where the trials come from: every block's share counted as SessionTrials counts it - a practice criterion's
    // max_repeats runs, a procedure's trials per crossing, the protocol's practice drawn from its block - the
    // biggest first, each with its crossing spelled out (in floating point: the product may not fit in 64 bits).
    // The message used to add up one run of each block and spell out the block with the most trials per run, so a
    // criterion's repeats were left out of a total that then lay below the cap it broke.
    struct Share {
      double n = 0;
      const Block* block = nullptr;
      std::string spelled;
    };
    std::vector<Share> shares;
    double total = 0;
    bool worst_case = false;
    for (const auto& b : p.blocks) {
      Share share{1, &b, ""};
      if (b.criterion) {
        share.n = b.criterion->max_repeats;
        share.spelled = std::to_string(b.criterion->max_repeats) + " runs (criterion max_repeats) x ";
        worst_case = true;
      }
      for (const auto& f : b.factors) {
        share.n *= double(f.levels.size());
        share.spelled += std::to_string(f.levels.size()) + " " + f.name + " x ";
      }
      if (b.factors.empty()) share.n = 0;
      if (b.procedure) {
        share.n *= b.procedure->trials;
        share.spelled += std::to_string(b.procedure->trials) + " trials (procedure)";
      } else {
        share.n *= b.repetitions * (b.counterbalance == Counterbalance::kSwapCopies ? 2.0 : 1.0);
        share.spelled += std::to_string(b.repetitions) + " repetitions" +
                         (b.counterbalance == Counterbalance::kSwapCopies ? " x 2 (swap_copies)" : "");
      }
      if (b.name == p.practice.block && p.practice.count > 0) {
        const double drawn = std::min<double>(p.practice.count, double(DesignTrials(b)));
        share.n += drawn;
        share.spelled += " + " + std::to_string(int64_t(drawn)) + " practice";
      }
      total += share.n;
      if (share.n > 0) shares.push_back(std::move(share));
    }
    std::stable_sort(shares.begin(), shares.end(), [](const Share& a, const Share& b) { return a.n > b.n; });
    auto count = [](double n) {
      char text[64];
      std::snprintf(text, sizeof text, n < 1e15 ? "%.0f" : "%.3g", n);
      return std::string(text);
    };
    const size_t kShown = 3;
    std::string parts;
    double rest = 0;
    for (size_t i = 0; i < shares.size(); ++i) {
      if (i >= kShown) {
        rest += shares[i].n;
        continue;
      }
      parts += (i ? " + " : "") + shares[i].spelled + " = " + count(shares[i].n) + " in block " + shares[i].block->name;
    }
    if (shares.size() > kShown)
      parts += " + " + count(rest) + " in " + std::to_string(shares.size() - kShown) + " more blocks";
    Problem(shares.empty() ? "/" : shares.front().block->factors_pointer,
            "the session would have " + std::string(worst_case ? "up to " : "") + count(total) + " trials (" + parts +
                "); a session may have at most " + std::to_string(kMaxTrials) + " trials, practice included");
  } else if (trials == 0) {
    Problem("/", "makes no trials");
  }
  if (!p.blocks.empty() && std::all_of(p.blocks.begin(), p.blocks.end(), [](const Block& b) { return b.practice; }))
    Problem("/blocks", "every block is a practice block: nothing would be scored");
  // Answering only after the motion needs something that moves or runs in intervals.
  if (p.responses.after_motion && IntervalCount(p) == 0 &&
      std::none_of(p.blocks.begin(), p.blocks.end(), [&](const Block& b) { return Provides(b, "speed_cm_s"); }))
    Problem("/responses/after_motion", "no block moves its objects (a speed_cm_s level) and the layout has no "
                                       "intervals: there is no motion to wait for", Json(true));
  for (const auto& b : p.blocks)
    if (b.practice && b.procedure)
      Problem(b.pointer + "/practice", "a procedure's block is scored by its procedure; practise in a block without one",
              Json(true));
  for (const auto& b : p.blocks)
    if (b.name == p.practice.block && p.practice.count > 0 && b.procedure)
      Problem("/practice/block", "names block " + b.name + ", whose trials its procedure decides from the answers; "
                                 "practise on a block without a procedure", Json(b.name));
  for (const auto& b : p.blocks)
    if (b.name == p.practice.block && p.practice.count > DesignTrials(b) && DesignTrials(b) <= kMaxTrials)
      Problem("/practice/count", "asks for " + std::to_string(p.practice.count) + " practice trials but block " +
                                     b.name + " has only " + std::to_string(DesignTrials(b)),
              Json(p.practice.count));
}

// True when every trial of `b` has a level `name`: a factor of that name, or a factor whose levels all carry it.
bool Parser::Provides(const Block& b, const std::string& name) {
  for (const auto& f : b.factors) {
    if (f.name == name) return true;
    if (!f.levels.empty() && std::all_of(f.levels.begin(), f.levels.end(), [&](const Json& level) {
          return level.is_object() && level.contains(name);
        }))
      return true;
  }
  return false;
}

}  // namespace

std::string CheckInfoValue(const InfoField& f, const std::string& value) {
  if (f.type == "integer" || f.type == "number") {
    const std::optional<double> x = ParseDecimal(value);
    if (!x || (f.type == "integer" && !IsWholeDecimal(value)) || *x < f.min || *x > f.max) {
      char range[96];
      std::snprintf(range, sizeof range, "%s in [%g, %g]", f.type == "integer" ? "a whole number" : "a number", f.min,
                    f.max);
      return std::string("must be ") + range;
    }
    return "";
  }
  if (f.type == "choice") {
    if (std::find(f.choices.begin(), f.choices.end(), value) != f.choices.end()) return "";
    std::string list;
    for (const auto& c : f.choices) list += (list.empty() ? "" : ", ") + c;
    return "must be one of " + list;
  }
  if (value.size() > 200 || !IsPrintableUtf8(value)) return "must be one line of printable text, at most 200 bytes";
  return "";
}


std::vector<std::string> Validate(const Json& json, const fs::path& file, const ValidateOptions& options) {
  Parser parser(file, options);
  parser.Parse(json);
  if (parser.more_problems > 0)
    parser.problems.push_back(file.string() + ": " + std::to_string(parser.more_problems) + " more problems not listed");
  return parser.problems;
}

Protocol ParseProtocol(const Json& json, const fs::path& file, const ValidateOptions& options) {
  Parser parser(file, options);
  Protocol p = parser.Parse(json);
  if (!parser.problems.empty()) {
    std::vector<std::string> lines = parser.problems;
    const size_t count = parser.problems.size() + parser.more_problems;
    if (parser.more_problems > 0)
      lines.push_back("(" + std::to_string(count) + " problems, the first " + std::to_string(parser.problems.size()) +
                      " listed)");
    else if (count > 1) lines.push_back("(" + std::to_string(count) + " problems)");
    throw Error(ErrorKind::kInput, std::move(lines));
  }
  return p;
}

int IntervalCount(const Protocol& protocol) {
  return protocol.layout == "two_intervals" ? 2 : protocol.layout == "odd_one_out" ? protocol.alternatives : 0;
}

int64_t DesignTrials(const Block& block) {
  if (block.factors.empty()) return 0;
  // Saturating: once past the cap the exact number does not matter, and it can no longer overflow.
  int64_t n = block.procedure ? block.procedure->trials
                              : block.repetitions * (block.counterbalance == Counterbalance::kSwapCopies ? 2 : 1);
  for (const auto& f : block.factors) {
    n *= static_cast<int64_t>(f.levels.size());
    if (n > kMaxTrials) return kMaxTrials + 1;
  }
  return n;
}

int64_t SessionTrials(const Protocol& protocol) {
  int64_t n = 0;
  for (const auto& b : protocol.blocks) {
    n += DesignTrials(b) * (b.criterion ? b.criterion->max_repeats : 1);
    if (b.name == protocol.practice.block) n += std::min<int64_t>(protocol.practice.count, DesignTrials(b));
    if (n > kMaxTrials) return kMaxTrials + 1;
  }
  return n;
}

Protocol LoadProtocol(const fs::path& file, const ValidateOptions& options) {
  return ParseProtocol(ReadJsonFile(file), file, options);
}

const Json* FindLevel(const Json& levels, const std::string& name) {
  if (!levels.is_object()) return nullptr;
  if (auto it = levels.find(name); it != levels.end()) return &*it;
  for (const auto& [key, value] : levels.items())
    if (value.is_object())
      if (auto it = value.find(name); it != value.end()) return &*it;
  return nullptr;
}

std::set<double> NumericLevels(const Protocol& protocol, const std::string& factor) {
  std::set<double> values;
  for (const auto& b : protocol.blocks)
    for (const auto& f : b.factors)
      for (const auto& level : f.levels) {
        Json levels = Json::object();
        levels[f.name] = level;
        if (const Json* v = FindLevel(levels, factor); v && v->is_number()) values.insert(v->get<double>());
      }
  return values;
}

std::string LevelText(double level) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", level);
  return text;
}

fs::path RealPhotoFor(const Content& content, double distance_m) {
  const std::string text = LevelText(distance_m);
  std::string path = content.real_photos;
  const std::string key = "{distance_m}";
  for (size_t at = path.find(key); at != std::string::npos; at = path.find(key, at + text.size()))
    path.replace(at, key.size(), text);
  return path;
}

}  // namespace blurcue::protocol
