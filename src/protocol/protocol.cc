#include "protocol/protocol.h"

#include "protocol/parser.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <cmath>
#include <functional>
#include <map>
#include <set>

#include "core/error.h"
#include "core/limits.h"
#include "core/names.h"
#include "core/typed.h"

namespace blurcue::protocol {
namespace fs = std::filesystem;

namespace detail {

Protocol Parser::Parse(const Json& json) {
  Protocol p;
  p.file = file_;
  if (!Object(json, "",
              {"$schema", "name", "version", "description", "scene", "content", "task", "factors", "conditions",
               "repetitions", "counterbalance", "sides", "adjust", "blocks", "block_order", "practice", "instructions",
               "breaks", "responses", "timing", "display", "participant_info", "groups", "layout", "alternatives"}))
    return p;
  if (auto s = Name(json, "name", "", true)) p.name = *s;
  if (auto n = Int(json, "version", "", true, 1, 1000000)) p.version = *n;
  if (auto s = Text(json, "description", "", false, 5 * kMaxTextChars, false)) p.description = *s;
  if (auto s = Text(json, "instructions", "", false, kMaxTextChars, false)) p.instructions = *s;
  const bool typed = ParseContentAndScene(json, &p);
  // Protocol-level design fields are checked where they are written even when no block inherits them.
  if (json.contains("factors")) ParseFactors(json["factors"], "/factors");
  if (json.contains("sides")) ParseSides(json["sides"], "/sides");
  if (json.contains("adjust")) ParseAdjust(json["adjust"], "/adjust");
  if (json.contains("repetitions")) Int(json, "repetitions", "", true, 1, kMaxTrials, "repetitions");
  if (json.contains("counterbalance"))
    Word<Counterbalance>(json, "counterbalance", "", true);
  if (json.contains("task")) Word<Task>(json, "task", "", true);

  ParseBlocks(json, &p);
  ParsePractice(json, &p);
  ParseLayout(json, typed, &p);
  if (const Json* v = Field(json, "participant_info", "", false)) ParseInfo(*v, "/participant_info", &p);
  if (const Json* v = Field(json, "groups", "", false)) ParseGroups(*v, json, "/groups", &p);
  if (const Json* v = Field(json, "breaks", "", false)) {
    if (Object(*v, "/breaks", {"every_trials", "text"})) {
      if (auto n = Int(*v, "every_trials", "/breaks", true, 1, kMaxTrials, "trials")) p.break_every_trials = *n;
      if (auto s = Text(*v, "text", "/breaks", false, kMaxTextChars, false)) p.break_text = *s;
    }
  }
  CheckRealPhotos(json, p);
  ParseResponsesAndTiming(json, &p);
  ParseDisplay(json, typed, &p);
  CheckDesign(p);
  p.conditions_tables = tables_;
  return p;
}

// content and scene: which scene a content needs. True when the file gives a valid content type.
bool Parser::ParseContentAndScene(const Json& json, Protocol* out) {
  Protocol& p = *out;
  if (const Json* v = Field(json, "content", "", true)) ParseContent(*v, "/content", &p);
  // Whether the file gives a valid content type (ParseContent then set it): the checks that depend on it stay
  // silent when it is missing or invalid (already reported).
  const bool typed = json.contains("content") && json["content"].is_object() && json["content"].contains("type") &&
                     json["content"]["type"].is_string() &&
                     ParseWord<ContentType>(json["content"]["type"].get<std::string>()).has_value();
  const ContentType type = p.content.type;
  // A depth matching with real photos shows no scene photo: its lower half is the real photo of each distance.
  const bool real_photos = typed && type == ContentType::kPicture && json["content"].contains("real_photos");
  if (const Json* v = Field(json, "scene", "", !real_photos)) {
    if (real_photos)
      Problem("/scene", "is not shown: with content.real_photos the lower half shows the real photo of each distance", *v);
    else
      ParseScene(*v, "/scene", &p);
  }
  if (typed && type == ContentType::kPicture && json.contains("scene") && json["scene"].is_object() &&
      json["scene"].contains("calib"))
    Problem("/scene/calib", "is not read by a picture (the real picture's blur comes from /content/real_camera)",
            json["scene"]["calib"]);
  if (typed && type == ContentType::kPicture && json.contains("scene") && json["scene"].is_object() &&
      json["scene"].contains("video"))
    Problem("/scene/video", "is for a grid or a ball (a picture's depth matching shows photos)", json["scene"]["video"]);
  if (json.contains("scene") && json["scene"].is_object() && !json["scene"].contains("calib") &&
      !json["scene"].contains("video") && !json["scene"].contains("track") &&
      (typed && (type == ContentType::kGrid || type == ContentType::kBall)))
    Problem("/scene/calib", "is required for a " + ToString(type) + " (its blur comes from the calibration) but missing");

  return typed;
}

// The blocks, or the one block of a file without "blocks" (the top level is its own).
void Parser::ParseBlocks(const Json& json, Protocol* out) {
  Protocol& p = *out;
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
                            "adjust", "procedure", "instructions", "shuffle", "groups", "practice", "criterion",
                            "title", "prompt", "timing"}))
        continue;
      Block b;
      if (auto s = Name(obj, "name", bp, true)) {
        for (const auto& other : p.blocks)
          if (other.name == *s) Problem(bp + "/name", "repeats the name of an earlier block", Json(*s));
        b.name = *s;
      }
      ParseBlock(obj, bp, json, &b);
      p.blocks.push_back(std::move(b));
    }
  }
}

// The protocol's practice: how many trials, drawn from which block.
void Parser::ParsePractice(const Json& json, Protocol* out) {
  Protocol& p = *out;
  if (const Json* v = Field(json, "practice", "", false)) {
    if (Object(*v, "/practice", {"count", "block", "instructions"})) {
      if (auto n = Int(*v, "count", "/practice", true, 0, 1000, "trials")) p.practice.count = *n;
      if (auto s = Text(*v, "instructions", "/practice", false, kMaxTextChars, false)) p.practice.instructions = *s;
      p.practice.block = p.blocks.empty() ? "" : p.blocks.front().name;
      if (auto s = String(*v, "block", "/practice", false)) {
        bool found = false;
        for (const auto& b : p.blocks) found = found || b.name == *s;
        std::vector<std::string> names;
        for (const auto& b : p.blocks) names.push_back(b.name);
        if (!found) Problem("/practice/block", "names no block of this protocol" + DidYouMean(*s, names), Json(*s));
        p.practice.block = *s;
        p.practice.block_given = true;
      }
    }
  }
}

// block_order, layout and alternatives, and what the layout makes of each procedure's guess rate.
void Parser::ParseLayout(const Json& json, bool typed, Protocol* out) {
  Protocol& p = *out;
  const ContentType type = p.content.type;
  if (auto order = Word<BlockSequence>(json, "block_order", "", false)) p.block_order = *order;
  if (auto layout = Word<Layout>(json, "layout", "", false)) {
    p.layout = *layout;
    if (p.layout != Layout::kSideBySide && typed && type == ContentType::kPicture)
      Problem("/layout", "is for grids and balls; a picture is shown in its depth-matching frame",
              Json(ToString(*layout)));
  }
  if (p.layout == Layout::kOddOneOut) p.alternatives = 3;
  if (json.contains("alternatives")) {
    if (auto n = Int(json, "alternatives", "", true, 3, 6, "intervals")) p.alternatives = *n;
    if (p.layout != Layout::kOddOneOut)
      Problem("/alternatives", "is for the layout odd_one_out (the intervals of an odd-one-out trial)", json["alternatives"]);
  }
  // A procedure's guess rate is the chance of a right answer by guessing: 1/n of an odd-one-out trial's n intervals
  // (QUEST+'s likelihood and a staircase's threshold posterior, procedure/threshold_fit.h, both use it).
  if (p.layout == Layout::kOddOneOut) {
    for (auto& b : p.blocks) {
      if (b.procedure && b.procedure->kind == Procedure::Kind::kStaircase) {
        b.procedure->guess = 1.0 / p.alternatives;
      } else if (b.procedure && b.procedure->kind == Procedure::Kind::kQuestPlus) {
        if (!b.procedure->guess_given) b.procedure->guess = 1.0 / p.alternatives;
        else if (std::abs(b.procedure->guess - 1.0 / p.alternatives) > 1e-3)
          Problem(b.pointer + "/procedure/guess", "an odd-one-out trial of " + std::to_string(p.alternatives) +
                                                      " intervals is guessed right 1/" + std::to_string(p.alternatives) +
                                                      " of the time; leave guess out", Json(b.procedure->guess));
      }
    }
  }
  // An up/down rule that converges at or below what guessing gives measures no threshold (3-up/1-down: 20.6 % of a
  // 2AFC's answers correct, which no participant goes below): refused here rather than 'not determined' after a study.
  for (const auto& b : p.blocks)
    if (b.procedure && b.procedure->kind == Procedure::Kind::kStaircase) {
      const double target = StaircaseTarget(b.procedure->up, b.procedure->down);
      if (!(target > b.procedure->guess + 0.01)) {
        char text[300];
        std::snprintf(text, sizeof text,
                      "a %d-up/%d-down staircase converges on %.1f %% correct, at or below what guessing gives here "
                      "(%.1f %%): it measures no threshold; step down after more correct answers in a row (down) "
                      "than it steps up after wrong ones",
                      b.procedure->up, b.procedure->down, 100 * target, 100 * b.procedure->guess);
        Problem(b.pointer + "/procedure/down", text, Json(b.procedure->down));
      }
    }
}

// The real photos: one per distance the design shows.
void Parser::CheckRealPhotos(const Json& json, const Protocol& p) {
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
}

// responses, then timing: the protocol's, and each block's resolved over it.
void Parser::ParseResponsesAndTiming(const Json& json, Protocol* out) {
  Protocol& p = *out;
  std::set<Task> tasks;
  for (const auto& b : p.blocks) tasks.insert(b.task);
  const Json* responses = Field(json, "responses", "", false);
  ParseResponses(responses ? *responses : Json(), "/responses", tasks, p, &p.responses);
  std::vector<const Block*> every_block;
  for (const auto& b : p.blocks) every_block.push_back(&b);
  if (const Json* v = Field(json, "timing", "", false)) ParseTiming(*v, "/timing", p, every_block, &p.timing);
  // What a block's trials read is resolved here, once: its timing is the protocol's with each field the block gives
  // overriding it, its prompt the protocol's unless it gives its own.
  for (auto& b : p.blocks) {
    b.timing = p.timing;
    if (b.prompt.empty()) b.prompt = p.responses.prompt;
    if (b.pointer.empty()) continue;  // the one block of a file without blocks: the top level is its own
    const Json& obj = json.at(Json::json_pointer(b.pointer));
    if (const Json* v = Field(obj, "timing", b.pointer, false)) ParseTiming(*v, b.pointer + "/timing", p, {&b}, &b.timing);
  }
}

// display: the window, the monitor and how the photo maps to the screen.
void Parser::ParseDisplay(const Json& json, bool typed, Protocol* out) {
  Protocol& p = *out;
  const ContentType type = p.content.type;
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
        else Problem("/display/scale", "must be \"fit\", \"native\" or screen px per photo px in " + Range(0.05, 8, "") +
                                           (s->is_string() ? DidYouMean(s->get<std::string>(), {"fit", "native"}) : ""),
                     *s);
      }
      if (auto x = Number(*v, "width_deg", "/display", false, 0.5, 180, "deg")) {
        if (v->contains("scale")) Problem("/display/width_deg", "give either scale or width_deg, not both", *x);
        else p.display.scaling = Scaling::kDegrees, p.display.width_deg = *x;
      }
      if ((v->contains("scale") || v->contains("width_deg")) && typed && type == ContentType::kPicture)
        Problem(v->contains("scale") ? "/display/scale" : "/display/width_deg",
                "a picture's frame is always fitted to the window at one screen px per frame px; leave it out",
                v->contains("scale") ? (*v)["scale"] : (*v)["width_deg"]);
    }
  }
}

// The design as a whole, once every field is valid: what each block shows fits the content, every trial has
// the levels its content needs, and the session's size is within the cap.
void Parser::CheckDesign(const Protocol& p) {
  if (calls_ > 0) return;  // a design built from fields with problems would only repeat them
  CheckGroups(p);
  for (const auto& b : p.blocks) {
    CheckBlockLevels(p, b);
    CheckBlockLayout(p, b);
  }
  CheckSessionSize(p);
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
  CheckGroupPractice(p);
  for (const auto& b : p.blocks)
    if (b.name == p.practice.block && p.practice.count > DesignTrials(b) && DesignTrials(b) <= kMaxTrials)
      Problem("/practice/count", "asks for " + std::to_string(p.practice.count) + " practice trials but block " +
                                     b.name + " has only " + std::to_string(DesignTrials(b)),
              Json(p.practice.count));
}

// Groups: a block names only the protocol's groups, and every group runs at least one block.
void Parser::CheckGroups(const Protocol& p) {
  for (const auto& b : p.blocks)
    for (size_t i = 0; i < b.groups.size(); ++i)
      if (!p.groups || std::find(p.groups->names.begin(), p.groups->names.end(), b.groups[i]) == p.groups->names.end())
        Problem((b.pointer.empty() ? std::string() : b.pointer) + "/groups/" + std::to_string(i),
                p.groups ? "names no group of /groups/names" + DidYouMean(b.groups[i], p.groups->names)
                         : "names a group but the protocol declares no /groups",
                Json(b.groups[i]));
  if (p.groups)
    for (const auto& g : p.groups->names)
      if (std::none_of(p.blocks.begin(), p.blocks.end(), [&](const Block& b) {
            return b.groups.empty() || std::count(b.groups.begin(), b.groups.end(), g);
          }))
        Problem("/groups/names", "group " + g + " runs no block", Json(g));
}

// What block `b` shows fits the content: its task, and the levels that place or move a stimulus.
void Parser::CheckBlockLevels(const Protocol& p, const Block& b) {
  const ContentType type = p.content.type;
  const std::string type_name = ToString(type), layout_name = ToString(p.layout);
  // The renderer draws a picture for adjustment (cut-offs) and a pair of grids or balls for forced choice.
  const TaskTraits& task = TraitsOf(b.task);
  const bool picture_task = task.shows == TaskShows::kPicture;
  if (type == ContentType::kPicture && !picture_task)
    Problem(b.task_pointer, "must be " + TaskWords([](const TaskTraits& t) { return t.shows == TaskShows::kPicture; }) +
                                " for a picture (forced_choice compares a pair of grids or balls)",
            Json(ToString(b.task)));
  if (type != ContentType::kPicture && picture_task)
    Problem(b.task_pointer, "must be forced_choice for a " + type_name + " (adjustment steps through the cut-offs of a "
                            "picture)", Json(ToString(b.task)));
  // A level that places or moves a stimulus is read only by the content it is for: anywhere else it would be
  // recorded but not shown.
  static const std::map<ContentType, std::set<std::string>> kUses = {
      {ContentType::kGrid, {"edge", "y_mm", "left_x_mm", "right_x_mm", "height_mm", "rotation_deg"}},
      {ContentType::kBall, {"edge", "from_edge", "to_edge", "section", "speed_cm_s", "y_mm", "from_y_mm", "to_y_mm",
                "left_x_mm", "right_x_mm", "height_mm"}},
      {ContentType::kPicture, {"distance_m"}}};
  static const std::set<std::string> kStimulusLevels = {"edge",      "from_edge",  "to_edge",   "section",
                                                        "speed_cm_s", "distance_m", "y_mm",      "from_y_mm",
                                                        "to_y_mm",   "left_x_mm",  "right_x_mm", "height_mm",
                                                        "rotation_deg"};
  const auto uses = kUses.find(type);
  for (const auto& f : b.factors) {
    std::set<std::string> names{f.name};
    for (const Level& level : f.levels)
      for (const auto& [key, value] : level.fields) names.insert(key);
    for (const auto& name : names)
      if (kStimulusLevels.count(name) && uses != kUses.end() && !uses->second.count(name))
        Problem(b.factors_pointer + "/" + f.name,
                "a " + type_name + " does not use " + name + " (it would be recorded but not shown); a " + type_name +
                    " uses " + [&] {
                      std::string list;
                      for (const auto& u : uses->second) list += (list.empty() ? "" : ", ") + u;
                      return list;
                    }());
  }
  // Every layout but side_by_side draws its objects - the single one, each interval's - at the left one's place,
  // and intervals hold them still: a level that places the right object, or ends a run in intervals, would be
  // recorded but not shown. Named at the factor, or at the first level (a conditions table's row) that gives it.
  if (uses != kUses.end() && type != ContentType::kPicture && p.layout != Layout::kSideBySide) {
    std::vector<std::pair<std::string, std::string>> unshown = {
        {"right_x_mm", "the layout " + layout_name + " shows every object at the left one's place (move it with "
                       "left_x_mm): a right_x_mm level would be recorded but not shown"}};
    if (IntervalCount(p) > 0)
      for (const char* end : {"to_edge", "to_y_mm"})
        unshown.push_back({end, std::string("intervals show still objects, where a run would start: a ") + end +
                                    " level would be recorded but not shown"});
    for (const auto& [name, why] : unshown)
      for (const auto& f : b.factors) {
        if (f.name == name) {
          Json levels = Json::array();
          for (const Level& level : f.levels) levels.push_back(ToJson(level));
          Problem(b.factors_pointer + "/" + JsonPointerToken(f.name), why, levels);
          continue;
        }
        for (size_t i = 0; i < f.levels.size(); ++i)
          if (const LevelValue* value = f.levels[i].Field(name)) {
            Problem(b.factors_pointer + "/" + JsonPointerToken(f.name) + "/" + std::to_string(i) + "/" + name, why,
                    ToJson(*value));
            break;
          }
      }
  }
  if (IntervalCount(p) > 0 && Provides(b, "speed_cm_s"))
    Problem(b.factors_pointer, "intervals show still objects: a speed_cm_s level would move them");
}

// What block `b` asks fits the layout: the task, the sides, and the levels a grid or real photos need.
void Parser::CheckBlockLayout(const Protocol& p, const Block& b) {
  const ContentType type = p.content.type;
  const std::string layout_name = ToString(p.layout);
  const TaskTraits& task = TraitsOf(b.task);
  // The layout decides the question: one object is answered yes/no or rated, a pair or N intervals chosen from.
  const bool one = task.shows == TaskShows::kOneObject;
  if (p.layout == Layout::kSingle && type != ContentType::kPicture && !one)
    Problem(b.task_pointer, "must be " + TaskWords([](const TaskTraits& t) { return t.shows == TaskShows::kOneObject; }) +
                                " for the layout single (one object: nothing to choose between)",
            Json(ToString(b.task)));
  if (p.layout != Layout::kSingle && one)
    Problem(b.task_pointer, "is for the layout single (one object); a " + layout_name + " trial is a forced choice",
            Json(ToString(b.task)));
  if (p.layout == Layout::kSingle && b.counterbalance != Counterbalance::kNone)
    Problem(b.counterbalance_pointer, "must be none for the layout single (one object: no sides to swap)",
            Json(ToString(b.counterbalance)));
  if (p.layout == Layout::kSingle && b.procedure)
    Problem(b.pointer + "/procedure", "needs a forced choice (layouts side_by_side, two_intervals, odd_one_out)");
  // "object" is the single layout's one source; a pair layout reads left and right.
  bool object = b.sides && b.sides->object;
  bool pair = b.sides && !b.sides->object;
  for (const auto& f : b.factors)
    for (const Level& level : f.levels) {
      object = object || level.Field("object");
      pair = pair || level.Field(ToString(Side::kLeft));
    }
  if (p.layout == Layout::kSingle && pair)
    Problem(b.sides ? b.sides_pointer : b.factors_pointer,
            "the layout single shows one object: give \"object\", not left and right");
  if (p.layout != Layout::kSingle && object)
    Problem(b.sides ? b.sides_pointer : b.factors_pointer,
            "\"object\" is for the layout single; a " + layout_name + " trial shows left and right");
  if (type == ContentType::kGrid && !Provides(b, "edge") && !Provides(b, "y_mm"))
    Problem(b.factors_pointer, "a grid stands at an edge: needs a factor edge (or y_mm), or a factor whose every "
                               "level has an edge (1..11 on the thesis's board)");
  if (type == ContentType::kPicture && !p.content.real_photos.empty() && !Provides(b, "distance_m"))
    Problem(b.factors_pointer, "content.real_photos chooses the photo by distance: needs a factor distance_m, or "
                               "a factor whose every level has a distance_m");
}

// The session's size: within kMaxTrials (and the blocks' shares spelled out when it is not), and not empty.
void Parser::CheckSessionSize(const Protocol& p) {
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
}

// Each group practises its own condition: the protocol's practice is drawn from one block for every participant,
// so a block that only some groups run would show the other groups a condition they never run (issue 38).
void Parser::CheckGroupPractice(const Protocol& p) {
  if (p.groups && p.practice.count > 0)
    for (const auto& b : p.blocks)
      if (b.name == p.practice.block && !b.groups.empty()) {
        std::string runs, others;
        for (const auto& g : p.groups->names) {
          std::string& list = std::count(b.groups.begin(), b.groups.end(), g) ? runs : others;
          list += (list.empty() ? "" : ", ") + g;
        }
        if (others.empty()) continue;
        Problem(p.practice.block_given ? "/practice/block" : "/practice",
                (p.practice.block_given ? "names block " + b.name
                                        : "draws from block " + b.name + " (the first; /practice/block names none)") +
                    ", which only group" + (b.groups.size() > 1 ? "s " : " ") + runs +
                    " run" + (b.groups.size() > 1 ? "" : "s") + ": group " + others +
                    " would practise another group's condition; give each group a practice block of its own "
                    "(\"practice\": true, \"groups\": [...]) or practise on a block every group runs",
                Json(b.name));
      }
  // A practice block of its own for some groups must show their condition: its sides those of a block they run, not
  // only of a block other groups run (the adversary's practice block for no_blur showing measured vs estimated).
  if (p.groups)
    for (const auto& b : p.blocks) {
      if (!b.practice || b.groups.empty() || !b.sides) continue;
      auto same = [&](const Block& o) {
        return o.sides && o.sides->object == b.sides->object && ToJson(o.sides->left) == ToJson(b.sides->left) &&
               ToJson(o.sides->right) == ToJson(b.sides->right);
      };
      auto runs = [](const Block& o, const std::string& g) {
        return o.groups.empty() || std::count(o.groups.begin(), o.groups.end(), g) > 0;
      };
      for (const auto& g : b.groups) {
        bool own = false;
        const Block* other = nullptr;
        for (const auto& o : p.blocks) {
          if (o.practice || !o.sides) continue;
          if (runs(o, g)) own = own || same(o);
          else if (same(o)) other = &o;
        }
        if (!own && other)
          Problem(b.sides_pointer.empty() ? b.pointer + "/sides" : b.sides_pointer,
                  "practice block " + b.name + " for group " + g + " shows the sides of block " + other->name +
                      ", which group " + g + " never runs: it would practise another group's condition; give it the "
                      "sides of a block group " + g + " runs",
                  ToJson(b.sides->left));
      }
    }
}

// True when every trial of `b` has a level `name`: a factor of that name, or a factor whose levels all carry it.
bool Parser::Provides(const Block& b, const std::string& name) {
  for (const auto& f : b.factors) {
    if (f.name == name) return true;
    if (!f.levels.empty() &&
        std::all_of(f.levels.begin(), f.levels.end(), [&](const Level& level) { return level.Field(name); }))
      return true;
  }
  return false;
}

}  // namespace detail

using detail::Parser;

std::string CheckInfoValue(const InfoField& f, const std::string& value) {
  switch (f.type) {
    case InfoType::kInteger:
    case InfoType::kNumber: {
      const bool integer = f.type == InfoType::kInteger;
      const std::optional<double> x = ParseDecimal(value);
      if (!x || (integer && !IsWholeDecimal(value)) || *x < f.min || *x > f.max) {
        char range[96];
        std::snprintf(range, sizeof range, "%s in [%g, %g]", integer ? "a whole number" : "a number", f.min, f.max);
        return std::string("must be ") + range;
      }
      return "";
    }
    case InfoType::kChoice: {
      if (std::find(f.choices.begin(), f.choices.end(), value) != f.choices.end()) return "";
      std::string list;
      for (const auto& c : f.choices) list += (list.empty() ? "" : ", ") + c;
      return "must be one of " + list + DidYouMean(value, f.choices);
    }
    case InfoType::kText: break;
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
  switch (protocol.layout) {
    case Layout::kTwoIntervals: return 2;
    case Layout::kOddOneOut: return protocol.alternatives;
    case Layout::kSideBySide:
    case Layout::kSingle: return 0;
  }
  return 0;
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

std::set<double> NumericLevels(const Protocol& protocol, const std::string& factor) {
  std::set<double> values;
  for (const auto& b : protocol.blocks)
    for (const auto& f : b.factors)
      for (const Level& level : f.levels) {
        // As FindLevel finds it in a trial: the factor itself, or a key of its object levels.
        const LevelValue* v = f.name == factor ? (level.object ? nullptr : &level.value) : level.Field(factor);
        if (v && v->IsNumber()) values.insert(v->number);
      }
  return values;
}

std::string BoardLevelsText(int cols, int rows) {
  return std::to_string(cols) + " x " + std::to_string(rows) + " squares: edges 1-" + std::to_string(rows + 1) +
         ", sections 1-" + std::to_string(rows) + " between them";
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

std::string RecordedText(const std::string& text, const Protocol& protocol) {
  if (protocol.conditions_tables.empty()) return text;
  Json json = ParseJson(text, protocol.file.string());
  Json& tables = json["recorded_conditions"] = Json::object();
  for (const auto& [path, table] : protocol.conditions_tables) tables[path] = table;
  return json.dump(2, ' ', false, Json::error_handler_t::replace);
}

double DownRunFirst(double p, int up, int down) {
  const double q = 1 - p;
  const double a = std::pow(p, down - 1), b = std::pow(q, up - 1);
  const double denominator = a + b - a * b;
  return denominator > 0 ? a * (1 - std::pow(q, up)) / denominator : 0.5;
}

double StaircaseTarget(int up, int down) {
  // DownRunFirst rises from 0 at p = 0 to 1 at p = 1: bisection for its 1/2.
  double lo = 0, hi = 1;
  for (int i = 0; i < 100; ++i) {
    const double mid = (lo + hi) / 2;
    (DownRunFirst(mid, up, down) < 0.5 ? lo : hi) = mid;
  }
  return (lo + hi) / 2;
}

}  // namespace blurcue::protocol
