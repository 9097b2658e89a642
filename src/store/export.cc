#include "store/export.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <optional>
#include <set>
#include <string>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/hash.h"
#include "core/json_io.h"
#include "core/typed.h"
#include "store/export_procedures.h"
#include "store/export_table.h"
#include "store/record.h"
#include "store/schema.h"
#include "store/sqlite.h"

#include <sqlite3.h>

namespace blurcue::store {
namespace {

// The fixed columns of trials.csv before the design's variables, and after them.
const std::vector<ColumnDef>& TrialColumnsBefore() {
  static const std::vector<ColumnDef> columns = {
      {"study", "string", "", "", "the protocol's name"},
      {"protocol_hash", "string", "", "16 hex digits", "FNV-1a-64 of the protocol's canonical text: its version"},
      {"protocol_version", "integer", "", ">= 1",
       "the protocol's declared \"version\" the session ran (one text per version of a study)"},
      {"participant", "string", "", "", "the participant's id"},
      {"observer", "string", "", "person|simulated", "who answered: a person, or blurcue's simulated observer"},
      {"observer_params", "string", "", "", "the simulated observer's parameters (sim:model=arcmin,... or sim:model=pixel,...; before model= existed sim:jnd=..., the pixel model); empty for a person"},
      {"window", "boolean", "", "0|1", "1: shown in a real window on the real clock; 0: headless on a simulated clock"},
      {"session_id", "integer", "", ">= 1", "the session's id in this record (merged records renumber it)"},
      {"session_number", "integer", "", ">= 1", "the participant's n-th session of this study, in the order started"},
      {"session_status", "string", "", "running|completed|aborted",
       "the session's status when exported: running (unfinished: stopped, killed or still being written), "
       "completed, or aborted (closed with blurcue sessions --abort; blurcue report leaves its answers out unless "
       "--include-aborted)"},
      {"seed", "string", "", "s followed by 1-20 digits",
       "the seed of the session's trial order, a 64-bit unsigned integer written with a leading s so that spreadsheets, "
       "R and JavaScript keep every digit; blurcue run --seed takes it as written"},
  };
  return columns;
}

const std::vector<ColumnDef>& TrialColumnsDesign() {
  static const std::vector<ColumnDef> columns = {
      {"trial_index", "integer", "", ">= 0", "the trial's place in the session, practice included, from 0"},
      {"block", "integer", "", ">= 0", "the block's place in the protocol's list of blocks, from 0"},
      {"block_name", "string", "", "", "the block's name"},
      {"task", "string", "", "forced_choice|adjustment|yes_no|rating", "the trial's task"},
      {"practice", "boolean", "", "0|1", "1: a practice trial (not scored)"},
      {"swapped", "boolean", "", "0|1", "1: left and right exchanged against the design (counterbalancing)"},
      {"cell", "string", "", "",
       "a procedure trial's cell by its levels (NAME=LEVEL;... of its block's factors): its own track and threshold; "
       "empty outside a procedure and in records made before cells were recorded"},
  };
  return columns;
}

const std::vector<ColumnDef>& TrialColumnsAfter() {
  static const std::string sources = "none|measured|measured_section|estimated|fitted|fixed_px|fixed_screen_px|fixed_arcmin";
  static const std::vector<ColumnDef> columns = {
      {"left_source", "string", "", sources, "the left side's blur source (the single layout's object); empty: none shown"},
      {"left_fixed", "number", "the source's unit", ">= 0", "a fixed_* left source's radius, in the unit its name says"},
      {"right_source", "string", "", sources, "the right side's blur source; empty: none shown"},
      {"right_fixed", "number", "the source's unit", ">= 0", "a fixed_* right source's radius, in the unit its name says"},
      {"status", "string", "", "answered|timed_out|skipped|unanswered",
       "answered; timed_out: no answer before the deadline; skipped: not shown (a stopped procedure, a practice "
       "criterion met); unanswered: not reached"},
      {"chosen_side", "string", "", "left|right|cant_tell",
       "forced choice of a pair: the side chosen (two intervals: left = the first, right = the second)"},
      {"chose_more_blurred", "boolean", "", "0|1",
       "forced choice of a pair: 1 when the side chosen showed the larger blur radius; empty when the radii were "
       "equal or no side was chosen"},
      {"chosen_interval", "integer", "", "1..alternatives", "odd one out: the interval named"},
      {"yes_no", "string", "", "yes|no", "yes_no task: the answer"},
      {"rating", "integer", "", "1..points", "rating task: the point of the scale chosen (1 the lowest)"},
      {"adjusted_level", "number", "the adjusted parameter's unit", "", "adjustment: the level accepted"},
      {"correct", "boolean", "", "0|1", "1: the answer was correct (procedure trials, odd one out); empty where no answer is correct"},
      {"rt_ms", "number", "ms", ">= 0", "response time from the stimulus's first frame; empty without an answer"},
      {"answered_at", "datetime", "", "", "when the answer was recorded (UTC)"},
  };
  return columns;
}

// What the runner records beside the factor levels (session/stimulus.h TrialVariables): the codebook's words for
// them. Any other column is a factor of the protocol (or a column of its conditions table, or a level's value).
const std::map<std::string, ColumnDef>& KnownVariables() {
  static const std::map<std::string, ColumnDef> known = [] {
    std::map<std::string, ColumnDef> m;
    auto add = [&](const std::string& name, const std::string& type, const std::string& unit, const std::string& meaning) {
      m[name] = {name, type, unit, "", meaning};
    };
    for (const std::string side : {"left", "right", "scene"}) {
      const std::string what = side == "scene" ? "the scene's own blur at the object's place (the fitted model; depth "
                                                 "matching: the real picture's, the thin lens of content.real_camera)"
                                               : "the " + side + " object's blur radius";
      add("r_" + side + "_px", "number", "photo px", what + ", as the camera makes it (moving: averaged over the run)");
      add("r_" + side + "_screen_px", "number", "screen px", what + ", on the screen");
      add("r_" + side + "_arcmin", "number", "arcmin", what + ", at the eye");
    }
    add("screen_px_per_photo_px", "number", "screen px / photo px", "how the photo was scaled onto the screen");
    add("kernel", "string", "", "the blur kernel (gaussian | disc)");
    add("blur_plan", "string", "", "one_radius: each object blurred with one radius; per_pixel: by depth");
    add("r_span_screen_px", "number", "screen px", "the largest change of a radius across an object's depth");
    add("size_left_deg", "number", "deg", "the left object's largest extent on screen at onset");
    add("size_right_deg", "number", "deg", "the right object's largest extent on screen at onset");
    add("brightness", "number", "", "the object's brightness matching (factor of its texture's values)");
    add("contrast", "number", "", "the object's contrast matching");
    add("white_balance_r", "number", "", "the object's red gain in linear light");
    add("white_balance_g", "number", "", "the object's green gain in linear light");
    add("white_balance_b", "number", "", "the object's blue gain in linear light");
    add("start_level", "number", "the adjusted parameter's unit", "adjustment: the level shown first");
    add("adjust_levels", "string", "the adjusted parameter's unit",
        "adjustment: the levels in the order the next key steps through them (cyclic), separated by ;");
    add("picture_width_arcmin", "number", "arcmin",
        "depth matching: the virtual picture's width at the eye (a cut-off c's blur is r = 2 x 0.1874 x this / c)");
    add("procedure_cell", "integer", "", "a procedure trial: which crossing of its block's factors (its own procedure)");
    add("test_side", "string", "", "a procedure trial: the side (or odd-one-out interval) showing the procedure's level");
    add("level", "number", "the procedure's variable", "a procedure trial: the level shown");
    add("reversals", "integer", "", "a staircase trial: the staircase's reversals before this answer (or when it stopped)");
    add("skipped", "string", "", "why a trial was not shown (stop rule: its staircase had ended)");
    add("posterior_threshold", "number", "the procedure's variable",
        "a QUEST+ trial: the posterior mean of the threshold after this answer (its running estimate)");
    add("posterior_slope", "number", "", "a QUEST+ trial: the posterior mean of the slope after this answer");
    add("round", "integer", "", "a practice block run until a criterion: which run of its design (from 1)");
    add("odd_interval", "integer", "", "odd one out: the interval that showed the right side's object (the correct answer)");
    add("intervals", "integer", "", "odd one out: intervals per trial");
    return m;
  }();
  return known;
}

// Columns of the design written from the record's typed columns, not from the factors' text.
bool TypedVariable(const std::string& key) {
  return key == "practice" || key == "swapped" || key == "block_name" || key == "correct";
}

// A variable's cell: strings bare, null empty, numbers as JSON; an object level (a pattern) by its id, else its
// scalar members as key=value;... - never JSON.
std::string TidyCell(const Json& value) {
  if (value.is_object()) {
    if (value.contains("id") && !value["id"].is_structured()) return Cell(value["id"]);
    std::string text;
    for (const auto& [key, member] : value.items())
      if (!member.is_structured()) text += (text.empty() ? "" : ";") + key + "=" + Cell(member);
    return text;
  }
  return value.is_array() ? std::string() : Cell(value);
}

// The codebook's type of a design column from its values: integer, number, or string.
struct TypeOf {
  bool any = false, numbers = true, integers = true;
  std::set<std::string> values;
  void Add(const Json& v) {
    if (v.is_null()) return;
    any = true;
    if (!v.is_number()) numbers = integers = false;
    else if (!v.is_number_integer() && !(std::isfinite(v.get<double>()) && v.get<double>() == std::floor(v.get<double>())))
      integers = false;
    if (values.size() <= 20) values.insert(TidyCell(v));
  }
  std::string Type() const { return !any ? "string" : integers ? "integer" : numbers ? "number" : "string"; }
  std::string Allowed() const {
    if (values.size() > 20 || values.empty()) return "";
    std::string text;
    for (const auto& v : values) text += (text.empty() ? "" : "|") + v;
    return text;
  }
};

// What the record's design table says of one column of trials.csv, over every protocol version that has it.
struct DesignOf {
  std::set<std::string> roles;
  std::vector<std::string> allowed;  // each version's allowed text, once
};

// The allowed values of several protocol versions as one: a list of numbers in numeric order, else of names in the
// order met; one text when they agree; "" (any) when ranges and lists mix.
std::string UnionAllowed(const std::vector<std::string>& texts) {
  if (texts.size() == 1) return texts[0];
  std::vector<std::string> names;
  bool numbers = true;
  for (const std::string& text : texts) {
    if (text.empty() || text.find("..") != std::string::npos || text.rfind(">=", 0) == 0) return "";
    for (size_t at = 0; at <= text.size();) {
      const size_t bar = std::min(text.find('|', at), text.size());
      const std::string name = text.substr(at, bar - at);
      if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
      if (!ParseDecimal(name)) numbers = false;
      at = bar + 1;
    }
  }
  if (numbers)
    std::sort(names.begin(), names.end(), [](const std::string& a, const std::string& b) {
      return *ParseDecimal(a) < *ParseDecimal(b);
    });
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : "|") + name;
  return text;
}

// Gives each design column of trials.csv its role and the values the protocol allows, from the design table (schema
// 8: recorded once per protocol version). A record with a protocol version that ran sessions but recorded no design
// (made before designs were recorded) keeps the values seen, and the codebook says so.
void ApplyDesign(Database& db, std::vector<ColumnDef>* columns) {
  const bool complete = db.QueryInt64("SELECT count(*) FROM protocol_versions pv WHERE EXISTS (SELECT 1 FROM sessions "
                                      "s WHERE s.protocol_version_id = pv.id) AND NOT EXISTS (SELECT 1 FROM "
                                      "design_columns d WHERE d.protocol_version_id = pv.id)") == 0;
  std::map<std::string, DesignOf> design;
  Statement rows(db, "SELECT name, role, allowed FROM design_columns ORDER BY protocol_version_id, position");
  while (rows.Step()) {
    DesignOf& d = design[rows.GetText(0)];
    d.roles.insert(rows.GetText(1));
    if (std::find(d.allowed.begin(), d.allowed.end(), rows.GetText(2)) == d.allowed.end())
      d.allowed.push_back(rows.GetText(2));
  }
  for (ColumnDef& c : *columns) {
    const auto it = design.find(c.name);
    if (it == design.end()) {
      if (!complete && c.meaning.rfind("a level of the protocol's design", 0) == 0)
        c.meaning += "; allowed: the values seen (the record holds sessions from before designs were recorded)";
      continue;
    }
    for (const std::string& role : it->second.roles) c.role += (c.role.empty() ? "" : "|") + role;
    if (complete) c.allowed = UnionAllowed(it->second.allowed);
    else c.meaning += "; allowed: the values seen (the record holds sessions from before designs were recorded)";
  }
}

bool AllDigits(const std::string& text) {
  return !text.empty() && text.find_first_not_of("0123456789") == std::string::npos;
}

}  // namespace

bool IsRecordedName(const std::string& name) {
  // The names trials.csv writes itself and the runner records beside the levels - read off the very definitions
  // the table and its codebook are written from, so a column added there is reserved here without another list.
  static const std::set<std::string> names = [] {
    std::set<std::string> n = {"group"};
    for (const auto* list : {&TrialColumnsBefore(), &TrialColumnsDesign(), &TrialColumnsAfter()})
      for (const auto& c : *list) n.insert(c.name);
    for (const auto& [name, definition] : KnownVariables()) n.insert(name);
    return n;
  }();
  return names.count(name) > 0 || name.rfind("info_", 0) == 0;
}

std::string DesignColumn(const std::string& name) { return IsRecordedName(name) ? "factor_" + name : name; }

int64_t ExportCsv(const std::filesystem::path& db_path, const std::filesystem::path& out_dir,
                  const ProgressNote& note) {
  Note(note, RemoveStaleLeftovers(out_dir));
  Database source(db_path, OpenMode::kReadOnly);
  RequireReadableRecord(source);
  // A record of an earlier version is exported from a migrated copy in memory (the record itself is only read: it may
  // be a read-only archive; and a killed export leaves no copy behind): SQLite's backup copies it, the migration
  // derives its typed columns.
  std::optional<Database> copy;
  if (SchemaVersion(source) < CurrentSchemaVersion()) {
    copy.emplace(":memory:");
    sqlite3_backup* backup = sqlite3_backup_init(copy->handle(), "main", source.handle(), "main");
    const int step = backup ? sqlite3_backup_step(backup, -1) : SQLITE_ERROR;
    const int finish = backup ? sqlite3_backup_finish(backup) : SQLITE_ERROR;
    if (step != SQLITE_DONE || finish != SQLITE_OK)
      throw InputError(db_path.string(), std::string("cannot copy the record to migrate it for export: ") +
                                             sqlite3_errmsg(copy->handle()));
    Migrate(*copy);
  }
  Database& db = copy ? *copy : source;

  // Pass 1: every design variable in the record (factor levels and the variables recorded with them, planned and as
  // shown), with the codebook's type of each, so every participant gets the same columns.
  std::map<std::string, TypeOf> keys;
  {
    Statement factors(db, "SELECT t.session_id, t.trial_index, t.factors, coalesce(r.shown, '{}') FROM trials t "
                          "LEFT JOIN responses r ON r.trial_id = t.id");
    while (factors.Step()) {
      const std::string where = Where(db_path, factors.GetInt64(0), factors.GetInt64(1));
      for (int column : {2, 3}) {
        const Json object = ParseColumn(factors.GetText(column), where + (column == 2 ? " factors" : " shown"));
        if (!object.is_object())
          throw InputError(where, std::string(column == 2 ? "factors" : "shown") + " must be a JSON object");
        for (const auto& item : object.items())
          if (!TypedVariable(item.key())) keys[item.key()].Add(item.value());
      }
    }
  }
  // Between-subject groups and participant information, when any session has them: a column "group" and one
  // "info_KEY" per key given anywhere.
  const bool groups = db.QueryInt64("SELECT count(*) FROM sessions WHERE group_name <> ''") > 0;
  // Read once: each session's answers, and per key the codebook's type of them.
  std::map<std::string, TypeOf> info_keys;
  std::map<int64_t, std::map<std::string, std::string>> info_of;
  {
    Statement info(db, "SELECT session_id, key, value FROM session_info");
    while (info.Step()) {
      const std::string key = info.GetText(1), value = info.GetText(2);
      info_of[info.GetInt64(0)][key] = value;
      Json parsed;
      try {
        parsed = Json::parse(value);
      } catch (const Json::exception&) {
        parsed = value;
      }
      info_keys[key].Add(parsed.is_number() ? parsed : Json(value));
    }
  }

  // The header and the codebook, from the same definitions.
  std::vector<ColumnDef> columns = TrialColumnsBefore();
  if (groups) columns.push_back({"group", "string", "", "", "the between-subject group the session ran"});
  for (const auto& [key, type] : info_keys)
    columns.push_back({"info_" + key, type.Type(), "", type.Allowed(), "participant information: " + key});
  columns.insert(columns.end(), TrialColumnsDesign().begin(), TrialColumnsDesign().end());
  std::vector<std::string> variable_names;
  for (const auto& [key, type] : keys) {
    // A recorded variable keeps its name; a level named like one (the runner records it as factor_NAME; a record of
    // before that holds it under its own name where no recorded variable took it) gets the same prefix.
    const auto known = KnownVariables().find(key);
    const std::string name = known != KnownVariables().end() ? key : DesignColumn(key);
    variable_names.push_back(key);
    const std::string level = key.rfind("factor_", 0) == 0 && IsRecordedName(key.substr(7)) ? key.substr(7) : key;
    // A recorded measurement takes any value; a name (kernel, plan) or a level of the design one of those seen.
    if (known != KnownVariables().end())
      columns.push_back({name, known->second.type, known->second.unit,
                         known->second.type == "string" ? type.Allowed() : "", known->second.meaning});
    else
      columns.push_back({name, type.Type(), "", type.Allowed(),
                         "a level of the protocol's design: factor " + level + " (or a column of a level or of the "
                         "conditions table)" + (name == key && level == key ? "" : "; named " + name +
                         " because trials.csv has a column " + level + " of its own")});
  }
  columns.insert(columns.end(), TrialColumnsAfter().begin(), TrialColumnsAfter().end());
  ApplyDesign(db, &columns);
  std::vector<std::string> header;
  for (const auto& c : columns) header.push_back(c.name);
  std::string text = CsvLine(header);
  std::string adjustments = CsvLine({"study", "participant", "session_id", "trial_index", "step", "level", "t_ms"});

  Statement rows(db,
                 "SELECT st.name, pv.hash, p.code, s.id, s.seed, t.trial_index, t.block, t.factors, "
                 "t.block_name, t.task, t.practice, t.swapped, t.left_source, t.left_fixed, t.right_source, "
                 "t.right_fixed, coalesce(r.r_left_px, t.r_left_px), coalesce(r.r_right_px, t.r_right_px), "
                 "r.id IS NULL, r.choice, r.rt_ms, r.answered_at, r.adjustment, coalesce(r.shown, '{}'), r.correct, "
                 "s.group_name, s.observer, s.observer_params, s.window, s.status, pv.version, s.session_number, "
                 "t.cell "
                 "FROM trials t JOIN sessions s ON s.id = t.session_id "
                 "JOIN participants p ON p.id = s.participant_id JOIN studies st ON st.id = p.study_id "
                 "JOIN protocol_versions pv ON pv.id = s.protocol_version_id "
                 "LEFT JOIN responses r ON r.trial_id = t.id "
                 "ORDER BY st.name, p.code, s.id, t.trial_index");
  int64_t count = 0;
  auto optional_number = [&](int column) { return rows.IsNull(column) ? std::string() : Number(rows.GetDouble(column)); };
  while (rows.Step()) {
    const int64_t session = rows.GetInt64(3);
    const int64_t trial = rows.GetInt64(5);
    const std::string where = Where(db_path, session, trial);
    std::vector<std::string> cells = {rows.GetText(0),
                                      rows.GetText(1),
                                      std::to_string(rows.GetInt64(30)),
                                      rows.GetText(2),
                                      rows.IsNull(26) ? "person" : rows.GetText(26),
                                      rows.IsNull(27) ? "" : rows.GetText(27),
                                      rows.IsNull(28) ? "" : std::to_string(rows.GetInt64(28)),
                                      std::to_string(session),
                                      std::to_string(rows.GetInt64(31)),
                                      rows.GetText(29),
                                      "s" + std::to_string(static_cast<uint64_t>(rows.GetInt64(4)))};
    if (groups) cells.push_back(rows.GetText(25));
    for (const auto& [key, type] : info_keys) {
      const auto& info = info_of[session];
      const auto it = info.find(key);
      cells.push_back(it == info.end() ? std::string() : it->second);
    }
    cells.push_back(std::to_string(trial));
    cells.push_back(std::to_string(rows.GetInt64(6)));
    cells.push_back(rows.IsNull(8) ? "" : rows.GetText(8));
    const std::string task = rows.IsNull(9) ? "" : rows.GetText(9);
    cells.push_back(task);
    cells.push_back(rows.IsNull(10) ? "0" : std::to_string(rows.GetInt64(10)));
    cells.push_back(rows.IsNull(11) ? "0" : std::to_string(rows.GetInt64(11)));
    cells.push_back(rows.IsNull(32) ? "" : rows.GetText(32));
    // The plan's variables, with what the trial showed when it was shown laid over them (adaptive levels).
    Json factors = ParseColumn(rows.GetText(7), where + " factors");
    const Json shown = ParseColumn(rows.GetText(23), where + " shown");
    if (factors.is_object() && shown.is_object())
      for (const auto& [key, value] : shown.items()) factors[key] = value;
    for (const auto& key : variable_names)
      cells.push_back(factors.contains(key) ? TidyCell(factors.at(key)) : std::string());
    cells.push_back(rows.IsNull(12) ? "" : rows.GetText(12));
    cells.push_back(optional_number(13));
    cells.push_back(rows.IsNull(14) ? "" : rows.GetText(14));
    cells.push_back(optional_number(15));
    // The answer, split by what it is: one column per kind of answer, each of one type.
    const bool answered = rows.GetInt64(18) == 0;
    const std::string choice = answered ? rows.GetText(19) : "";
    const std::string status = !answered                  ? "unanswered"
                               : choice == kChoiceNone    ? "timed_out"
                               : choice == kChoiceSkipped ? "skipped"
                                                          : "answered";
    std::string side, more_blurred, interval, yes_no, rating, level;
    if (status == "answered") {
      if (task == "adjustment") level = choice;
      else if (task == "yes_no") yes_no = choice;
      else if (task == "rating") rating = choice;
      else if (AllDigits(choice)) interval = choice;
      else side = choice;
    }
    if ((side == "left" || side == "right") && !rows.IsNull(16) && !rows.IsNull(17)) {
      const double l = rows.GetDouble(16), r = rows.GetDouble(17);
      if (std::abs(l - r) > 1e-9) more_blurred = ((side == "left") == (l > r)) ? "1" : "0";
    }
    // Scored once, when the answer was given (records from before: by the migration to schema 8), never here.
    const std::string correct = rows.IsNull(24) ? "" : std::to_string(rows.GetInt64(24));
    for (const std::string& cell : {status, side, more_blurred, interval, yes_no, rating, level, correct})
      cells.push_back(cell);
    cells.push_back(answered && !rows.IsNull(20) ? Number(rows.GetDouble(20)) : "");
    cells.push_back(answered ? rows.GetText(21) : "");
    text += CsvLine(cells);
    // The adjustment path, long: one row per step.
    if (answered && !rows.IsNull(22)) {
      const Json steps = ParseColumn(rows.GetText(22), where + " adjustment");
      if (steps.is_array())
        for (size_t i = 0; i < steps.size(); ++i)
          adjustments += CsvLine({rows.GetText(0), rows.GetText(2), std::to_string(session), std::to_string(trial),
                                  std::to_string(i + 1), steps[i].is_object() ? TidyCell(steps[i].value("level", Json())) : "",
                                  steps[i].is_object() ? TidyCell(steps[i].value("t_ms", Json())) : ""});
    }
    ++count;
  }
  // The codebook: every column of every table this export writes; a design's column with its role.
  std::string codebook = CsvLine({"table", "column", "type", "unit", "allowed", "meaning", "role"});
  for (const auto& c : columns)
    codebook += CsvLine({"trials.csv", c.name, c.type, c.unit, c.allowed, c.meaning, c.role});
  for (const auto& c : AdjustmentColumns())
    codebook += CsvLine({"adjustments.csv", c.name, c.type, c.unit, c.allowed, c.meaning, ""});
  for (const auto& c : FrameColumns()) codebook += CsvLine({"frames.csv", c.name, c.type, c.unit, c.allowed, c.meaning, ""});
  // Every table of one export appears together: a kill leaves the previous export whole, never its frames.csv
  // beside a new trials.csv.
  WriteFolderAtomically(
      out_dir,
      [&](const std::filesystem::path& partial) {
        WriteFileAtomically(partial / "trials.csv", text);
        WriteFileAtomically(partial / "adjustments.csv", adjustments);
        codebook += WriteSummaries(db, partial);
        codebook += WriteProcedures(db, partial);
        WriteFileAtomically(partial / "codebook.csv", codebook);
        WriteFrames(db, partial);
      },
      IsExportFile);
  return count;
}

}  // namespace blurcue::store
