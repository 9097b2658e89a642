// The record's column table (columns.h) and what is generated from it for the schema, the INSERTs and the merge.
#include "store/columns.h"
#include "store/frame_columns.h"

#include <deque>
#include <iterator>
#include <optional>
#include <type_traits>

#include "core/error.h"
#include "protocol/vocabulary.h"
#include "store/record.h"
#include "store/sqlite.h"

namespace blurcue::store {
namespace {

Value Optional(const std::optional<double>& value) { return value ? Value(*value) : Value(); }
Value NonEmpty(const std::string& text) { return text.empty() ? Value() : Value(text); }
// A number of the display profile the session records whole, typed.
Value ProfileNumber(const Json& profile, const char* key) {
  if (profile.is_object() && profile.contains(key) && profile[key].is_number()) return profile[key].get<double>();
  return {};
}

// A kept place with no accessor (a column the shipped migrations made and the record writes itself).
Stored Plain(const std::string& table, const std::string& column, const std::string& sql, int since) {
  Stored s;
  s.table = table;
  s.column = column;
  s.sql = sql;
  s.since = since;
  return s;
}
Stored Typed(const std::string& table, const std::string& sql, const std::string& check, int since,
             const std::string& derive = "") {
  Stored s = Plain(table, "", sql, since);
  s.check = check;
  s.derive = derive;
  return s;
}
// A side's source and fixed radius as a record of before version 7 kept them: the side's JSON (a source's name, a
// number of photo px, or an object of screen_px or arcmin).
std::string SourceOf(const std::string& column) {
  return "CASE json_type(" + column + ") WHEN 'text' THEN json_extract(" + column + ", '$') "
         "WHEN 'integer' THEN 'fixed_px' WHEN 'real' THEN 'fixed_px' "
         "WHEN 'object' THEN CASE WHEN json_extract(" + column + ", '$.screen_px') IS NOT NULL "
         "THEN 'fixed_screen_px' ELSE 'fixed_arcmin' END END";
}
std::string FixedOf(const std::string& column) {
  return "CASE json_type(" + column + ") WHEN 'integer' THEN json_extract(" + column + ", '$') "
         "WHEN 'real' THEN json_extract(" + column + ", '$') "
         "WHEN 'object' THEN coalesce(json_extract(" + column + ", '$.screen_px'), json_extract(" + column +
         ", '$.arcmin')) END";
}
// A member of RecordedVariables as the variables' JSON holds it: a flag as 1 | 0, a number or text as it is.
template <typename T>
std::function<Json(const RecordedVariables&)> Member(std::optional<T> RecordedVariables::*member) {
  return [member](const RecordedVariables& v) -> Json {
    const std::optional<T>& x = v.*member;
    if (!x) return Json();
    if constexpr (std::is_same_v<T, bool>) return Json(int64_t(*x ? 1 : 0));
    else return Json(*x);
  };
}
// One place's radius of RecordedVariables::r_px, r_screen_px or r_arcmin.
std::function<Json(const RecordedVariables&)> Radius(
    std::array<std::optional<double>, RecordedVariables::kSides> RecordedVariables::*radii, size_t place) {
  return [radii, place](const RecordedVariables& v) { return (v.*radii)[place] ? Json(*(v.*radii)[place]) : Json(); };
}
// One side's member of RecordedVariables::sides.
std::function<Json(const RecordedVariables&)> OfSide(std::optional<double> SideVariables::*member, size_t side) {
  return [member, side](const RecordedVariables& v) {
    const std::optional<double>& x = v.sides[side].*member;
    return x ? Json(*x) : Json();
  };
}

Stored OfSession(Stored s, std::function<Value(const SessionValues&)> of) { return s.of_session = std::move(of), s; }
Stored OfTrial(Stored s, std::function<Value(const TrialRecord&)> of) { return s.of_trial = std::move(of), s; }
Stored OfResponse(Stored s, std::function<Value(const Response&)> of) { return s.of_response = std::move(of), s; }

// Builds the record's column table in order, one row per call; a row stays where it is (a deque) while the rest of
// it is set through the reference the call returns.
class ColumnList {
 public:
  // One row: name, codebook type, unit, allowed, meaning, place, cell; the rest set on the returned row.
  Column& operator()(const std::string& name, const std::string& type, const std::string& unit,
                     const std::string& allowed, const std::string& meaning, Place place, Cell cell) {
    Column column;
    column.name = name, column.type = type, column.unit = unit, column.allowed = allowed;
    column.meaning = meaning, column.place = place, column.cell = cell;
    rows_.push_back(std::move(column));
    return rows_.back();
  }
  // A variable the runner records in the trial's variables' JSON, read from RecordedVariables by `read`.
  void Variable(const std::string& name, const std::string& type, const std::string& unit, const std::string& meaning,
                std::function<Json(const RecordedVariables&)> read) {
    (*this)(name, type, unit, "", meaning, Place::kVariable, Cell::kText).variable = std::move(read);
  }
  std::vector<Column> Take() { return {std::make_move_iterator(rows_.begin()), std::make_move_iterator(rows_.end())}; }

 private:
  std::deque<Column> rows_;
};

// The places of the table's rows, short: the rows read as a table.
constexpr Place S = Place::kSession, T = Place::kTrial, V = Place::kVariable, A = Place::kAnswer, N = Place::kNone;

// The session's columns, and the display profile's geometry kept typed.
void AddSessionColumns(ColumnList& add) {
  // The session's.
  add("study", "string", "", "", "the protocol's name", S, Cell::kText).at = Plain("studies", "name", "TEXT", 1);
  add("protocol_hash", "string", "", "16 hex digits", "FNV-1a-64 of the protocol's canonical text: its version", S,
      Cell::kText).at = Plain("protocol_versions", "hash", "TEXT", 1);
  Column& version = add("protocol_version", "integer", "", ">= 1",
                         "the protocol's declared \"version\" the session ran (one text per version of a study)", S,
                         Cell::kInteger);
  version.at = Typed("protocol_versions", "INTEGER", "version >= 1", 8);
  version.at.column = "version";  // written by the record with the protocol version (EnsureProtocolVersion)
  add("participant", "string", "", "", "the participant's id", S, Cell::kText).at = Plain("participants", "code", "TEXT", 1);
  Column& observer = add("observer", "string", "", "person|simulated",
                         "who answered: a person, or blurcue's simulated observer", S, Cell::kText);
  observer.if_null = "person";  // a record of before the typed columns that no migration filled
  observer.at = OfSession(Typed("sessions", "TEXT", "observer IN ('person', 'simulated')", 7,
                                "CASE WHEN instr(display, '; observer ') > 0 THEN 'simulated' ELSE 'person' END"),
                          [](const SessionValues& s) { return Value(s.meta.simulated ? "simulated" : "person"); });
  add("observer_params", "string", "", "", "the simulated observer's parameters (sim:model=arcmin,... or sim:model=pixel,...; before model= existed sim:jnd=..., the pixel model); empty for a person", S, Cell::kText)
      .at = OfSession(Typed("sessions", "TEXT", "", 7,
                            "CASE WHEN instr(display, '; observer ') > 0 "
                            "THEN substr(display, instr(display, '; observer ') + 11) ELSE '' END"),
                      [](const SessionValues& s) { return Value(s.meta.observer_params); });
  add("window", "boolean", "", "0|1", "1: shown in a real window on the real clock; 0: headless on a simulated clock",
      S, Cell::kInteger)
      .at = OfSession(Typed("sessions", "INTEGER", "window IN (0, 1)", 7, "(display LIKE 'window%')"),
                      [](const SessionValues& s) { return Value(int64_t(s.meta.window ? 1 : 0)); });
  // The display profile's geometry, typed from the profile the session records whole; trials.csv leaves it out.
  add("profile_name", "string", "", "", "the display profile's name", N, Cell::kText)
      .at = OfSession(Typed("sessions", "TEXT", "", 7, "json_extract(display_profile, '$.name')"), [](const SessionValues& s) {
        const Json& p = s.profile;
        return p.is_object() && p.contains("name") && p["name"].is_string() ? Value(p["name"].get<std::string>())
                                                                              : Value();
      });
  add("screen_width_mm", "number", "mm", "", "the screen's width (display profile)", N, Cell::kNumber)
      .at = OfSession(Typed("sessions", "REAL", "", 7, "json_extract(display_profile, '$.width_mm')"),
                      [](const SessionValues& s) { return ProfileNumber(s.profile, "width_mm"); });
  add("screen_height_mm", "number", "mm", "", "the screen's height (display profile)", N, Cell::kNumber)
      .at = OfSession(Typed("sessions", "REAL", "", 7, "json_extract(display_profile, '$.height_mm')"),
                      [](const SessionValues& s) { return ProfileNumber(s.profile, "height_mm"); });
  add("viewing_distance_mm", "number", "mm", "", "the eye's distance to the screen (display profile)", N, Cell::kNumber)
      .at = OfSession(Typed("sessions", "REAL", "", 7, "json_extract(display_profile, '$.distance_mm')"),
                      [](const SessionValues& s) { return ProfileNumber(s.profile, "distance_mm"); });
  add("px_per_deg", "number", "screen px / deg", "", "screen pixels per degree of visual angle (display profile)", N,
      Cell::kNumber)
      .at = OfSession(Typed("sessions", "REAL", "", 7, "json_extract(display_profile, '$.px_per_deg')"),
                      [](const SessionValues& s) { return ProfileNumber(s.profile, "px_per_deg"); });
  add("session_id", "integer", "", ">= 1", "the session's id in this record (merged records renumber it)", S,
      Cell::kInteger).at = Plain("sessions", "id", "INTEGER", 1);
  add("session_number", "integer", "", ">= 1", "the participant's n-th session of this study, in the order started",
      S, Cell::kInteger)
      .at = OfSession(Typed("sessions", "INTEGER", "session_number >= 1", 8),
                      [](const SessionValues& s) { return Value(s.number); });
  add("session_status", "string", "", "running|completed|aborted",
      "the session's status when exported: running (unfinished: stopped, killed or still being written; blurcue "
      "report leaves its answers out unless --include-unfinished), completed, or aborted (closed with blurcue sessions --abort; blurcue report leaves its answers out unless "
      "--include-aborted)", S, Cell::kText).at = Plain("sessions", "status", "TEXT", 1);
  add("seed", "string", "", "s followed by 1-20 digits",
      "the seed of the session's trial order, a 64-bit unsigned integer written with a leading s so that spreadsheets, "
      "R and JavaScript keep every digit; blurcue run --seed takes it as written", S, Cell::kSeed)
      .at = Plain("sessions", "seed", "INTEGER", 1);
}

// The trial's columns.
void AddTrialColumns(ColumnList& add) {
  // The trial's.
  add("trial_index", "integer", "", ">= 0", "the trial's place in the session, practice included, from 0", T,
      Cell::kInteger).at = Plain("trials", "trial_index", "INTEGER", 1);
  add("block", "integer", "", ">= 0", "the block's place in the protocol's list of blocks, from 0", T, Cell::kInteger)
      .at = Plain("trials", "block", "INTEGER", 1);
  Column& block_name = add("block_name", "string", "", "", "the block's name", T, Cell::kText);
  block_name.in_variables = true, block_name.variable = Member(&RecordedVariables::block_name);
  block_name.at = OfTrial(Typed("trials", "TEXT", "", 7, "coalesce(json_extract(factors, '$.block_name'), '')"), [](const TrialRecord& t) { return Value(t.block_name); });
  std::string tasks;  // the task vocabulary's words, as the protocol spells them
  for (const std::string& word : protocol::Words<protocol::Task>()) tasks += (tasks.empty() ? "" : "|") + word;
  add("task", "string", "", tasks, "the trial's task", T, Cell::kText)
      .at = OfTrial(Typed("trials", "TEXT", "", 7,
                          "CASE WHEN json_extract(factors, '$.start_level') IS NOT NULL THEN 'adjustment' "
                          "ELSE 'forced_choice' END"),
                    [](const TrialRecord& t) { return Value(t.task); });
  Column& practice = add("practice", "boolean", "", "0|1", "1: a practice trial (not scored)", T, Cell::kInteger);
  practice.if_null = "0", practice.in_variables = true, practice.variable = Member(&RecordedVariables::practice);
  practice.at = OfTrial(Typed("trials", "INTEGER", "practice IN (0, 1)", 7,
                              "coalesce(json_extract(factors, '$.practice'), 0) <> 0"),
                        [](const TrialRecord& t) { return Value(int64_t(t.practice ? 1 : 0)); });
  Column& swapped = add("swapped", "boolean", "", "0|1",
                        "1: left and right exchanged against the design (counterbalancing)", T, Cell::kInteger);
  swapped.if_null = "0", swapped.in_variables = true, swapped.variable = Member(&RecordedVariables::swapped);
  swapped.at = OfTrial(Typed("trials", "INTEGER", "swapped IN (0, 1)", 7,
                             "coalesce(json_extract(factors, '$.swapped'), 0) <> 0"),
                       [](const TrialRecord& t) { return Value(int64_t(t.swapped ? 1 : 0)); });
  add("cell", "string", "", "",
      "a procedure trial's cell by its levels (NAME=LEVEL;... of its block's factors): its own track and threshold; "
      "empty outside a procedure and in records made before cells were recorded", T, Cell::kText)
      .at = OfTrial(Typed("trials", "TEXT", "", 8), [](const TrialRecord& t) { return NonEmpty(t.cell); });
}

// Each side's source and fixed radius (named by SideColumn), and a procedure's level.
void AddSourceColumns(ColumnList& add) {
  // Each side's source, with the answer in trials.csv; in schema 7's order before the planned radii.
  const std::string sources = SourceColumns::Names();
  for (const protocol::Side side : protocol::Vocabulary<protocol::Side>::values) {
    const std::string word = protocol::ToString(side), shown = SideColumn("", side, "shown");
    const size_t k = protocol::Index(side);
    add(SideColumn("", side, "source"), "string", "", sources,
        "the " + word + " side's blur source" + (side == protocol::Side::kLeft ? " (the single layout's object)" : "") +
            "; empty: none shown",
        A, Cell::kText)
        .at = OfTrial(Typed("trials", "TEXT", "", 7, SourceOf(shown)),
                      [k](const TrialRecord& t) { return NonEmpty(SourceColumns::Of(t.source_json[k]).source); });
    add(SideColumn("", side, "fixed"), "number", "the source's unit", ">= 0",
        "a fixed_* " + word + " source's radius, in the unit its name says", A, Cell::kNumber)
        .at = OfTrial(Typed("trials", "REAL", "", 7, FixedOf(shown)),
                      [k](const TrialRecord& t) { return Optional(SourceColumns::Of(t.source_json[k]).fixed); });
  }

  // The runner's variables of a trial (session/recording.h TrialVariables), kept in its variables' JSON (factors; a
  // response's shown for what a procedure decided at the trial). Those also kept typed come first, in schema 7's order.
  Column& level = add("level", "number", "the procedure's variable", "",
                      "a procedure trial: the level shown, in the procedure's variable (procedures.csv: "
                      "relative_difference, ratio - 1: the test radius / the reference's - 1; difference_arcmin: "
                      "arcmin added on the screen); the unit is the design's where the record says", V,
                      Cell::kText);
  level.variable = Member(&RecordedVariables::level);
  level.shown = OfResponse(Typed("responses", "REAL", "", 7, "json_extract(shown, '$.level')"),
                           [](const Response& r) { return Optional(r.level); });
}

// The answer's columns, decided from it when exported, and whether it was correct.
void AddAnswerColumns(ColumnList& add) {
  // The answer.
  add("status", "string", "", "answered|timed_out|skipped|unanswered",
      "answered; timed_out: no answer before the deadline; skipped: not shown (a stopped procedure, a practice "
      "criterion met); unanswered: not reached", A, Cell::kAnswer).answer = Answer::kStatus;
  add("chosen_side", "string", "", "left|right|cant_tell",
      "forced choice of a pair: the side chosen (two intervals: left = the first, right = the second)", A, Cell::kAnswer)
      .answer = Answer::kChosenSide;
  add("chose_more_blurred", "boolean", "", "0|1",
      "forced choice of a pair: 1 when the side chosen showed the larger blur radius; empty when the radii were "
      "equal or no side was chosen", A, Cell::kAnswer).answer = Answer::kChoseMoreBlurred;
  add("chosen_interval", "integer", "", "1..alternatives", "odd one out: the interval named", A, Cell::kAnswer)
      .answer = Answer::kChosenInterval;
  add("yes_no", "string", "", "yes|no", "yes_no task: the answer", A, Cell::kAnswer).answer = Answer::kYesNo;
  add("rating", "integer", "", "1..points", "rating task: the point of the scale chosen (1 the lowest)", A,
      Cell::kAnswer).answer = Answer::kRating;
  add("adjusted_level", "number", "the adjusted parameter's unit", "", "adjustment: the level accepted", A,
      Cell::kAnswer).answer = Answer::kAdjustedLevel;
  // Scored once, when the answer is given (records from before: by the migration to schema 8), never by the export.
  Column& correct = add("correct", "boolean", "", "0|1",
                        "1: the answer was correct (procedure trials, odd one out); empty where no answer is correct",
                        A, Cell::kInteger);
  correct.in_variables = true, correct.variable = Member(&RecordedVariables::correct);
  correct.at = OfResponse(Typed("responses", "INTEGER", "correct IN (0, 1)", 7, "json_extract(shown, '$.correct')"), [](const Response& r) {
    return r.correct ? Value(int64_t(*r.correct ? 1 : 0)) : Value();
  });
}

// Each place's radius in photo px, screen px and arcmin; the response time and when it was recorded.
void AddRadiusColumns(ColumnList& add) {
  // Each radius as the camera made it, on the screen and at the eye; the photo px ones also typed, planned (trials)
  // and as shown (responses), for a procedure decides them at the trial.
  for (size_t k = 0; k < RecordedVariables::kSides; ++k) {
    const std::string side = RecordedVariables::SideName(k);
    const std::string what = k == 2 ? "the scene's own blur at the object's place (the fitted model; depth "
                                               "matching: the real picture's, the thin lens of content.real_camera)"
                                             : "the " + side + " object's blur radius";
    const std::string name = SideColumn("r", side, "px");
    Column& px = add(name, "number", "photo px",
                     "", what + ", as the camera makes it (moving: averaged over the run)", V, Cell::kText);
    px.variable = Radius(&RecordedVariables::r_px, k);
    // Before version 7 only the variables' JSON had it, planned (factors) and as shown (shown).
    const Stored planned = Typed("trials", "REAL", "", 7, "json_extract(factors, '$." + name + "')");
    const Stored shown = Typed("responses", "REAL", "", 7, "json_extract(shown, '$." + name + "')");
    if (k == RecordedVariables::kScene) {
      px.at = OfTrial(planned, [](const TrialRecord& t) { return Optional(t.r_scene_px); });
    } else {
      px.at = OfTrial(planned, [k](const TrialRecord& t) { return Optional(t.r_px[k]); });
      px.shown = OfResponse(shown, [k](const Response& r) { return Optional(r.r_px[k]); });
    }
    add(SideColumn("r", side, "screen_px"), "number", "screen px", "", what + ", on the screen", V, Cell::kText)
        .variable = Radius(&RecordedVariables::r_screen_px, k);
    add(SideColumn("r", side, "arcmin"), "number", "arcmin", "", what + ", at the eye", V, Cell::kText).variable =
        Radius(&RecordedVariables::r_arcmin, k);
  }
  Column& rt = add("rt_ms", "number", "ms", ">= 0", "response time from the stimulus's first frame; empty without an answer",
                   A, Cell::kNumber);
  rt.at = Plain("responses", "rt_ms", "REAL", 1);
  add("answered_at", "datetime", "", "", "when the answer was recorded (UTC)", A, Cell::kText)
      .at = Plain("responses", "answered_at", "TEXT", 1);
}

// The rest of the runner's variables of a trial.
void AddVariableColumns(ColumnList& add) {
  using R = RecordedVariables;
  add.Variable("screen_px_per_photo_px", "number", "screen px / photo px", "how the photo was scaled onto the screen", Member(&R::screen_px_per_photo_px));
  add.Variable("kernel", "string", "", "the blur kernel (gaussian | disc)", Member(&R::kernel));
  add.Variable("blur_plan", "string", "", "one_radius: each object blurred with one radius; per_pixel: by depth",
           Member(&R::blur_plan));
  add.Variable("r_span_screen_px", "number", "screen px", "the largest change of a radius across an object's depth", Member(&R::r_span_screen_px));
  // The PSF beside each radius (render/psf.h): the lens floor inside it and the motion streak over the exposure.
  add.Variable("exposure_ms", "number", "ms", "the exposure a moving object's motion blur lasts (content.exposure_ms; 0: none)",
           Member(&R::exposure_ms));
  using SV = SideVariables;
  for (size_t k = 0; k < 2; ++k) {
    const std::string side = RecordedVariables::SideName(k);
    add.Variable(SideColumn("floor_sigma", side, "px"), "number", "photo px",
             "the lens floor (std) inside the " + side + " object's radius: the scene's, for a measured, measured_section "
             "or fitted source (its defocus drawn convolved with it); 0 for the others",
             OfSide(&SV::floor_sigma_px, k));
    add.Variable(SideColumn("floor_sigma", side, "screen_px"), "number", "screen px", "the same on the screen",
             OfSide(&SV::floor_sigma_screen_px, k));
    add.Variable(SideColumn("motion", side, "x_screen_px"), "number", "screen px",
             "the " + side + " object's motion streak over the exposure, across (x right), averaged over the run",
             OfSide(&SV::motion_x_screen_px, k));
    add.Variable(SideColumn("motion", side, "y_screen_px"), "number", "screen px",
             "the " + side + " object's motion streak over the exposure, down (y down), averaged over the run",
             OfSide(&SV::motion_y_screen_px, k));
  }
  // Where each object is: its depth (what an edge number stands for) and, as the eye gets it, its height in the picture.
  for (size_t k = 0; k < 2; ++k) {
    const std::string side = RecordedVariables::SideName(k);
    add.Variable(SideColumn("u", side, "mm"), "number", "mm",
             "the " + side + " object's depth u: its centre's distance from the camera's lens plane along the optical "
             "axis (camera z in the calibration's board pose), where its radius was evaluated (an intervals trial: the "
             "left object's place); a ball: averaged over its run like the radii", OfSide(&SV::u_mm, k));
    add.Variable(SideColumn("elevation", side, "deg"), "number", "deg",
             "the " + side + " object's place in the picture as a visual angle: its centre's image above (+) or below "
             "(-) the photo's principal point (where the camera's optical axis meets the photo), on the display, "
             "atan(offset on the screen / viewing distance); not its angular size (" + SideColumn("size", side, "deg") +
             "); a ball: averaged over its run", OfSide(&SV::elevation_deg, k));
  }
  for (size_t k = 0; k < 2; ++k) {
    const std::string side = RecordedVariables::SideName(k);
    add.Variable(SideColumn("size", side, "deg"), "number", "deg",
             "the " + side + " object's largest extent on screen at onset", OfSide(&SV::size_deg, k));
  }
  add.Variable("brightness", "number", "", "the object's brightness matching (factor of its texture's values)", Member(&R::brightness));
  add.Variable("contrast", "number", "", "the object's contrast matching", Member(&R::contrast));
  add.Variable("white_balance_r", "number", "", "the object's red gain in linear light", Member(&R::white_balance_r));
  add.Variable("white_balance_g", "number", "", "the object's green gain in linear light", Member(&R::white_balance_g));
  add.Variable("white_balance_b", "number", "", "the object's blue gain in linear light", Member(&R::white_balance_b));
  add.Variable("start_level", "number", "the adjusted parameter's unit", "adjustment: the level shown first", Member(&R::start_level));
  add.Variable("adjust_levels", "string", "the adjusted parameter's unit",
           "adjustment: the levels in the order the next key steps through them (cyclic), separated by ;",
           Member(&R::adjust_levels));
  add.Variable("picture_width_arcmin", "number", "arcmin",
           "depth matching: the virtual picture's width at the eye (a cut-off c's blur is r = 2 x 0.1874 x this / c)", Member(&R::picture_width_arcmin));
  add.Variable("procedure_cell", "integer", "", "a procedure trial: which crossing of its block's factors (its own procedure)", Member(&R::procedure_cell));
  add.Variable("test_side", "string", "", "a procedure trial: the side (or odd-one-out interval) showing the procedure's level", Member(&R::test_side));
  add.Variable("reversals", "integer", "", "a staircase trial: the staircase's reversals before this answer (or when it stopped)", Member(&R::reversals));
  add.Variable("skipped", "string", "", "why a trial was not shown (stop rule: its staircase had ended)", Member(&R::skipped));
  add.Variable("posterior_threshold", "number", "the procedure's variable",
           "a QUEST+ trial: the posterior mean of the threshold after this answer (its running estimate)", Member(&R::posterior_threshold));
  add.Variable("posterior_slope", "number", "", "a QUEST+ trial: the posterior mean of the slope after this answer", Member(&R::posterior_slope));
  add.Variable("round", "integer", "", "a practice block run until a criterion: which run of its design (from 1)", Member(&R::round));
  add.Variable("odd_interval", "integer", "", "odd one out: the interval that showed the right side's object (the correct answer)", Member(&R::odd_interval));
  add.Variable("intervals", "integer", "", "odd one out: intervals per trial", Member(&R::intervals));
}

std::vector<Column> MakeColumns() {
  ColumnList add;
  AddSessionColumns(add);
  AddTrialColumns(add);
  AddSourceColumns(add);
  AddAnswerColumns(add);
  AddRadiusColumns(add);
  AddVariableColumns(add);
  return add.Take();
}

// The export's alias of each table the record keeps a variable in.
std::string Alias(const std::string& table) {
  if (table == "studies") return "st";
  if (table == "protocol_versions") return "pv";
  if (table == "participants") return "p";
  if (table == "sessions") return "s";
  if (table == "trials") return "t";
  if (table == "responses") return "r";
  throw Error(ErrorKind::kInternal, "columns: no alias for table " + table);
}


// Binds the typed columns of `table` each read by `read` (its accessor, or null for one the record writes elsewhere).
template <typename Read>
void BindEach(const std::vector<Column>& columns, const std::string& table, Statement& insert, int first, Read read) {
  for (const Kept& kept : KeptIn(columns, table, 7)) BindValue(insert, first++, read(*kept.stored));
}

}  // namespace

const std::vector<Column>& RecordColumns() {
  static const std::vector<Column> columns = MakeColumns();
  return columns;
}

std::string RecordedVariables::SideName(size_t k) {
  return k < 2 ? protocol::ToString(protocol::Vocabulary<protocol::Side>::values[k]) : std::string("scene");
}

std::string SideColumn(const std::string& quantity, const std::string& side, const std::string& suffix) {
  return (quantity.empty() ? "" : quantity + "_") + side + (suffix.empty() ? "" : "_" + suffix);
}

std::string SideColumn(const std::string& quantity, protocol::Side side, const std::string& suffix) {
  return SideColumn(quantity, protocol::ToString(side), suffix);
}

Json VariablesJson(const RecordedVariables& variables) {
  Json json = Json::object();
  for (const Column& column : RecordColumns())
    if (column.variable)
      if (Json value = column.variable(variables); !value.is_null()) json[column.name] = std::move(value);
  return json;
}

std::string ColumnName(const Column& column, const Stored& stored) {
  return stored.column.empty() ? column.name : stored.column;
}

std::string SelectOf(const Column& column) {
  if (!column.select.empty()) return column.select;
  return Alias(column.at.table) + "." + ColumnName(column, column.at);
}

std::vector<Kept> KeptIn(const std::vector<Column>& columns, const std::string& table, int since) {
  std::vector<Kept> kept;
  for (const Column& column : columns)
    for (const Stored* stored : {&column.at, &column.shown})
      if (stored->table == table && stored->since >= since) kept.push_back({&column, stored, ColumnName(column, *stored)});
  return kept;
}

std::string AddColumnsSql(const std::vector<Column>& columns, int version) {
  std::string sql;
  for (const char* table : {"protocol_versions", "sessions", "trials", "responses"})
    for (const Kept& kept : KeptIn(columns, table, version))
      if (kept.stored->since == version)
        sql += std::string("ALTER TABLE ") + table + " ADD COLUMN " + kept.name + " " + kept.stored->sql +
               (kept.stored->check.empty() ? std::string() : " CHECK (" + kept.stored->check + ")") + ";";
  return sql;
}

std::string DerivedColumnsSql(const std::vector<Column>& columns, const std::string& table) {
  std::string set;
  for (const Kept& kept : KeptIn(columns, table, 7))
    if (kept.stored->since == 7) set += (set.empty() ? "" : ", ") + kept.name + " = " + kept.stored->derive;
  return set;
}

// The INSERTs of sessions, trials and responses write the typed columns their rows give (protocol_versions.version
// is written with the protocol version, not by an INSERT of these).
std::string InsertNames(const std::vector<Column>& columns, const std::string& table) {
  std::string names;
  for (const Kept& kept : KeptIn(columns, table, 7)) names += ", " + kept.name;
  return names;
}

std::string InsertPlaceholders(const std::vector<Column>& columns, const std::string& table) {
  std::string marks;
  for (size_t i = 0; i < KeptIn(columns, table, 7).size(); ++i) marks += ", ?";
  return marks;
}

void BindTyped(const std::vector<Column>& columns, Statement& insert, int first, const SessionValues& session) {
  BindEach(columns, "sessions", insert, first,
           [&](const Stored& s) { return s.of_session ? s.of_session(session) : Value(); });
}

void BindTyped(const std::vector<Column>& columns, Statement& insert, int first, const TrialRecord& trial) {
  BindEach(columns, "trials", insert, first, [&](const Stored& s) { return s.of_trial ? s.of_trial(trial) : Value(); });
}

void BindTyped(const std::vector<Column>& columns, Statement& insert, int first, const Response& response) {
  BindEach(columns, "responses", insert, first,
           [&](const Stored& s) { return s.of_response ? s.of_response(response) : Value(); });
}

}  // namespace blurcue::store
