#include "protocol/parser.h"

#include <algorithm>
#include <cctype>
#include <map>

#include "core/error.h"
#include "core/names.h"
#include "core/typed.h"

namespace blurcue::protocol::detail {

namespace {
// Two names that differ only in ASCII letter case: one name, since a case slip is answered with the nearest
// (--info handedness=Left: did you mean left?) - groups "a" and "A", or choices "yes" and "Yes", used to pass.
bool SameButCase(const std::string& a, const std::string& b) {
  return a != b && a.size() == b.size() &&
         std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) { return std::tolower((unsigned char)x) ==
                                                                              std::tolower((unsigned char)y); });
}
bool CaseTwin(const std::vector<std::string>& names, const std::string& name) {
  return std::any_of(names.begin(), names.end(), [&](const std::string& n) { return SameButCase(n, name); });
}
}  // namespace

void Parser::ParseScene(const Json& v, const std::string& ptr, Protocol* p) {
  if (!Object(v, ptr, {"background", "board_free", "calib", "show", "video", "track"})) return;
  if (v.contains("video") || v.contains("track")) {
    // A tracked take: each frame's photo and calibration come from the take and its track folder.
    for (const char* key : {"background", "board_free", "calib", "show"})
      if (v.contains(key))
        Problem(ptr + "/" + key, "is not read with a video scene (each frame's photo and calibration come from " +
                                     ptr + "/video and " + ptr + "/track)", v[key]);
    if (auto s = Text(v, "video", ptr, true, kMaxPathChars, true)) {
      p->scene.video = (base_ / *s).lexically_normal();
      // A printf pattern (frames/frame-%04d.png) names no one file; its first frame is checked when it is read.
      if (options_.check_files && s->find('%') == std::string::npos) CheckFile(p->scene.video, ptr + "/video", Json(*s));
    }
    if (auto s = Text(v, "track", ptr, true, kMaxPathChars, true)) {
      p->scene.track = (base_ / *s).lexically_normal();
      if (options_.check_files) CheckFile(p->scene.track / "track.csv", ptr + "/track", Json(*s));
    }
    return;
  }
  p->scene.background = Path(v, "background", ptr, true, FileUse::kImage);
  p->scene.board_free = Path(v, "board_free", ptr, false, FileUse::kImage);
  p->scene.calib = Path(v, "calib", ptr, false, FileUse::kCalibration);
  if (auto show = Word<ScenePhoto>(v, "show", ptr, false)) p->scene.show = *show;
  if (p->scene.show == ScenePhoto::kBoardFree && !v.contains("board_free"))
    Problem(ptr + "/show", "names the board-free photo but /scene/board_free is missing", v["show"]);
}

void Parser::ParseContent(const Json& v, const std::string& ptr, Protocol* p) {
  if (!v.is_object()) {
    Problem(ptr, "must be an object", v);
    return;
  }
  const auto type = Word<ContentType>(v, "type", ptr, true);
  if (!type) return;
  p->content.type = *type;
  const bool object = *type == ContentType::kGrid || *type == ContentType::kBall;
  if (object) {
    if (auto k = Word<Kernel>(v, "kernel", ptr, false)) p->content.kernel = *k;
    // The thesis matched the virtual object to the scene by eye; a factor of 4 either way is far beyond that.
    if (auto x = Number(v, "brightness", ptr, false, 0.25, 4, "(a factor)")) p->content.brightness = *x;
    if (auto x = Number(v, "contrast", ptr, false, 0.25, 4, "(a factor)")) p->content.contrast = *x;
    if (const Json* t = Field(v, "depth_blur_threshold", ptr, false)) {
      const std::string at = ptr + "/depth_blur_threshold";
      if (t->is_object() && t->size() == 1 && (t->contains("screen_px") || t->contains("arcmin"))) {
        const bool px = t->contains("screen_px");
        if (auto x = Number(*t, px ? "screen_px" : "arcmin", at, true, 0, px ? 100 : 600, px ? "screen px" : "arcmin"))
          p->content.depth_blur_threshold = *x, p->content.depth_blur_threshold_unit = px ? ThresholdUnit::kScreenPx : ThresholdUnit::kArcmin;
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
  if (object) {
    // The card's face or the ball's surface: a shipped texture by name, or an image file.
    const bool grid = *type == ContentType::kGrid;
    p->content.texture = grid ? "grid" : "soccer";
    if (auto t = Text(v, "texture", ptr, false, kMaxPathChars, true)) {
      const std::vector<std::string> shipped = grid ? std::vector<std::string>{"grid"}
                                                    : std::vector<std::string>{"soccer", "wood"};
      const std::string nearest = NearestName(*t, shipped);
      std::error_code ec;
      if (std::count(shipped.begin(), shipped.end(), *t)) {
        p->content.texture = *t;
      } else if (!nearest.empty() && !fs::exists(base_ / *t, ec)) {
        // "Soccer" is a slip of the shipped texture's name, not an image file that happens to be missing.
        Problem(ptr + "/texture", "must be " + (grid ? std::string("grid") : "soccer or wood") +
                                      " or an image file (did you mean " + nearest + "?)", Json(*t));
      } else {
        p->content.texture = Path(v, "texture", ptr, true, FileUse::kImage).string();
      }
    }
  }
  if (object) {
    // Raised above the table: up to a metre.
    if (auto h = Number(v, "height_mm", ptr, false, 0, 1000, "mm")) p->content.height_mm = *h;
  }
  if (*type == ContentType::kGrid) {
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
  } else if (*type == ContentType::kBall) {
    Object(v, ptr, {"type", "texture", "radius_mm", "kernel", "brightness", "contrast", "white_balance",
                    "depth_blur_threshold", "height_mm", "exposure_ms"});
    // A ball rolls on the board's 25 mm squares: from a marble to a football.
    if (auto r = Number(v, "radius_mm", ptr, false, 1, 150, "mm")) p->content.radius_mm = *r;
    // A camera's exposure: up to a second (a longer one smears a rolling ball over much of the board).
    if (auto e = Number(v, "exposure_ms", ptr, false, 0, 1000, "ms"))
      p->content.exposure_ms = *e, p->content.exposure_given = true;
  } else {
    Object(v, ptr, {"type", "image", "real_photos", "real_camera"});
    p->content.image = Path(v, "image", ptr, true, FileUse::kImage);
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
    if (auto t = Word<InfoType>(f, "type", fp, false)) field.type = *t;
    const bool numeric = field.type == InfoType::kInteger || field.type == InfoType::kNumber;
    if (numeric) {
      auto lo = Number(f, "min", fp, true, -1e9, 1e9, ""), hi = Number(f, "max", fp, true, -1e9, 1e9, "");
      if (lo && hi && *lo >= *hi) Problem(fp + "/max", "must be larger than min", f["max"]);
      field.min = lo.value_or(0), field.max = hi.value_or(0);
    } else {
      for (const char* k : {"min", "max"})
        if (f.contains(k)) Problem(fp + "/" + k, "is for an integer or number field, not " + ToString(field.type), f[k]);
    }
    if (field.type == InfoType::kChoice) {
      const Json* c = Field(f, "choices", fp, true);
      if (c && (!c->is_array() || c->empty() || c->size() > 20))
        Problem(fp + "/choices", "must be a list of 1 to 20 answers", *c);
      else if (c)
        for (size_t k = 0; k < c->size(); ++k) {
          const Json& choice = (*c)[k];
          if (!choice.is_string() || choice.get<std::string>().empty() || Utf8Length(choice.get<std::string>()) > 100 ||
              !IsPrintableUtf8(choice.get<std::string>()) ||
              std::count(field.choices.begin(), field.choices.end(), choice.get<std::string>()))
            Problem(fp + "/choices/" + std::to_string(k), "must be a new answer of 1-100 characters", choice);
          else if (const std::string why = UnsafeIdReason(choice.get<std::string>()); !why.empty())
            Problem(fp + "/choices/" + std::to_string(k), why, choice);  // recorded as info_KEY, a name in the tables
          else if (CaseTwin(field.choices, choice.get<std::string>()))
            Problem(fp + "/choices/" + std::to_string(k), "must differ from an earlier answer by more than letter case",
                    choice);
          else
            field.choices.push_back(choice.get<std::string>());
        }
    } else if (f.contains("choices")) {
      Problem(fp + "/choices", "is for a choice field, not " + ToString(field.type), f["choices"]);
    }
    if (auto r = Bool(f, "required", fp)) field.required = *r;
    if (auto s = Text(f, "prompt", fp, false, 200, true)) field.prompt = *s;
    p->participant_info.push_back(std::move(field));
  }
}

void Parser::ParseGroups(const Json& v, const Json& top, const std::string& ptr, Protocol* p) {
  if (!Object(v, ptr, {"names", "assign"})) return;
  Groups g;
  if (auto a = Word<GroupAssign>(v, "assign", ptr, false)) g.assign = *a;
  const Json* names = Field(v, "names", ptr, true);
  if (names && (!names->is_array() || names->size() < 2 || names->size() > 20)) {
    Problem(ptr + "/names", "must be a list of 2 to 20 group names", *names);
    return;
  }
  if (names)
    for (size_t i = 0; i < names->size(); ++i) {
      const Json& n = (*names)[i];
      if (!n.is_string() || n.get<std::string>().empty() || Utf8Length(n.get<std::string>()) > kMaxNameChars ||
          !IsPrintableUtf8(n.get<std::string>()) ||
          std::count(g.names.begin(), g.names.end(), n.get<std::string>()))
        Problem(ptr + "/names/" + std::to_string(i), "must be a new name of 1-100 characters", n);
      else if (const std::string why = UnsafeIdReason(n.get<std::string>()); !why.empty())
        Problem(ptr + "/names/" + std::to_string(i), why, n);
      else if (CaseTwin(g.names, n.get<std::string>()))
        Problem(ptr + "/names/" + std::to_string(i), "must differ from an earlier name by more than letter case", n);
      else
        g.names.push_back(n.get<std::string>());
    }
  p->groups = g;
  (void)top;
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
  if (p.layout == Layout::kOddOneOut) r->cant_tell = "";
  if (v.is_null()) return;
  std::vector<std::string> fields = Words<ResponseKey>();
  fields.insert(fields.end(), {"rating", "alternatives", "prompt", "after_motion"});
  if (!Object(v, ptr, fields)) return;
  auto key_name = [&](const Json& value, const std::string& at) -> std::optional<std::string> {
    if (!value.is_string()) return Problem(at, "must be a key name", value), std::nullopt;
    const std::string s = value.get<std::string>();
    if (s == "Escape") return Problem(at, "Escape is reserved for pausing a session", value), std::nullopt;
    if (!IsKeyName(s))
      return Problem(at, "must be a key name: A-Z, 0-9, Left, Right, Up, Down, Space, Return, Tab, Backspace, F1-F12 "
                         "or KP_0-KP_9" + DidYouMean(s, KeyNames()), value), std::nullopt;
    return s;
  };
  const std::string cant_tell = ToString(ResponseKey::kCantTell);
  std::map<std::string, std::string*> slots;
  for (const ResponseKey field : Vocabulary<ResponseKey>::values) slots[ToString(field)] = &r->Slot(field);
  for (auto& [key, slot] : slots) {
    if (!v.contains(key)) continue;
    // cant_tell: null makes a strict 2AFC: no key answers can't tell.
    if (key == cant_tell && v[key].is_null()) {
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
  // Each task's keys (TaskTraits::keys) are read when a block has the task; an odd one out answers with its
  // intervals' keys, not left and right.
  for (const Task task : Vocabulary<Task>::values)
    for (const std::string& key : TraitsOf(task).keys) {
      const bool read = tasks.count(task) > 0;
      const bool intervals = p.layout == Layout::kOddOneOut && TraitsOf(task).answer == TaskAnswer::kSide &&
                             key != cant_tell;
      unused(key.c_str(), read && !intervals,
             read ? "is not read by the layout odd_one_out (its intervals have /responses/alternatives)"
                  : "is for the task " + ToString(task) + ", which no block has");
    }
  unused("alternatives", p.layout == Layout::kOddOneOut, "is for the layout odd_one_out");
  auto distinct = [&](const std::vector<std::pair<std::string, std::string>>& set) {
    for (size_t i = 0; i < set.size(); ++i)
      for (size_t j = 0; j < i; ++j)
        if (set[i].second == set[j].second)
          Problem(ptr + "/" + set[i].first, "is the same key as /responses/" + set[j].first, Json(set[i].second));
  };
  // A task's single keys (a rating's list is checked below) must differ; a strict 2AFC has no can't-tell key.
  for (const Task task : tasks) {
    std::vector<std::pair<std::string, std::string>> keys;
    for (const std::string& key : TraitsOf(task).keys)
      if (const auto it = slots.find(key); it != slots.end() && !it->second->empty()) keys.emplace_back(key, *it->second);
    distinct(keys);
  }
  auto distinct_list = [&](const char* key, const std::vector<std::string>& keys) {
    for (size_t i = 0; i < keys.size(); ++i)
      for (size_t j = 0; j < i; ++j)
        if (keys[i] == keys[j])
          Problem(ptr + "/" + key + "/" + std::to_string(i), "is the same key as /responses/" + std::string(key) + "/" + std::to_string(j),
                  Json(keys[i]));
  };
  for (const Task task : tasks)
    if (TraitsOf(task).answer == TaskAnswer::kRatingPoint) distinct_list("rating", r->rating);
  if (p.layout == Layout::kOddOneOut) distinct_list("alternatives", r->alternatives);
}
// The protocol's timing (at /timing) or a block's (at /blocks/N/timing): each field given is checked and set in `t`,
// so a block's fields override the protocol's and the others stay as inherited.
void Parser::ParseTiming(const Json& v, const std::string& ptr, const Protocol& p,
                         const std::vector<const Block*>& blocks, Timing* t) {
  if (!Object(v, ptr, {"stimulus_ms", "inter_trial_ms", "interval_ms", "isi_ms", "deadline_ms", "feedback_ms",
                       "fixation_ms"}))
    return;
  if (const Json* s = Field(v, "stimulus_ms", ptr, false)) {
    // From about a frame to a minute.
    if (s->is_string() && *s == "until_response") t->stimulus_ms = 0;
    else if (NumberIn(*s, 10, 60000)) t->stimulus_ms = s->get<double>();
    else Problem(ptr + "/stimulus_ms", "must be a duration in " + Range(10, 60000, "ms") + " or \"until_response\"" +
                                           (s->is_string() ? DidYouMean(s->get<std::string>(), {"until_response"}) : ""),
                 *s);
  }
  if (auto x = Number(v, "inter_trial_ms", ptr, false, 0, 60000, "ms")) t->inter_trial_ms = *x;
  if (auto x = Number(v, "interval_ms", ptr, false, 100, 10000, "ms")) t->interval_ms = *x;
  if (auto x = Number(v, "isi_ms", ptr, false, 0, 10000, "ms")) t->isi_ms = *x;
  if (auto x = Number(v, "deadline_ms", ptr, false, 100, 60000, "ms")) t->deadline_ms = *x;
  if (auto x = Number(v, "feedback_ms", ptr, false, 100, 5000, "ms")) t->feedback_ms = *x;
  if (auto x = Number(v, "fixation_ms", ptr, false, 100, 5000, "ms")) t->fixation_ms = *x;
  // Feedback needs a correct answer: a procedure's, an odd one out's, or a practice run to a criterion's.
  const bool correct = p.layout == Layout::kOddOneOut || std::any_of(blocks.begin(), blocks.end(), [](const Block* b) {
                         return b->procedure || b->criterion;
                       });
  if (v.contains("feedback_ms") && !correct)
    Problem(ptr + "/feedback_ms", "needs a correct answer: a block with a procedure or a criterion, or the "
                                  "layout odd_one_out, defines one", v["feedback_ms"]);
  const bool untimed =
      std::any_of(blocks.begin(), blocks.end(), [](const Block* b) { return !TraitsOf(b->task).deadline; });
  if (v.contains("deadline_ms") && untimed)
    Problem(ptr + "/deadline_ms", "is for a forced choice, yes/no or rating; adjustment runs until a level is "
                                  "accepted", v["deadline_ms"]);
  for (const char* key : {"interval_ms", "isi_ms"})
    if (v.contains(key) && IntervalCount(p) == 0)
      Problem(ptr + "/" + key, "is for the layouts two_intervals and odd_one_out", v[key]);
  if (v.contains("stimulus_ms") && IntervalCount(p) > 0)
    Problem(ptr + "/stimulus_ms", "intervals are timed by interval_ms and isi_ms", v["stimulus_ms"]);
}

}  // namespace blurcue::protocol::detail
