#include "protocol/parser.h"

#include <algorithm>

#include "core/names.h"

namespace blurcue::protocol::detail {

std::optional<Adjustment> Parser::ParseAdjust(const Json& v, const std::string& ptr) {
  if (!Object(v, ptr, {"parameter", "levels", "order"})) return std::nullopt;
  Adjustment a;
  // The renderer steps through Butterworth cut-offs of a picture; no other parameter is drawn.
  if (auto s = String(v, "parameter", ptr, false, {"cutoff"})) a.parameter = *s;
  if (auto order = Word<AdjustOrder>(v, "order", ptr, false)) a.order = *order;
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

std::optional<Procedure> Parser::ParseProcedure(const Json& v, const std::string& ptr) {
  if (!v.is_object()) {
    Problem(ptr, "must be an object (type staircase or quest_plus)", v);
    return std::nullopt;
  }
  const auto kind = Word<ProcedureKind>(v, "type", ptr, true);
  if (!kind) return std::nullopt;
  Procedure pr;
  pr.kind = *kind;
  const bool quest = pr.kind == Procedure::Kind::kQuestPlus;
  if (quest)
    Object(v, ptr, {"type", "variable", "reference", "trials", "stimuli", "threshold", "slope", "lapse", "guess"});
  else
    Object(v, ptr, {"type", "variable", "reference", "trials", "start", "min", "max", "up", "down", "steps", "stop"});
  if (auto variable = Word<ProcedureVariable>(v, "variable", ptr, true)) pr.variable = *variable;
  // What the level can be: up to 20 times more blur, or up to 10 degrees more.
  const bool relative = pr.variable == ProcedureVariable::kRelativeDifference;
  const double hi = relative ? 20 : 600;
  const std::string unit = relative ? "(times the reference)" : "arcmin";
  if (const Json* r = Field(v, "reference", ptr, true)) {
    CheckLevelValue(ToString(Side::kLeft), *r, ptr + "/reference");
    if (IsBlurSource(*r)) pr.reference = BlurSpecOf(*r);
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

std::optional<Block::Sides> Parser::ParseSides(const Json& v, const std::string& ptr) {
  // A source as typed, when it is one (a problem is reported for any other).
  auto typed = [](const Json& source) -> std::optional<BlurSpec> {
    return IsBlurSource(source) ? std::optional<BlurSpec>(BlurSpecOf(source)) : std::nullopt;
  };
  if (!v.is_object()) {
    Object(v, ptr, {ToString(Side::kLeft), ToString(Side::kRight), "object"});
    return std::nullopt;
  }
  Block::Sides sides;
  // The single layout shows one "object"; the others a pair, left and right.
  if (v.contains("object")) {
    sides.object = true;
    if (Object(v, ptr, {"object"})) {
      CheckLevelValue("object", v["object"], ptr + "/object");
      sides.left = sides.right = typed(v["object"]);
    }
    return sides;
  }
  const std::string left = ToString(Side::kLeft), right = ToString(Side::kRight);
  if (!Object(v, ptr, {left, right, "object"})) return sides;
  if (const Json* s = Field(v, left, ptr, true)) CheckLevelValue(left, *s, ptr + "/" + left), sides.left = typed(*s);
  if (const Json* s = Field(v, right, ptr, true))
    CheckLevelValue(right, *s, ptr + "/" + right), sides.right = typed(*s);
  return sides;
}

// How block `b` runs, from its own fields only: its screens, order, practice and criterion, and groups.
void Parser::ParseBlockRun(const Json& obj, const std::string& ptr, Block* b) {
  const TaskTraits& task = TraitsOf(b->task);
  if (auto s = Text(obj, "instructions", ptr, false, kMaxTextChars, false)) b->instructions = *s;
  // What the participant sees: a title of one line, a prompt of its own (the timing is read once the layout is known).
  // Blank (spaces only) is empty: it used to pass and open the block with no title on screen.
  auto blank = [](const std::string& t) { return t.find_first_not_of(' ') == std::string::npos; };
  if (auto s = Text(obj, "title", ptr, false, 100, true)) {
    if (blank(*s)) Problem(ptr + "/title", "must not be empty (leave it out for \"Part n of N\")", Json(*s));
    b->title = *s;
  }
  if (auto s = Text(obj, "prompt", ptr, false, 200, true)) {
    if (blank(*s)) Problem(ptr + "/prompt", "must not be empty (leave it out for /responses/prompt)", Json(*s));
    b->prompt = *s;
  }
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
    if (!task.scored || b->procedure)
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
             auto t = Word<Task>(*s.holder, "task", s.ptr, true)) {
    b->task = *t;
  }
  b->pointer = ptr;
  const size_t calls_before_factors = calls_;
  const Source factors = pick("factors"), conditions = pick("conditions");
  if (factors.holder && conditions.holder)
    Problem(conditions.ptr + "/conditions", "give either factors or a conditions table, not both",
            (*conditions.holder)["conditions"]);
  else if (conditions.holder)
    b->factors = ParseConditions(*conditions.holder, conditions.ptr + "/conditions"),
    b->factors_pointer = conditions.ptr + "/conditions",
    b->conditions = (*conditions.holder)["conditions"].is_string() ? (*conditions.holder)["conditions"].get<std::string>() : "";
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
    if (auto c = Word<Counterbalance>(*s.holder, "counterbalance", s.ptr, true)) b->counterbalance = *c;
  }
  const Source sides = pick("sides");
  if (sides.holder) {
    b->sides = ParseSides((*sides.holder)["sides"], sides.ptr + "/sides");
    b->sides_pointer = sides.ptr + "/sides";
  }
  const Source adjust = pick("adjust");
  const TaskTraits& task = TraitsOf(b->task);
  if (adjust.holder && task.answer == TaskAnswer::kLevel)
    b->adjust = ParseAdjust((*adjust.holder)["adjust"], adjust.ptr + "/adjust");
  if (obj.is_object() && obj.contains("procedure")) {
    b->procedure = ParseProcedure(obj["procedure"], ptr + "/procedure");
    // The procedure says what each side shows and how often: the design fields that would say it too are refused.
    if (!task.scored || task.answer != TaskAnswer::kSide)
      Problem(b->task_pointer, "must be " + TaskWords([](const TaskTraits& t) {
                                 return t.scored && t.answer == TaskAnswer::kSide;
                               }) + " for a procedure (which side is more blurred?)",
              Json(ToString(b->task)));
    if (sides.holder) Problem(sides.ptr + "/sides", "is given but the procedure shows its reference on both sides",
                              (*sides.holder)["sides"]);
    if (b->repetitions != 1) Problem(ptr + "/procedure/trials", "sets how often each crossing runs: leave out "
                                                                "repetitions", Json(b->repetitions));
    if (b->counterbalance != Counterbalance::kNone)
      Problem(b->counterbalance_pointer, "must be none for a procedure (the test side is drawn at random per trial)",
              Json(ToString(b->counterbalance)));
  }
  ParseBlockRun(obj, ptr, b);

  // What is shown left and right must be known for a comparison, and for any left/right counterbalancing.
  bool factor_sides = false;
  for (const auto& f : b->factors)
    for (const auto& level : f.levels) factor_sides |= level.Field(ToString(Side::kLeft)) || level.Field("object");
  const std::string where = ptr.empty() ? "/" : ptr;
  if (factor_sides && sides.holder)
    Problem(sides.ptr + "/sides", "is given but a factor's levels already carry the sides (left and right, or object)",
            (*sides.holder)["sides"]);
  const bool needs_sides =
      !b->procedure && (task.shows == TaskShows::kPair || b->counterbalance != Counterbalance::kNone);
  if (needs_sides && factors_ok && !factor_sides && !sides.holder)
    Problem(where, "needs what is shown left and right: a \"sides\" object or a factor whose levels have left and "
                   "right (a forced choice or left/right counterbalancing compares two sides)");
  if (task.shows == TaskShows::kOneObject && factors_ok && !factor_sides && !sides.holder)
    Problem(where, "needs the object shown: \"sides\": {\"object\": SOURCE} or a factor whose levels have an object "
                   "(a " + ToString(b->task) + " trial shows one object)");
  if (task.answer == TaskAnswer::kLevel && !adjust.holder)
    Problem(ptr + "/adjust", "is required for the " + ToString(b->task) + " task (here or at /adjust) but missing");
}
}  // namespace blurcue::protocol::detail
