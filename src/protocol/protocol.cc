#include "protocol/protocol.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <cmath>
#include <functional>
#include <map>
#include <set>

#include "core/error.h"

namespace blurcue::protocol {
namespace fs = std::filesystem;

std::string ToString(Task task) { return task == Task::kAdjustment ? "adjustment" : "forced_choice"; }

std::string ToString(Counterbalance counterbalance) {
  switch (counterbalance) {
    case Counterbalance::kSwapCopies: return "swap_copies";
    case Counterbalance::kByParticipant: return "by_participant";
    case Counterbalance::kNone: break;
  }
  return "none";
}

namespace {

const int kEdges = 11;  // parallel edges of the 7 x 10 board (thesis figure 4.10)

// JSON pointer escaping (RFC 6901): '~' -> "~0", '/' -> "~1".
std::string Escape(const std::string& key) {
  std::string out;
  for (char c : key) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}

std::string Got(const Json& value) {
  std::string text = value.dump();
  if (text.size() > 80) text = text.substr(0, 77) + "...";
  return text;
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

bool IsBlurSource(const Json& v) {
  if (v.is_number()) return v.get<double>() >= 0;
  if (!v.is_string()) return false;
  static const std::set<std::string> kNames = {"none", "measured", "estimated", "fitted"};
  return kNames.count(v.get<std::string>()) > 0;
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

  std::vector<std::string> problems;

  void Problem(const std::string& ptr, const std::string& what) {
    problems.push_back(file_.string() + ": " + (ptr.empty() ? "/" : ptr) + ": " + what);
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

  std::optional<int> Int(const Json& obj, const std::string& key, const std::string& ptr, bool required, int min,
                         int max = 1 << 30) {
    const Json* v = Field(obj, key, ptr, required);
    if (!v) return std::nullopt;
    const std::string p = ptr + "/" + Escape(key);
    if (!v->is_number_integer()) {
      Problem(p, "must be an integer", *v);
      return std::nullopt;
    }
    const long long n = v->get<long long>();
    if (n < min || n > max) {
      Problem(p, max == (1 << 30) ? "must be >= " + std::to_string(min)
                                  : "must be in " + std::to_string(min) + ".." + std::to_string(max),
              *v);
      return std::nullopt;
    }
    return static_cast<int>(n);
  }

  // A number > min (strict) or >= min.
  std::optional<double> Number(const Json& obj, const std::string& key, const std::string& ptr, bool required,
                               double min, bool strict) {
    const Json* v = Field(obj, key, ptr, required);
    if (!v) return std::nullopt;
    const std::string p = ptr + "/" + Escape(key);
    if (!v->is_number()) {
      Problem(p, "must be a number", *v);
      return std::nullopt;
    }
    const double x = v->get<double>();
    if (strict ? !(x > min) : !(x >= min)) {
      Problem(p, std::string("must be ") + (strict ? "> " : ">= ") + Json(min).dump(), *v);
      return std::nullopt;
    }
    return x;
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
    const auto s = String(obj, key, ptr, required);
    if (!s) return {};
    if (s->empty()) {
      Problem(ptr + "/" + Escape(key), "must name a file", Json(*s));
      return {};
    }
    const fs::path resolved = (base_ / *s).lexically_normal();
    if (options_.check_files && !fs::is_regular_file(resolved))
      Problem(ptr + "/" + Escape(key), "no such file: " + resolved.string(), Json(*s));
    return resolved;
  }

  Protocol Parse(const Json& json);

 private:
  void ParseScene(const Json& v, const std::string& ptr, Protocol* p);
  void ParseContent(const Json& v, const std::string& ptr, Protocol* p);
  std::vector<Factor> ParseFactors(const Json& v, const std::string& ptr);
  void CheckLevelValue(const std::string& name, const Json& v, const std::string& ptr);
  std::optional<Adjustment> ParseAdjust(const Json& v, const std::string& ptr);
  void ParseSides(const Json& v, const std::string& ptr);
  // Fills `b` from `obj` at `ptr`, falling back to the protocol-level defaults in `top`.
  void ParseBlock(const Json& obj, const std::string& ptr, const Json& top, Block* b);
  void ParseResponses(const Json& v, const std::string& ptr, const std::set<Task>& tasks, Responses* r);

  fs::path file_, base_;
  ValidateOptions options_;
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
  if (*type == "grid") {
    Object(v, ptr, {"type", "cells"});
    if (auto n = Int(v, "cells", ptr, false, 1, 100)) p->content.cells = *n;
  } else if (*type == "ball") {
    Object(v, ptr, {"type", "texture", "radius_mm"});
    if (auto r = Number(v, "radius_mm", ptr, false, 0, true)) p->content.radius_mm = *r;
    if (auto t = String(v, "texture", ptr, false)) {
      if (*t == "soccer" || *t == "wood") p->content.texture = *t;
      else p->content.texture = Path(v, "texture", ptr, true).string();
    }
  } else {
    Object(v, ptr, {"type", "image", "real_photos"});
    p->content.image = Path(v, "image", ptr, true);
    if (auto pattern = String(v, "real_photos", ptr, false)) {
      if (pattern->find("{distance_m}") == std::string::npos)
        Problem(ptr + "/real_photos", "must contain {distance_m} (one photo per distance)", Json(*pattern));
      else
        p->content.real_photos = (base_ / *pattern).lexically_normal().string();
    }
  }
}

// Checks a value by the name it goes by (a factor's name, or a key of an object level).
void Parser::CheckLevelValue(const std::string& name, const Json& v, const std::string& ptr) {
  auto integer_in = [&](int lo, int hi, const std::string& what) {
    if (!v.is_number_integer() || v.get<long long>() < lo || v.get<long long>() > hi)
      Problem(ptr, what + " must be an integer in " + std::to_string(lo) + ".." + std::to_string(hi), v);
  };
  auto positive = [&](const std::string& what) {
    if (!v.is_number() || !(v.get<double>() > 0)) Problem(ptr, what + " must be a number > 0", v);
  };
  if (name == "edge" || name == "from_edge" || name == "to_edge") integer_in(1, kEdges, "an edge");
  else if (name == "section") integer_in(1, kEdges - 1, "a section (edge s to s + 1)");
  else if (name == "speed_cm_s") positive("a speed");
  else if (name == "distance_m") positive("a distance");
  else if (name == "cutoff") {
    if (!v.is_number() || v.get<double>() < 0) Problem(ptr, "a cut-off must be a number >= 0", v);
  } else if (name == "left" || name == "right") {
    if (!IsBlurSource(v)) Problem(ptr, "a blur source must be none, measured, estimated, fitted or a radius >= 0", v);
  }
}

std::vector<Factor> Parser::ParseFactors(const Json& v, const std::string& ptr) {
  std::vector<Factor> factors;
  if (!v.is_object()) {
    Problem(ptr, "must be an object mapping factor names to lists of levels", v);
    return factors;
  }
  if (v.empty()) Problem(ptr, "must name at least one factor", v);
  int carrying_sides = 0;
  for (const auto& [name, levels] : v.items()) {
    const std::string fp = ptr + "/" + Escape(name);
    if (!levels.is_array()) {
      Problem(fp, "must be a list of levels", levels);
      continue;
    }
    if (levels.empty()) {
      Problem(fp, "must list at least one level", levels);
      continue;
    }
    Factor f{name, {}};
    bool sides = false;
    for (size_t i = 0; i < levels.size(); ++i) {
      const Json& level = levels[i];
      const std::string lp = fp + "/" + std::to_string(i);
      if (!level.is_number() && !level.is_string() && !level.is_object()) {
        Problem(lp, "a level must be a number, a string or an object", level);
        continue;
      }
      for (size_t j = 0; j < i; ++j)
        if (levels[j] == level) Problem(lp, "repeats level " + std::to_string(j), level);
      if (level.is_object()) {
        for (const auto& [key, value] : level.items()) CheckLevelValue(key, value, lp + "/" + Escape(key));
        const bool l = level.contains("left"), r = level.contains("right");
        if (l != r) Problem(lp, std::string("has \"") + (l ? "left" : "right") + "\" but no \"" + (l ? "right" : "left") + "\"", level);
        if (l && r) sides = true;
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
  if (auto s = String(v, "parameter", ptr, false)) a.parameter = *s;
  if (auto s = String(v, "order", ptr, false, {"shuffled", "ascending", "descending"})) a.order = *s;
  const Json* levels = Field(v, "levels", ptr, true);
  if (!levels) return a;
  if (!levels->is_array() || levels->size() < 2) {
    Problem(ptr + "/levels", "must be a list of at least 2 numbers", *levels);
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

void Parser::ParseSides(const Json& v, const std::string& ptr) {
  if (!Object(v, ptr, {"left", "right"})) return;
  for (const char* side : {"left", "right"}) {
    if (const Json* s = Field(v, side, ptr, true)) CheckLevelValue(side, *s, ptr + "/" + side);
  }
}

void Parser::ParseBlock(const Json& obj, const std::string& ptr, const Json& top, Block* b) {
  // A field of the block, else of the protocol: the object that holds it and that object's pointer. Inherited
  // fields are checked again per block; ParseProtocol drops the repeated messages.
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
  } else if (auto t = String(*s.holder, "task", s.ptr, true, {"forced_choice", "adjustment"})) {
    b->task = *t == "adjustment" ? Task::kAdjustment : Task::kForcedChoice;
  }
  const size_t before_factors = problems.size();
  if (const Source s = pick("factors"); !s.holder)
    Problem(ptr + "/factors", "is required (here or at /factors) but missing");
  else
    b->factors = ParseFactors((*s.holder)["factors"], s.ptr + "/factors");
  const bool factors_ok = problems.size() == before_factors;
  if (const Source s = pick("repetitions"); s.holder) {
    if (auto n = Int(*s.holder, "repetitions", s.ptr, true, 1, 10000)) b->repetitions = *n;
  }
  if (const Source s = pick("counterbalance"); s.holder) {
    if (auto c = String(*s.holder, "counterbalance", s.ptr, true, {"swap_copies", "by_participant", "none"}))
      b->counterbalance = *c == "swap_copies"      ? Counterbalance::kSwapCopies
                          : *c == "by_participant" ? Counterbalance::kByParticipant
                                                   : Counterbalance::kNone;
  }
  const Source sides = pick("sides");
  if (sides.holder) {
    ParseSides((*sides.holder)["sides"], sides.ptr + "/sides");
    b->sides = (*sides.holder)["sides"];
  }
  const Source adjust = pick("adjust");
  if (adjust.holder && b->task == Task::kAdjustment)
    b->adjust = ParseAdjust((*adjust.holder)["adjust"], adjust.ptr + "/adjust");
  if (auto s = String(obj, "instructions", ptr, false)) b->instructions = *s;
  if (auto s = Bool(obj, "shuffle", ptr)) b->shuffle = *s;

  // What is shown left and right must be known for a comparison, and for any left/right counterbalancing.
  bool factor_sides = false;
  for (const auto& f : b->factors)
    for (const auto& level : f.levels) factor_sides = factor_sides || (level.is_object() && level.contains("left"));
  const std::string where = ptr.empty() ? "/" : ptr;
  if (factor_sides && sides.holder)
    Problem(sides.ptr + "/sides", "is given but a factor's levels already carry left and right",
            (*sides.holder)["sides"]);
  const bool needs_sides = b->task == Task::kForcedChoice || b->counterbalance != Counterbalance::kNone;
  if (needs_sides && factors_ok && !factor_sides && !sides.holder)
    Problem(where, "needs what is shown left and right: a \"sides\" object or a factor whose levels have left and "
                   "right (a forced choice or left/right counterbalancing compares two sides)");
  if (b->task == Task::kAdjustment && !adjust.holder)
    Problem(ptr + "/adjust", "is required for the adjustment task (here or at /adjust) but missing");
}

void Parser::ParseResponses(const Json& v, const std::string& ptr, const std::set<Task>& tasks, Responses* r) {
  // Defaults that suit a keyboard: arrows to choose or step, Return to accept.
  *r = Responses{"Left", "Right", "Down", "Left", "Right", "Return"};
  if (v.is_null()) return;
  if (!Object(v, ptr, {"left", "right", "cant_tell", "previous", "next", "accept"})) return;
  std::map<std::string, std::string*> slots = {{"left", &r->left},         {"right", &r->right},
                                               {"cant_tell", &r->cant_tell}, {"previous", &r->previous},
                                               {"next", &r->next},         {"accept", &r->accept}};
  for (auto& [key, slot] : slots) {
    const auto s = String(v, key, ptr, false);
    if (!s) continue;
    if (*s == "Escape") Problem(ptr + "/" + key, "Escape is reserved for pausing a session", Json(*s));
    else if (!IsKeyName(*s))
      Problem(ptr + "/" + key, "must be a key name: A-Z, 0-9, Left, Right, Up, Down, Space, Return, Tab, "
                               "Backspace, F1-F12 or KP_0-KP_9", Json(*s));
    else *slot = *s;
  }
  auto distinct = [&](const std::vector<std::pair<std::string, std::string>>& set) {
    for (size_t i = 0; i < set.size(); ++i)
      for (size_t j = 0; j < i; ++j)
        if (set[i].second == set[j].second)
          Problem(ptr + "/" + set[i].first, "is the same key as /responses/" + set[j].first, Json(set[i].second));
  };
  if (tasks.count(Task::kForcedChoice))
    distinct({{"left", r->left}, {"right", r->right}, {"cant_tell", r->cant_tell}});
  if (tasks.count(Task::kAdjustment))
    distinct({{"previous", r->previous}, {"next", r->next}, {"accept", r->accept}});
}

Protocol Parser::Parse(const Json& json) {
  Protocol p;
  p.file = file_;
  if (!Object(json, "",
              {"$schema", "name", "version", "description", "scene", "content", "task", "factors", "repetitions",
               "counterbalance", "sides", "adjust", "blocks", "practice", "instructions", "breaks", "responses",
               "timing", "display"}))
    return p;
  if (auto s = String(json, "name", "", true)) {
    if (s->empty()) Problem("/name", "must not be empty", Json(*s));
    p.name = *s;
  }
  if (auto n = Int(json, "version", "", true, 1)) p.version = *n;
  if (auto s = String(json, "description", "", false)) p.description = *s;
  if (auto s = String(json, "instructions", "", false)) p.instructions = *s;
  if (const Json* v = Field(json, "content", "", true)) ParseContent(*v, "/content", &p);
  if (const Json* v = Field(json, "scene", "", true)) ParseScene(*v, "/scene", &p);
  if (json.contains("scene") && json["scene"].is_object() && !json["scene"].contains("calib") &&
      (p.content.type == "grid" || p.content.type == "ball"))
    Problem("/scene/calib", "is required for a " + p.content.type + " (its blur comes from the calibration) but missing");

  // Protocol-level design fields are checked where they are written even when no block inherits them.
  if (json.contains("factors")) ParseFactors(json["factors"], "/factors");
  if (json.contains("sides")) ParseSides(json["sides"], "/sides");
  if (json.contains("adjust")) ParseAdjust(json["adjust"], "/adjust");
  if (json.contains("repetitions")) Int(json, "repetitions", "", true, 1, 10000);
  if (json.contains("counterbalance"))
    String(json, "counterbalance", "", true, {"swap_copies", "by_participant", "none"});
  if (json.contains("task")) String(json, "task", "", true, {"forced_choice", "adjustment"});

  const Json* blocks = Field(json, "blocks", "", false);
  if (!blocks) {
    Block b;
    b.name = "main";
    ParseBlock(Json::object(), "", json, &b);
    p.blocks.push_back(std::move(b));
  } else if (!blocks->is_array() || blocks->empty()) {
    Problem("/blocks", "must be a non-empty list of blocks", *blocks);
  } else {
    for (size_t i = 0; i < blocks->size(); ++i) {
      const Json& obj = (*blocks)[i];
      const std::string bp = "/blocks/" + std::to_string(i);
      if (!Object(obj, bp, {"name", "task", "factors", "repetitions", "counterbalance", "sides", "adjust",
                            "instructions", "shuffle"}))
        continue;
      Block b;
      if (auto s = String(obj, "name", bp, true)) {
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
      if (auto n = Int(*v, "count", "/practice", true, 0)) p.practice.count = *n;
      if (auto s = String(*v, "instructions", "/practice", false)) p.practice.instructions = *s;
      p.practice.block = p.blocks.empty() ? "" : p.blocks.front().name;
      if (auto s = String(*v, "block", "/practice", false)) {
        bool found = false;
        for (const auto& b : p.blocks) found = found || b.name == *s;
        if (!found) Problem("/practice/block", "names no block of this protocol", Json(*s));
        p.practice.block = *s;
      }
    }
  }
  if (const Json* v = Field(json, "breaks", "", false)) {
    if (Object(*v, "/breaks", {"every_trials", "text"})) {
      if (auto n = Int(*v, "every_trials", "/breaks", true, 1)) p.break_every_trials = *n;
      if (auto s = String(*v, "text", "/breaks", false)) p.break_text = *s;
    }
  }
  // The real photos: one per distance the design shows.
  if (!p.content.real_photos.empty() && options_.check_files) {
    const std::set<double> distances = NumericLevels(p, "distance_m");
    if (distances.empty())
      Problem("/content/real_photos", "needs a factor distance_m to choose the photo by", Json(p.content.real_photos));
    for (double d : distances)
      if (const fs::path photo = RealPhotoFor(p.content, d); !fs::is_regular_file(photo))
        Problem("/content/real_photos", "no photo for distance_m " + Json(d).dump() + ": " + photo.string(),
                json["content"]["real_photos"]);
  }
  std::set<Task> tasks;
  for (const auto& b : p.blocks) tasks.insert(b.task);
  const Json* responses = Field(json, "responses", "", false);
  ParseResponses(responses ? *responses : Json(), "/responses", tasks, &p.responses);
  if (const Json* v = Field(json, "timing", "", false)) {
    if (Object(*v, "/timing", {"stimulus_ms", "inter_trial_ms"})) {
      if (const Json* s = Field(*v, "stimulus_ms", "/timing", false)) {
        if (s->is_string() && *s == "until_response") p.timing.stimulus_ms = 0;
        else if (s->is_number() && s->get<double>() > 0) p.timing.stimulus_ms = s->get<double>();
        else Problem("/timing/stimulus_ms", "must be a duration > 0 ms or \"until_response\"", *s);
      }
      if (auto x = Number(*v, "inter_trial_ms", "/timing", false, 0, false)) p.timing.inter_trial_ms = *x;
    }
  }
  if (const Json* v = Field(json, "display", "", false)) {
    if (Object(*v, "/display", {"width_px", "height_px", "fullscreen", "monitor"})) {
      if (auto n = Int(*v, "width_px", "/display", false, 1, 16384)) p.display.width_px = *n;
      if (auto n = Int(*v, "height_px", "/display", false, 1, 16384)) p.display.height_px = *n;
      if (auto b = Bool(*v, "fullscreen", "/display")) p.display.fullscreen = *b;
      if (auto n = Int(*v, "monitor", "/display", false, 0, 16)) p.display.monitor = *n;
    }
  }
  // Fields inherited by several blocks were checked once per block: keep each message once, in first order.
  std::vector<std::string> unique;
  for (const auto& line : problems)
    if (std::find(unique.begin(), unique.end(), line) == unique.end()) unique.push_back(line);
  problems = std::move(unique);
  return p;
}

}  // namespace

std::vector<std::string> Validate(const Json& json, const fs::path& file, const ValidateOptions& options) {
  Parser parser(file, options);
  parser.Parse(json);
  return parser.problems;
}

Protocol ParseProtocol(const Json& json, const fs::path& file, const ValidateOptions& options) {
  Parser parser(file, options);
  Protocol p = parser.Parse(json);
  if (!parser.problems.empty()) {
    std::string message;
    for (const auto& line : parser.problems) message += (message.empty() ? "" : "\n") + line;
    if (parser.problems.size() > 1) message += "\n(" + std::to_string(parser.problems.size()) + " problems)";
    throw Error(ErrorKind::kInput, message);
  }
  return p;
}

Protocol LoadProtocol(const fs::path& file, const ValidateOptions& options) {
  return ParseProtocol(ReadJsonFile(file), file, options);
}

std::set<double> NumericLevels(const Protocol& protocol, const std::string& factor) {
  std::set<double> values;
  for (const auto& b : protocol.blocks)
    for (const auto& f : b.factors)
      if (f.name == factor)
        for (const auto& level : f.levels)
          if (level.is_number()) values.insert(level.get<double>());
  return values;
}

fs::path RealPhotoFor(const Content& content, double distance_m) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", distance_m);
  std::string path = content.real_photos;
  const std::string key = "{distance_m}";
  for (size_t at = path.find(key); at != std::string::npos; at = path.find(key, at + std::strlen(text)))
    path.replace(at, key.size(), text);
  return path;
}

}  // namespace blurcue::protocol
