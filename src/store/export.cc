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
#include "protocol/vocabulary.h"
#include "store/columns.h"
#include "store/export_procedures.h"
#include "store/procedures.h"
#include "store/export_table.h"
#include "store/frame_columns.h"
#include "store/record.h"
#include "store/schema.h"
#include "store/sqlite.h"

namespace blurcue::store {
namespace {

// trials.csv's columns of one place, in the column table's order (columns.h), as the codebook defines them.
std::vector<ColumnDef> Defs(const std::vector<Column>& table, Place place) {
  std::vector<ColumnDef> defs;
  for (const Column& c : table)
    if (c.place == place) defs.push_back(ColumnDef{c});
  return defs;
}

// The runner's variable named `key` (session/recording.h TrialVariables), or null: any other key of a trial's
// variables is a level of the protocol's design (or a column of its conditions table, or a level's value).
const Column* RecordedVariable(const std::vector<Column>& table, const std::string& key) {
  for (const Column& c : table)
    if (c.place == Place::kVariable && c.name == key) return &c;
  return nullptr;
}

// A variable the runner writes both in the trial's variables and in a typed column: exported from the typed column.
bool TypedVariable(const std::vector<Column>& table, const std::string& key) {
  for (const Column& c : table)
    if (c.in_variables && c.name == key) return true;
  return false;
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
  // A number binary cannot hold as written (a staircase's 0.5 - 0.1 - 0.1 - 0.1 = 0.20000000000000004, recorded so
  // before the runner recorded levels as given) is written at 15 significant digits, the most a double keeps of any
  // decimal: 0.2. A number that needs no more keeps its shortest text (4.0 stays 4.0).
  if (value.is_number_float() && std::isfinite(value.get<double>())) {
    char text[32];
    std::snprintf(text, sizeof text, "%.15g", value.get<double>());
    if (std::strtod(text, nullptr) != value.get<double>()) return text;
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
  std::set<std::string> units;       // each version's unit
};

// The unit a design column's versions give it, for the codebook ("" where they differ or give none). The procedure's
// level is the one design column whose empty unit says something: protocol::DescribeDesign gives "arcmin" for a
// difference_arcmin procedure and "" for relative_difference, whose level is the test radius / the reference's - 1.
std::string UnitOfDesign(const std::string& name, const DesignOf& design) {
  if (design.units.size() != 1) return "";
  const std::string& unit = *design.units.begin();
  if (name == "level" && unit.empty()) return "ratio - 1 (relative_difference: the test side's radius / the reference's - 1)";
  return unit;
}

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
  Statement rows(db, "SELECT name, role, allowed, unit FROM design_columns ORDER BY protocol_version_id, position");
  while (rows.Step()) {
    DesignOf& d = design[rows.GetText(0)];
    d.roles.insert(rows.GetText(1));
    d.units.insert(rows.GetText(3));
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
    // The design's unit where every version gives the same (a level of speed_cm_s is in cm/s, a difference_arcmin
    // procedure's level in arcmin); the table's words otherwise.
    if (const std::string unit = UnitOfDesign(c.name, it->second); !unit.empty()) c.unit = unit;
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
    for (const Column& c : RecordColumns())
      if (c.place != Place::kNone) n.insert(c.name);
    return n;
  }();
  return names.count(name) > 0 || name.rfind("info_", 0) == 0;
}

std::string DesignColumn(const std::string& name) { return IsRecordedName(name) ? "factor_" + name : name; }

void SpreadObjectLevels(Json* variables) {
  if (!variables->is_object()) return;
  Json spread = Json::object();
  for (const auto& [name, level] : variables->items())
    if (level.is_object())
      for (const auto& [key, value] : level.items())
        if (!protocol::ParseWord<protocol::Side>(key) && key != "object" && !variables->contains(DesignColumn(key)) &&
            !spread.contains(DesignColumn(key)))
          spread[DesignColumn(key)] = value;
  for (auto& [key, value] : spread.items()) (*variables)[key] = std::move(value);
}

Json LevelVariables(const Json& levels) {
  Json v = Json::object();
  if (!levels.is_object()) return v;
  for (const auto& [name, level] : levels.items()) v[DesignColumn(name)] = level;
  SpreadObjectLevels(&v);
  if (v.contains("row") && v["row"].is_object()) v.erase("row");
  return v;
}

const std::vector<AdjustmentColumn>& AdjustmentColumns() {
  // A step's recorded value (level, t_ms) as a cell; a step that is no object gives empty ones.
  auto recorded = [](const char* key) {
    return [key](const AdjustmentStep& s) { return s.step.is_object() ? TidyCell(s.step.value(key, Json())) : ""; };
  };
  static const std::vector<AdjustmentColumn> columns = {
      {{"study", "string", "", "", "the protocol's name"}, [](const AdjustmentStep& s) { return s.study; }},
      {{"participant", "string", "", "", "the participant's id"},
       [](const AdjustmentStep& s) { return s.participant; }},
      {{"session_id", "integer", "", ">= 1", "the session's id in this record (as in trials.csv)"},
       [](const AdjustmentStep& s) { return std::to_string(s.session); }},
      {{"trial_index", "integer", "", ">= 0", "the trial (as in trials.csv)"},
       [](const AdjustmentStep& s) { return std::to_string(s.trial); }},
      {{"step", "integer", "", ">= 1", "the step's place in the trial's adjustment, from 1"},
       [](const AdjustmentStep& s) { return std::to_string(s.index + 1); }},
      {{"level", "number", "the adjusted parameter's unit", "", "the level stepped to"}, recorded("level")},
      {{"t_ms", "number", "ms", ">= 0", "when, from the stimulus's first frame"}, recorded("t_ms")},
  };
  return columns;
}

int64_t ExportCsv(const std::filesystem::path& db_path, const std::filesystem::path& out_dir,
                  const ProgressNote& note) {
  return ExportCsvWith(RecordColumns(), db_path, out_dir, note);
}

namespace {

// Pass 1: every design variable in the record (factor levels and the variables recorded with them, planned and as
// shown) that no typed column keeps, with the codebook's type of each, so every participant gets the same columns.
std::map<std::string, TypeOf> DesignVariables(const std::vector<Column>& table, Database& db,
                                              const std::filesystem::path& db_path) {
  std::map<std::string, TypeOf> keys;
  Statement factors(db, "SELECT t.session_id, t.trial_index, t.factors, coalesce(r.shown, '{}') FROM trials t "
                        "LEFT JOIN responses r ON r.trial_id = t.id");
  while (factors.Step()) {
    const std::string where = Where(db_path, factors.GetInt64(0), factors.GetInt64(1));
    for (int column : {2, 3}) {
      Json object = ParseColumn(factors.GetText(column), where + (column == 2 ? " factors" : " shown"));
      if (column == 2) SpreadObjectLevels(&object);
      if (!object.is_object())
        throw InputError(where, std::string(column == 2 ? "factors" : "shown") + " must be a JSON object");
      for (const auto& item : object.items())
        if (!TypedVariable(table, item.key())) keys[item.key()].Add(item.value());
    }
  }
  return keys;
}

// The participant information, read once: each session's answers, and per key the codebook's type of them.
struct SessionInfo {
  std::map<std::string, TypeOf> keys;
  std::map<int64_t, std::map<std::string, std::string>> of;
};
SessionInfo ReadSessionInfo(Database& db) {
  SessionInfo read;
  Statement info(db, "SELECT session_id, key, value FROM session_info");
  while (info.Step()) {
    const std::string key = info.GetText(1), value = info.GetText(2);
    read.of[info.GetInt64(0)][key] = value;
    Json parsed;
    try {
      parsed = ParseJson(value, key);  // nesting scanned first (a hand-edited record's)
    } catch (const std::exception&) {
      parsed = value;
    }
    read.keys[key].Add(parsed.is_number() ? parsed : Json(value));
  }
  return read;
}

// trials.csv's columns, for its header and the codebook alike: the session's, a group column and one info_KEY per
// key of participant information when any session has them, the trial's, the design's variables (`variables`, each
// key as the record holds it, set in the same order) and the answer's.
std::vector<ColumnDef> TrialsColumns(const std::vector<Column>& table, Database& db, bool groups,
                                     const SessionInfo& info, const std::map<std::string, TypeOf>& keys,
                                     std::vector<std::string>* variables) {
  std::vector<ColumnDef> columns = Defs(table, Place::kSession);
  if (groups) columns.push_back({"group", "string", "", "", "the between-subject group the session ran"});
  for (const auto& [key, type] : info.keys)
    columns.push_back({"info_" + key, type.Type(), "", type.Allowed(), "participant information: " + key});
  const std::vector<ColumnDef> trial_columns = Defs(table, Place::kTrial);
  columns.insert(columns.end(), trial_columns.begin(), trial_columns.end());
  for (const auto& [key, type] : keys) {
    // A recorded variable keeps its name; a level named like one (the runner records it as factor_NAME; a record of
    // before that holds it under its own name where no recorded variable took it) gets the same prefix.
    const Column* known = RecordedVariable(table, key);
    const std::string name = known ? key : DesignColumn(key);
    variables->push_back(key);
    const std::string level = key.rfind("factor_", 0) == 0 && IsRecordedName(key.substr(7)) ? key.substr(7) : key;
    // A recorded measurement takes any value; a name (kernel, plan) or a level of the design one of those seen.
    if (known)
      columns.push_back({name, known->type, known->unit,
                         !known->allowed.empty() ? known->allowed : known->type == "string" ? type.Allowed() : "",
                         known->meaning});
    else
      columns.push_back({name, type.Type(), "", type.Allowed(),
                         "a level of the protocol's design: factor " + level + " (or a column of a level or of the "
                         "conditions table)" + (name == key && level == key ? "" : "; named " + name +
                         " because trials.csv has a column " + level + " of its own")});
  }
  const std::vector<ColumnDef> answer_columns = Defs(table, Place::kAnswer);
  columns.insert(columns.end(), answer_columns.begin(), answer_columns.end());
  ApplyDesign(db, &columns);
  return columns;
}

// The answer split by what it is: one cell per kind of answer, each of one type, decided when it is exported.
struct AnswerCells {
  std::string status, side, more_blurred, interval, yes_no, rating, level;

  // `answered`: the trial has a response; `choice` its text; `task` the trial's task word (an unknown word is read
  // as a side or interval, as forced choice); `radii` each side's radius it is judged by (photo px; none: unknown).
  AnswerCells(bool answered, const std::string& choice, const std::string& task,
              const std::array<std::optional<double>, 2>& radii) {
    const std::optional<protocol::Task> parsed = protocol::ParseWord<protocol::Task>(task);
    const protocol::TaskAnswer kind = parsed ? protocol::TraitsOf(*parsed).answer : protocol::TaskAnswer::kSide;
    status = !answered                  ? "unanswered"
             : choice == kChoiceNone    ? "timed_out"
             : choice == kChoiceSkipped ? "skipped"
                                        : "answered";
    if (status == "answered") {
      switch (kind) {
        case protocol::TaskAnswer::kLevel: level = choice; break;
        case protocol::TaskAnswer::kYesNo: yes_no = choice; break;
        case protocol::TaskAnswer::kRatingPoint: rating = choice; break;
        case protocol::TaskAnswer::kSide: (AllDigits(choice) ? interval : side) = choice; break;
      }
    }
    const std::optional<double>& l = radii[protocol::Index(protocol::Side::kLeft)];
    const std::optional<double>& r = radii[protocol::Index(protocol::Side::kRight)];
    if (const auto chosen = protocol::ParseWord<protocol::Side>(side); chosen && l && r)
      if (std::abs(*l - *r) > 1e-9) more_blurred = ((*chosen == protocol::Side::kLeft) == (*l > *r)) ? "1" : "0";
  }
  // The cell of a column decided from the answer; none for another column.
  std::optional<std::string> Of(Answer answer) const {
    switch (answer) {
      case Answer::kStatus: return status;
      case Answer::kChosenSide: return side;
      case Answer::kChoseMoreBlurred: return more_blurred;
      case Answer::kChosenInterval: return interval;
      case Answer::kYesNo: return yes_no;
      case Answer::kRating: return rating;
      case Answer::kAdjustedLevel: return level;
      case Answer::kNone: break;
    }
    return std::nullopt;
  }
};

// A column's cell read from the record at `i`, as the table says it is written (NULL: Column::if_null).
std::string KeptCell(Statement& rows, int i, const Column& c) {
  if (rows.IsNull(i)) return c.if_null;
  switch (c.cell) {
    case Cell::kInteger: return std::to_string(rows.GetInt64(i));
    case Cell::kNumber: return Number(rows.GetDouble(i));
    case Cell::kSeed: return "s" + std::to_string(static_cast<uint64_t>(rows.GetInt64(i)));
    case Cell::kText:
    case Cell::kAnswer: break;
  }
  return rows.GetText(i);
}

// The adjustment path of a trial, long: one row of adjustments.csv per step (AdjustmentColumns).
std::string AdjustmentRows(const std::string& study, const std::string& participant, int64_t session, int64_t trial,
                           const Json& steps) {
  std::string rows;
  if (!steps.is_array()) return rows;
  for (size_t i = 0; i < steps.size(); ++i) {
    const AdjustmentStep step{study, participant, session, trial, i, steps[i]};
    std::vector<std::string> cells;
    for (const AdjustmentColumn& c : AdjustmentColumns()) cells.push_back(c.cell(step));
    rows += CsvLine(cells);
  }
  return rows;
}

// The codebook's rows of trials.csv (`columns`), adjustments.csv and frames.csv: a design's column with its role.
std::string CodebookRows(const std::vector<ColumnDef>& columns) {
  std::string codebook = CsvLine({"table", "column", "type", "unit", "allowed", "meaning", "role"});
  for (const auto& c : columns) codebook += CodebookRow("trials.csv", c, c.role);
  for (const auto& c : AdjustmentColumns()) codebook += CodebookRow("adjustments.csv", c);
  codebook += CsvCodebook("frames.csv", FrameColumns());
  return codebook;
}

}  // namespace

int64_t ExportCsvWith(const std::vector<Column>& table, const std::filesystem::path& db_path,
                      const std::filesystem::path& out_dir, const ProgressNote& note) {
  Note(note, RemoveStaleLeftovers(out_dir));
  // A record of an earlier version is exported from a migrated copy in memory (the record itself is only read).
  Database db = OpenRecordForReading(db_path);
  const std::map<std::string, TypeOf> keys = DesignVariables(table, db, db_path);
  // Between-subject groups and participant information, when any session has them.
  const bool groups = db.QueryInt64("SELECT count(*) FROM sessions WHERE group_name <> ''") > 0;
  SessionInfo info = ReadSessionInfo(db);
  // The header and the codebook, from the same definitions.
  std::vector<std::string> variable_names;
  const std::vector<ColumnDef> columns = TrialsColumns(table, db, groups, info, keys, &variable_names);
  std::vector<std::string> header;
  for (const auto& c : columns) header.push_back(c.name);
  std::string text = CsvLine(header);
  header.clear();
  for (const auto& c : AdjustmentColumns()) header.push_back(c.name);
  std::string adjustments = CsvLine(header);

  // What every row needs (who, which trial, its variables, the answer and the radii it is judged by), then each
  // column of the table that is read from the record, as it says (SelectOf), at `at[column]`.
  std::string select = "SELECT st.name, p.code, s.id, t.trial_index, t.factors, coalesce(r.shown, '{}'), r.id IS NULL, "
                       "r.choice, coalesce(t.task, '')";
  for (const protocol::Side side : protocol::Vocabulary<protocol::Side>::values) {
    const std::string r = SideColumn("r", side, "px");
    select += ", coalesce(r." + r + ", t." + r + ")";
  }
  select += ", r.adjustment, s.group_name";
  std::map<const Column*, int> at;
  int next = 13;
  for (const Column& c : table)
    if (c.place != Place::kVariable && c.place != Place::kNone && c.cell != Cell::kAnswer) {
      select += ", " + SelectOf(c);
      at[&c] = next++;
    }
  Statement rows(db, select +
                 " FROM trials t JOIN sessions s ON s.id = t.session_id "
                 "JOIN participants p ON p.id = s.participant_id JOIN studies st ON st.id = p.study_id "
                 "JOIN protocol_versions pv ON pv.id = s.protocol_version_id "
                 "LEFT JOIN responses r ON r.trial_id = t.id "
                 "ORDER BY st.name, p.code, s.id, t.trial_index");
  int64_t count = 0;
  while (rows.Step()) {
    const int64_t session = rows.GetInt64(2);
    const int64_t trial = rows.GetInt64(3);
    const std::string where = Where(db_path, session, trial);
    const bool answered = rows.GetInt64(6) == 0;
    std::array<std::optional<double>, 2> radii;
    for (size_t k = 0; k < 2; ++k)
      if (!rows.IsNull(9 + int(k))) radii[k] = rows.GetDouble(9 + int(k));
    const AnswerCells answer(answered, answered ? rows.GetText(7) : "", rows.GetText(8), radii);
    // A column's cell as the table says it is read.
    auto cells_of = [&](Place place, std::vector<std::string>* cells) {
      for (const Column& c : table)
        if (c.place == place) {
          const std::optional<std::string> decided = answer.Of(c.answer);
          cells->push_back(decided ? *decided : KeptCell(rows, at.at(&c), c));
        }
    };
    std::vector<std::string> cells;
    cells_of(Place::kSession, &cells);
    if (groups) cells.push_back(rows.GetText(12));
    for (const auto& [key, type] : info.keys) {
      const auto& given = info.of[session];
      const auto it = given.find(key);
      cells.push_back(it == given.end() ? std::string() : it->second);
    }
    cells_of(Place::kTrial, &cells);
    // The plan's variables, with what the trial showed when it was shown laid over them (adaptive levels).
    Json factors = ParseColumn(rows.GetText(4), where + " factors");
    SpreadObjectLevels(&factors);
    const Json shown = ParseColumn(rows.GetText(5), where + " shown");
    if (factors.is_object() && shown.is_object())
      for (const auto& [key, value] : shown.items()) factors[key] = value;
    for (const auto& key : variable_names)
      cells.push_back(factors.contains(key) ? TidyCell(factors.at(key)) : std::string());
    cells_of(Place::kAnswer, &cells);
    text += CsvLine(cells);
    if (answered && !rows.IsNull(11))
      adjustments += AdjustmentRows(rows.GetText(0), rows.GetText(1), session, trial,
                                    ParseColumn(rows.GetText(11), where + " adjustment"));
    ++count;
  }
  CheckProcedures(db, db_path.string());
  std::string codebook = CodebookRows(columns);
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
