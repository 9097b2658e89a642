#include "protocol/parser.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/limits.h"
#include "core/names.h"
#include "core/typed.h"

namespace blurcue::protocol::detail {

std::string Escape(const std::string& key) { return JsonPointerToken(key); }

namespace {

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

}  // namespace

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
  const std::optional<BlurSource> source = ParseWord<BlurSource>(v.get<std::string>());
  return source && *source != BlurSource::kFixed;  // a fixed radius is a number, never the word
}

// Names whose values CheckLevelValue knows: a level of a factor so named is that value, never an object.
const std::vector<std::string>& ValueNames() {
  static const std::vector<std::string> kNames = {"edge",       "from_edge",  "to_edge", "section",   "speed_cm_s",
                                                  "distance_m", "cutoff",     ToString(Side::kLeft),
                                                  ToString(Side::kRight),     "y_mm",    "object",
                                                  "from_y_mm",  "to_y_mm",    "left_x_mm", "right_x_mm",
                                                  "height_mm",  "rotation_deg"};
  return kNames;
}

bool IsValueName(const std::string& name) {
  const auto& names = ValueNames();
  return std::find(names.begin(), names.end(), name) != names.end();
}

bool IsLabelName(const std::string& name) { return name == "id" || name == "label" || name.rfind("label_", 0) == 0; }

const std::vector<std::string>& ReadNames() {
  static const std::vector<std::string> kNames = [] {
    std::vector<std::string> names = ValueNames();
    names.insert(names.end(), {"id", "label"});
    return names;
  }();
  return kNames;
}

const std::vector<std::string>& KeyNames() {
  static const std::vector<std::string> kNames = [] {
    std::vector<std::string> names = {"Left", "Right", "Up", "Down", "Space", "Return", "Tab", "Backspace"};
    for (char c = 'A'; c <= 'Z'; ++c) names.emplace_back(1, c);
    for (char c = '0'; c <= '9'; ++c) names.emplace_back(1, c);
    for (int f = 1; f <= 12; ++f) names.push_back("F" + std::to_string(f));
    for (char c = '0'; c <= '9'; ++c) names.push_back(std::string("KP_") + c);
    return names;
  }();
  return kNames;
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

// Fields inherited by several blocks are checked once per block: each message is kept once.
void Parser::Problem(const std::string& ptr, const std::string& what) {
  ++calls_;
  const auto place = table_places_.find(ptr);
  const std::string& at = place != table_places_.end() ? place->second : ptr;
  std::string line = file_.string() + ": " + (at.empty() ? "/" : at) + ": " + what;
  if (!reported_.insert(line).second) return;
  if (problems.size() < kMaxProblems) problems.push_back(std::move(line));
  else ++more_problems;
}

void Parser::Problem(const std::string& ptr, const std::string& what, const Json& got) {
  Problem(ptr, what + ", got " + Got(got));
}

// True if `v` is an object; reports keys outside `known` (with the nearest known key as a hint).
bool Parser::Object(const Json& v, const std::string& ptr, const std::vector<std::string>& known) {
  if (!v.is_object()) {
    Problem(ptr, "must be an object", v);
    return false;
  }
  for (const auto& [key, value] : v.items()) {
    if (std::find(known.begin(), known.end(), key) != known.end()) continue;
    const std::string hint = NearestName(key, known);  // a slip or an abbreviation ("exposure" for exposure_ms)
    std::string list;
    for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
    Problem(ptr + "/" + Escape(key),
            "unknown key" + (hint.empty() ? " (known: " + list + ")" : " (did you mean \"" + hint + "\"?)"), value);
  }
  return true;
}

const Json* Parser::Field(const Json& obj, const std::string& key, const std::string& ptr, bool required) {
  if (!obj.is_object()) return nullptr;
  auto it = obj.find(key);
  if (it == obj.end()) {
    if (required) Problem(ptr + "/" + Escape(key), "is required but missing");
    return nullptr;
  }
  return &*it;
}

std::optional<std::string> Parser::String(const Json& obj, const std::string& key, const std::string& ptr,
                                          bool required, const std::vector<std::string>& allowed) {
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
    Problem(p, "must be one of " + list + DidYouMean(s, allowed), *v);
    return std::nullopt;
  }
  return s;
}

// An integer in [min, max]; `unit` (e.g. "px", "trials") goes into the message.
std::optional<int> Parser::Int(const Json& obj, const std::string& key, const std::string& ptr, bool required,
                               int min, int max, const std::string& unit) {
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
std::optional<double> Parser::Number(const Json& obj, const std::string& key, const std::string& ptr,
                                     bool required, double min, double max, const std::string& unit) {
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
bool Parser::IntegerIn(const Json& v, int64_t min, int64_t max) {
  if (v.is_number_unsigned()) return v.get<uint64_t>() <= static_cast<uint64_t>(std::max<int64_t>(max, 0)) &&
                                     static_cast<int64_t>(v.get<uint64_t>()) >= min;
  return v.is_number_integer() && v.get<int64_t>() >= min && v.get<int64_t>() <= max;
}

bool Parser::NumberIn(const Json& v, double min, double max) {
  if (!v.is_number()) return false;
  const double x = v.get<double>();
  return std::isfinite(x) && x >= min && x <= max;
}

// A string of at most `max_chars` bytes; `one_line`: without control characters (names, keys, paths).
std::optional<std::string> Parser::Text(const Json& obj, const std::string& key, const std::string& ptr,
                                        bool required, size_t max_chars, bool one_line) {
  const auto s = String(obj, key, ptr, required);
  if (!s) return std::nullopt;
  const std::string p = ptr + "/" + Escape(key);
  // Characters, as the message says: 100 x "é" is 100 characters (200 bytes), and fits.
  if (Utf8Length(*s) > max_chars) {
    Problem(p, "must be at most " + std::to_string(max_chars) + " characters, got " + std::to_string(Utf8Length(*s)));
    return std::nullopt;
  }
  if (one_line && !IsPrintableUtf8(*s)) {
    Problem(p, "must not contain control characters (line breaks, tabs, NUL)", Json(*s));
    return std::nullopt;
  }
  return s;
}

std::optional<std::string> Parser::Name(const Json& obj, const std::string& key, const std::string& ptr,
                                        bool required) {
  auto s = Text(obj, key, ptr, required, kMaxNameChars, true);
  if (!s) return std::nullopt;
  const std::string p = ptr + "/" + Escape(key);
  if (s->empty()) {
    Problem(p, "must not be empty", Json(*s));
    return std::nullopt;
  }
  if (const std::string why = UnsafeIdReason(*s); !why.empty()) {
    Problem(p, why, Json(*s));
    return std::nullopt;
  }
  return s;
}

std::optional<bool> Parser::Bool(const Json& obj, const std::string& key, const std::string& ptr) {
  const Json* v = Field(obj, key, ptr, false);
  if (!v) return std::nullopt;
  if (!v->is_boolean()) {
    Problem(ptr + "/" + Escape(key), "must be true or false", *v);
    return std::nullopt;
  }
  return v->get<bool>();
}

// A path relative to the protocol file's folder; checked for existence unless options say otherwise.
fs::path Parser::Path(const Json& obj, const std::string& key, const std::string& ptr, bool required,
                      std::optional<FileUse> use) {
  const auto s = Text(obj, key, ptr, required, kMaxPathChars, true);
  if (!s) return {};
  if (s->empty()) {
    Problem(ptr + "/" + Escape(key), "must name a file", Json(*s));
    return {};
  }
  const fs::path resolved = (base_ / *s).lexically_normal();
  if (options_.check_files && CheckFile(resolved, ptr + "/" + Escape(key), Json(*s)) && use &&
      options_.check_content)
    if (const std::string wrong = options_.check_content(resolved, *use); !wrong.empty())
      Problem(ptr + "/" + Escape(key), wrong);  // the reader names the file
  return resolved;
}

// A regular file: not missing, not a folder, not a device (/dev/zero) or FIFO that a reader would wait on.
// What is in it (an image that decodes, a calibration that parses) is checked before a session: PrepareSession.
bool Parser::CheckFile(const fs::path& resolved, const std::string& ptr, const Json& got) {
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

}  // namespace blurcue::protocol::detail
