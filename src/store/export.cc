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
#include "store/record.h"
#include "store/schema.h"
#include "store/sqlite.h"

#include <sqlite3.h>

namespace blurcue::store {
namespace {

// What the codebook says of a column: its type (string, integer, number, boolean - 0 or 1 -, datetime - ISO 8601
// UTC), unit, allowed values and meaning. The tables are written from these definitions and the codebook is written
// from the same ones, so the two cannot drift.
struct ColumnDef {
  std::string name, type, unit, allowed, meaning;
};

// A JSON value as a cell: strings bare, null empty, anything else as compact JSON.
std::string Cell(const Json& value) {
  if (value.is_string()) return value.get<std::string>();
  if (value.is_null()) return {};
  return value.dump();
}

Json ParseColumn(const std::string& text, const std::string& where) {
  try {
    return Json::parse(text);
  } catch (const Json::exception& e) {
    throw InputError(where, std::string("not valid JSON: ") + e.what());
  }
}

// Shortest text that reads back as the same double.
std::string Number(double value) {
  char text[64];
  const auto result = std::to_chars(text, text + sizeof(text), value);
  return std::string(text, result.ptr);
}

std::string Where(const std::filesystem::path& db, int64_t session, int64_t trial) {
  return db.string() + ": session " + std::to_string(session) + " trial " + std::to_string(trial);
}

// What an export folder may hold and still be replaced as a whole: the files an export writes, and the
// temporaries an earlier version left beside them when killed (FILE.csv.tmpPID).
bool IsExportFile(const std::string& name) {
  const bool table = name == "trials.csv" || name == "frames.csv" || name == "adjustments.csv" ||
                     name == "codebook.csv" || name.rfind("summary-", 0) == 0;
  if (table && name.size() > 4 && name.compare(name.size() - 4, 4, ".csv") == 0) return true;
  const size_t tmp = name.rfind(".csv.tmp");
  return tmp != std::string::npos && tmp + 8 < name.size() &&
         name.find_first_not_of("0123456789", tmp + 8) == std::string::npos;
}

void Note(const ProgressNote& note, const std::vector<std::filesystem::path>& removed) {
  for (const auto& path : removed)
    if (note) note("removed " + path.string() + ", left by an interrupted run");
}

std::string CsvLine(const std::vector<std::string>& cells) {
  std::string line;
  for (size_t i = 0; i < cells.size(); ++i) {
    if (i) line += ',';
    line += CsvField(cells[i]);
  }
  return line + "\r\n";
}

// Per study, one row per session: trials planned and answered (practice apart), the median response time, and
// how often each answer was given - for forced choice the source chosen (the one shown on the side picked) or
// cant_tell, for adjustment the level accepted. Writes OUT/SummaryFileName(STUDY) for every study and returns the
// codebook's rows for them.
std::string WriteSummaries(Database& db, const std::filesystem::path& out_dir) {
  struct Row {
    std::string participant, status;
    int64_t planned = 0, answered = 0;
    std::vector<double> rts;
    std::map<std::string, int64_t> answers;
  };
  std::map<std::string, std::map<int64_t, Row>> studies;
  // Answers in a natural order: numbers (adjustment levels) by value, then names.
  struct Natural {
    bool operator()(const std::string& a, const std::string& b) const {
      const std::optional<double> x = ParseDecimal(a), y = ParseDecimal(b);
      if (x.has_value() != y.has_value()) return x.has_value();
      return x && *x != *y ? *x < *y : a < b;
    }
  };
  std::map<std::string, std::set<std::string, Natural>> answer_names;
  Statement rows(db,
                 "SELECT st.name, p.code, s.id, s.status, r.id IS NOT NULL, r.choice, r.rt_ms, "
                 "CASE r.choice WHEN 'left' THEN t.left_shown WHEN 'right' THEN t.right_shown END "
                 "FROM trials t JOIN sessions s ON s.id = t.session_id "
                 "JOIN participants p ON p.id = s.participant_id JOIN studies st ON st.id = p.study_id "
                 "LEFT JOIN responses r ON r.trial_id = t.id "
                 "WHERE coalesce(t.practice, 0) = 0 AND coalesce(r.choice, '') <> '" + std::string(kChoiceSkipped) +
                 "' ORDER BY st.name, p.code, s.id");
  while (rows.Step()) {
    Row& row = studies[rows.GetText(0)][rows.GetInt64(2)];
    row.participant = rows.GetText(1);
    row.status = rows.GetText(3);
    ++row.planned;
    if (rows.GetInt64(4) == 0) continue;
    ++row.answered;
    if (!rows.IsNull(6)) row.rts.push_back(rows.GetDouble(6));
    const std::string answer = rows.IsNull(7) ? rows.GetText(5) : Cell(Json::parse(rows.GetText(7)));
    ++row.answers[answer];
    answer_names[rows.GetText(0)].insert(answer);
  }
  std::string codebook;
  // File names folded to lower case: two studies' summaries must not share a name on a case-insensitive file system
  // either.
  std::map<std::string, std::string> files;
  for (auto& [study, sessions] : studies) {
    const std::string file = SummaryFileName(study);
    std::string folded = file;
    for (char& c : folded) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (const auto [it, fresh] = files.emplace(folded, study); !fresh)
      throw InputError(db.path(), "the studies " + Echo(it->second) + " and " + Echo(study) +
                                               " would both be summarised as " + file);
    std::vector<std::string> header = {"participant", "session", "status", "planned", "answered", "median_rt_ms"};
    for (const auto& name : answer_names[study]) header.push_back("n_" + name);
    const std::string of = " (study " + study + ")";
    const std::vector<ColumnDef> columns = {
        {"participant", "string", "", "", "the participant's id" + of},
        {"session", "integer", "", ">= 1", "the session's id in this record (session_id in trials.csv)"},
        {"status", "string", "", "", "the session's status"},
        {"planned", "integer", "", ">= 0", "trials planned, practice apart"},
        {"answered", "integer", "", ">= 0", "trials answered, practice apart"},
        {"median_rt_ms", "number", "ms", ">= 0", "the median response time of the answered trials"}};
    for (const auto& c : columns) codebook += CsvLine({file, c.name, c.type, c.unit, c.allowed, c.meaning});
    for (const auto& name : answer_names[study])
      codebook += CsvLine({file, "n_" + name, "integer", "", ">= 0",
                           "how often the answer " + name + " was given (forced choice: the source chosen, or "
                           "cant_tell; adjustment: the level accepted)"});
    std::string text = CsvLine(header);
    for (auto& [session, row] : sessions) {
      std::sort(row.rts.begin(), row.rts.end());
      const size_t n = row.rts.size();
      const std::string median =
          n == 0 ? "" : Number(n % 2 ? row.rts[n / 2] : 0.5 * (row.rts[n / 2 - 1] + row.rts[n / 2]));
      std::vector<std::string> cells = {row.participant, std::to_string(session), row.status,
                                        std::to_string(row.planned), std::to_string(row.answered), median};
      for (const auto& name : answer_names[study]) cells.push_back(std::to_string(row.answers[name]));
      text += CsvLine(cells);
    }
    WriteFileAtomically(out_dir / file, text);
  }
  return codebook;
}

// The columns of adjustments.csv and frames.csv, for their writers and the codebook.
const std::vector<ColumnDef>& AdjustmentColumns() {
  static const std::vector<ColumnDef> columns = {
      {"study", "string", "", "", "the protocol's name"},
      {"participant", "string", "", "", "the participant's id"},
      {"session_id", "integer", "", ">= 1", "the session's id in this record (as in trials.csv)"},
      {"trial_index", "integer", "", ">= 0", "the trial (as in trials.csv)"},
      {"step", "integer", "", ">= 1", "the step's place in the trial's adjustment, from 1"},
      {"level", "number", "the adjusted parameter's unit", "", "the level stepped to"},
      {"t_ms", "number", "ms", ">= 0", "when, from the stimulus's first frame"},
  };
  return columns;
}
const std::vector<ColumnDef>& FrameColumns() {
  static const std::vector<ColumnDef> columns = {
      {"study", "string", "", "", "the protocol's name"},
      {"participant", "string", "", "", "the participant's id"},
      {"session_id", "integer", "", ">= 1", "the session's id in this record (as in trials.csv)"},
      {"window", "boolean", "", "0|1", "1: a real window on the real clock; 0: headless on a simulated clock"},
      {"trial_index", "integer", "", ">= 0", "the trial (as in trials.csv)"},
      {"frame_index", "integer", "", ">= 0", "the frame's place in the trial"},
      {"flip_time_s", "number", "s", ">= 0", "when the frame reached the screen, from the trial's first flip"},
      {"dropped", "boolean", "", "0|1", "1: more than 1.5 refresh periods after the frame before (window only)"},
      {"r_left_px", "number", "photo px", ">= 0", "the left object's blur radius in this frame; empty: not shown"},
      {"r_right_px", "number", "photo px", ">= 0", "the right object's blur radius in this frame; empty: not shown"},
      {"y_mm", "number", "mm", "", "the objects' place along the board's y in this frame (0 at edge 1)"},
  };
  return columns;
}

// OUT/frames.csv: every recorded display flip, one row each (FrameColumns): what each frame showed of a pair, empty
// where nothing was shown and for pictures.
void WriteFrames(Database& db, const std::filesystem::path& out_dir) {
  std::vector<std::string> header;
  for (const auto& c : FrameColumns()) header.push_back(c.name);
  std::string text = CsvLine(header);
  Statement rows(db,
                 "SELECT st.name, p.code, s.id, t.trial_index, f.frame_index, f.flip_time_s, f.dropped, "
                 "coalesce(s.window, s.display LIKE 'window%'), f.r_left_px, f.r_right_px, f.y_mm "
                 "FROM frames f JOIN trials t ON t.id = f.trial_id JOIN sessions s ON s.id = t.session_id "
                 "JOIN participants p ON p.id = s.participant_id JOIN studies st ON st.id = p.study_id "
                 "ORDER BY st.name, p.code, s.id, t.trial_index, f.frame_index");
  auto optional = [&](int column) { return rows.IsNull(column) ? std::string() : Number(rows.GetDouble(column)); };
  while (rows.Step())
    text += CsvLine({rows.GetText(0), rows.GetText(1), std::to_string(rows.GetInt64(2)),
                     std::to_string(rows.GetInt64(7)), std::to_string(rows.GetInt64(3)),
                     std::to_string(rows.GetInt64(4)), Number(rows.GetDouble(5)), std::to_string(rows.GetInt64(6)),
                     optional(8), optional(9), optional(10)});
  WriteFileAtomically(out_dir / "frames.csv", text);
}

// Schema 7's typed columns of one table (schema.h TypedColumns): copied as they are from an input of version 7 or
// later; derived from the texts (DeriveTypedColumns) for an older one.
std::vector<TypedColumn> TypedColumnsOf(const std::string& table) {
  std::vector<TypedColumn> out;
  for (const TypedColumn& c : TypedColumns())
    if (table == c.table) out.push_back(c);
  return out;
}
// ", a, b, c" for a SELECT or INSERT column list; empty for an input before version 7.
std::string TypedList(const std::string& table, bool typed) {
  std::string list;
  if (typed)
    for (const auto& c : TypedColumnsOf(table)) list += std::string(", ") + c.name;
  return list;
}
std::string TypedPlaceholders(const std::string& table, bool typed) {
  std::string list;
  if (typed)
    for (size_t i = 0; i < TypedColumnsOf(table).size(); ++i) list += ", ?";
  return list;
}
// Binds the typed columns read from `from` (starting at column `first`) to `to` (starting at parameter `at`).
void CopyTyped(const std::string& table, bool typed, Statement& from, int first, Statement& to, int at) {
  if (!typed) return;
  for (const auto& c : TypedColumnsOf(table)) {
    const std::string type = c.type;
    if (from.IsNull(first)) to.BindNull(at);
    else if (type == "TEXT") to.Bind(at, from.GetText(first));
    else if (type == "REAL") to.Bind(at, from.GetDouble(first));
    else to.Bind(at, from.GetInt64(first));
    ++first, ++at;
  }
}

void RemoveDatabaseFiles(const std::filesystem::path& path) {
  std::error_code ignored;
  for (const char* suffix : {"", "-wal", "-shm", "-journal"})
    std::filesystem::remove(path.string() + suffix, ignored);
}

}  // namespace

std::string CsvField(const std::string& text) {
  const bool quote = text.find_first_of(",\"\r\n") != std::string::npos ||
                     (!text.empty() && (text.front() == ' ' || text.back() == ' '));
  if (!quote) return text;
  std::string out = "\"";
  for (char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

namespace {

// The fixed columns of trials.csv before the design's variables, and after them.
const std::vector<ColumnDef>& TrialColumnsBefore() {
  static const std::vector<ColumnDef> columns = {
      {"study", "string", "", "", "the protocol's name"},
      {"protocol_hash", "string", "", "16 hex digits", "FNV-1a-64 of the protocol's canonical text: its version"},
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
  std::vector<std::string> header;
  for (const auto& c : columns) header.push_back(c.name);
  std::string text = CsvLine(header);
  std::string adjustments = CsvLine({"study", "participant", "session_id", "trial_index", "step", "level", "t_ms"});

  Statement rows(db,
                 "SELECT st.name, pv.hash, p.code, s.id, s.seed, t.trial_index, t.block, t.factors, "
                 "t.block_name, t.task, t.practice, t.swapped, t.left_source, t.left_fixed, t.right_source, "
                 "t.right_fixed, coalesce(r.r_left_px, t.r_left_px), coalesce(r.r_right_px, t.r_right_px), "
                 "r.id IS NULL, r.choice, r.rt_ms, r.answered_at, r.adjustment, coalesce(r.shown, '{}'), r.correct, "
                 "s.group_name, s.observer, s.observer_params, s.window, s.status "
                 "FROM trials t JOIN sessions s ON s.id = t.session_id "
                 "JOIN participants p ON p.id = s.participant_id JOIN studies st ON st.id = p.study_id "
                 "JOIN protocol_versions pv ON pv.id = s.protocol_version_id "
                 "LEFT JOIN responses r ON r.trial_id = t.id "
                 "ORDER BY st.name, p.code, s.id, t.trial_index");
  // The participant's n-th session (of the study: a participant belongs to one study).
  std::map<int64_t, int64_t> session_number;
  {
    Statement numbers(db, "SELECT s.id, row_number() OVER (PARTITION BY s.participant_id ORDER BY s.id) FROM sessions s");
    while (numbers.Step()) session_number[numbers.GetInt64(0)] = numbers.GetInt64(1);
  }
  int64_t count = 0;
  auto optional_number = [&](int column) { return rows.IsNull(column) ? std::string() : Number(rows.GetDouble(column)); };
  while (rows.Step()) {
    const int64_t session = rows.GetInt64(3);
    const int64_t trial = rows.GetInt64(5);
    const std::string where = Where(db_path, session, trial);
    std::vector<std::string> cells = {rows.GetText(0),
                                      rows.GetText(1),
                                      rows.GetText(2),
                                      rows.IsNull(26) ? "person" : rows.GetText(26),
                                      rows.IsNull(27) ? "" : rows.GetText(27),
                                      rows.IsNull(28) ? "" : std::to_string(rows.GetInt64(28)),
                                      std::to_string(session),
                                      std::to_string(session_number[session]),
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
    std::string correct = rows.IsNull(24) ? "" : std::to_string(rows.GetInt64(24));
    if (correct.empty() && !interval.empty() && factors.contains("odd_interval"))
      correct = TidyCell(factors["odd_interval"]) == interval ? "1" : "0";
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
  // The codebook: every column of every table this export writes.
  std::string codebook = CsvLine({"table", "column", "type", "unit", "allowed", "meaning"});
  for (const auto& c : columns) codebook += CsvLine({"trials.csv", c.name, c.type, c.unit, c.allowed, c.meaning});
  for (const auto& c : AdjustmentColumns()) codebook += CsvLine({"adjustments.csv", c.name, c.type, c.unit, c.allowed, c.meaning});
  for (const auto& c : FrameColumns()) codebook += CsvLine({"frames.csv", c.name, c.type, c.unit, c.allowed, c.meaning});
  // Every table of one export appears together: a kill leaves the previous export whole, never its frames.csv
  // beside a new trials.csv.
  WriteFolderAtomically(
      out_dir,
      [&](const std::filesystem::path& partial) {
        WriteFileAtomically(partial / "trials.csv", text);
        WriteFileAtomically(partial / "adjustments.csv", adjustments);
        codebook += WriteSummaries(db, partial);
        WriteFileAtomically(partial / "codebook.csv", codebook);
        WriteFrames(db, partial);
      },
      IsExportFile);
  return count;
}

std::string SummaryFileName(const std::string& study) {
  // Plain: what needs no change on any file system and cannot be mistaken for a name with a suffix.
  const bool plain =
      !study.empty() && std::all_of(study.begin(), study.end(), [](char c) {
        return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' || c == '_';
      });
  const bool looks_suffixed = study.size() > 17 && study[study.size() - 17] == '-' &&
                              study.find_first_not_of("0123456789abcdef", study.size() - 16) == std::string::npos;
  if (plain && !looks_suffixed) return "summary-" + study + ".csv";
  std::string safe = study;
  for (char& c : safe)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
  char hash[17];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(Fnv1a64(study)));
  return "summary-" + safe + "-" + hash + ".csv";
}

std::vector<SessionSummary> ListSessions(const std::filesystem::path& db_path) {
  Database db(db_path, OpenMode::kReadOnly);
  RequireReadableRecord(db);
  Statement rows(db,
                 "SELECT s.id, st.name, p.code, s.status, s.started, coalesce(s.ended, ''), s.host, s.seed, "
                 "(SELECT count(*) FROM trials t WHERE t.session_id = s.id), "
                 "(SELECT count(*) FROM trials t JOIN responses r ON r.trial_id = t.id WHERE t.session_id = s.id), "
                 "s.lock_token IS NOT NULL, coalesce(s.lock_pid, 0), coalesce(s.lock_host, ''), "
                 "coalesce(s.lock_heartbeat_ms, 0) "
                 "FROM sessions s JOIN participants p ON p.id = s.participant_id JOIN studies st ON st.id = p.study_id "
                 "ORDER BY st.name, p.code, s.id");
  std::vector<SessionSummary> sessions;
  while (rows.Step()) {
    SessionSummary s;
    s.id = rows.GetInt64(0);
    s.study = rows.GetText(1);
    s.participant = rows.GetText(2);
    s.status = rows.GetText(3);
    s.started = rows.GetText(4);
    s.ended = rows.GetText(5);
    s.host = rows.GetText(6);
    s.seed = static_cast<uint64_t>(rows.GetInt64(7));
    s.planned = rows.GetInt64(8);
    s.answered = rows.GetInt64(9);
    if (rows.GetInt64(10) != 0) s.writer = JudgeLock(rows.GetText(12), rows.GetInt64(11), rows.GetInt64(13)).text;
    sessions.push_back(std::move(s));
  }
  return sessions;
}

namespace {

// Refuses an input whose session a live writer holds (the record's own rule, JudgeLock: a copy taken now would miss
// the answers still coming, and the two copies could each be resumed and never merged again). Adds one line to
// `unfinished` per running session with no live writer (a killed or stopped one): copied as it is, and it must be
// resumed in one record only.
void CheckSessionsToMerge(Database& src, const std::filesystem::path& input, std::vector<std::string>* unfinished) {
  Statement sessions(src,
                     "SELECT s.id, st.name, p.code, s.status, "
                     "(SELECT count(*) FROM trials t WHERE t.session_id = s.id), "
                     "(SELECT count(*) FROM trials t JOIN responses r ON r.trial_id = t.id WHERE t.session_id = s.id), "
                     "s.lock_token IS NOT NULL, coalesce(s.lock_host, ''), coalesce(s.lock_pid, 0), "
                     "coalesce(s.lock_heartbeat_ms, 0) "
                     "FROM sessions s JOIN participants p ON p.id = s.participant_id "
                     "JOIN studies st ON st.id = p.study_id ORDER BY s.id");
  while (sessions.Step()) {
    const std::string id = std::to_string(sessions.GetInt64(0));
    const std::string who = "session " + id + " (study " + sessions.GetText(1) + ", participant " +
                            sessions.GetText(2) + ", " + std::to_string(sessions.GetInt64(5)) + " of " +
                            std::to_string(sessions.GetInt64(4)) + " trials answered)";
    if (sessions.GetInt64(6) != 0) {
      const LockState lock = JudgeLock(sessions.GetText(7), sessions.GetInt64(8), sessions.GetInt64(9));
      if (!lock.stale)
        throw InputError(input.string(),
                         who + " is being written by " + lock.text + "; merge it once that session has ended (to "
                         "give it up instead: stop that run, then blurcue sessions --db " + input.string() +
                         " --abort " + id + ")");
    }
    if (sessions.GetText(3) == "running")
      unfinished->push_back(input.string() + ": " + who + " is unfinished, with no live writer: copied as running; "
                            "resume it in one record only (this one, then merge again into a new file, or the "
                            "merged one), never both: the two copies could not be merged again");
  }
}

}  // namespace

void MergeDatabases(const std::vector<std::filesystem::path>& inputs, const std::filesystem::path& out,
                    const ProgressNote& note) {
  Note(note, RemoveStaleLeftovers(out));
  if (std::filesystem::exists(out)) throw InputError(out.string(), "exists; merge refuses to overwrite it");
  std::set<std::filesystem::path> seen;
  for (const auto& input : inputs) {
    if (!seen.insert(std::filesystem::weakly_canonical(input)).second)
      throw InputError(input.string(), "listed twice among the merge inputs");
  }
  const std::filesystem::path temp = TemporaryBeside(out, "partial");
  RemoveDatabaseFiles(temp);
  std::vector<std::string> unfinished;
  try {
    {
      Database dst(temp);
      Migrate(dst);
      Transaction transaction(dst);
      for (const auto& input : inputs) {
        Database src(input, OpenMode::kReadOnly);
        RequireReadableRecord(src);
        // One snapshot of the input: the sessions judged below are the ones copied, with the answers they had then.
        src.Exec("BEGIN");
        CheckSessionsToMerge(src, input, &unfinished);
        std::map<int64_t, int64_t> study_ids, protocol_ids, participant_ids, session_ids, trial_ids;
        const bool typed = SchemaVersion(src) >= 7;

        Statement studies(src, "SELECT id, name, created FROM studies");
        while (studies.Step())
          study_ids[studies.GetInt64(0)] = EnsureStudy(dst, studies.GetText(1), studies.GetText(2));

        Statement protocols(src, "SELECT id, study_id, json, hash, created FROM protocol_versions");
        while (protocols.Step()) {
          // An input of schema 1 holds raw texts: the merged record keys them by their canonical text, as run does.
          std::string json = protocols.GetText(2), hash = protocols.GetText(3);
          try {
            json = CanonicalProtocolText(json);
            hash = ProtocolHash(json);
          } catch (const Error&) {
          }
          std::string stored_json;
          protocol_ids[protocols.GetInt64(0)] = EnsureProtocolVersion(
              dst, study_ids.at(protocols.GetInt64(1)), json, hash, protocols.GetText(4), &stored_json);
          if (stored_json != json)
            throw InputError(input.string(), "protocol hash " + hash + " names a different protocol text in another input");
        }

        Statement participants(src, "SELECT id, study_id, code, created FROM participants");
        while (participants.Step())
          participant_ids[participants.GetInt64(0)] = EnsureParticipant(
              dst, study_ids.at(participants.GetInt64(1)), participants.GetText(2), participants.GetText(3));

        Statement sessions(src, "SELECT id, participant_id, protocol_version_id, seed, software_version, host, "
                                "display, started, ended, status, " +
                                std::string(SchemaVersion(src) >= 3 ? "display_profile" : "'{}'") + ", " +
                                std::string(SchemaVersion(src) >= 6 ? "group_name, participant_info" : "'', '{}'") +
                                TypedList("sessions", typed) + " FROM sessions");
        Statement duplicate(dst, "SELECT id FROM sessions WHERE participant_id = ? AND protocol_version_id = ? "
                                 "AND seed = ? AND host = ? AND started = ?");
        Statement insert_session(dst, "INSERT INTO sessions (participant_id, protocol_version_id, seed, "
                                      "software_version, host, display, started, ended, status, display_profile, "
                                      "group_name, participant_info" + TypedList("sessions", typed) +
                                      ") VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?" +
                                      TypedPlaceholders("sessions", typed) + ")");
        while (sessions.Step()) {
          const int64_t participant = participant_ids.at(sessions.GetInt64(1));
          const int64_t protocol = protocol_ids.at(sessions.GetInt64(2));
          duplicate.Bind(1, participant);
          duplicate.Bind(2, protocol);
          duplicate.Bind(3, sessions.GetInt64(3));
          duplicate.Bind(4, sessions.GetText(5));
          duplicate.Bind(5, sessions.GetText(7));
          if (duplicate.Step())
            throw InputError(input.string(), "session " + std::to_string(sessions.GetInt64(0)) +
                                                 " is already in the merge (an input merged twice?)");
          duplicate.Reset();
          insert_session.Bind(1, participant);
          insert_session.Bind(2, protocol);
          insert_session.Bind(3, sessions.GetInt64(3));
          for (int column = 4; column <= 7; ++column) insert_session.Bind(column, sessions.GetText(column));
          if (sessions.IsNull(8)) insert_session.BindNull(8);
          else insert_session.Bind(8, sessions.GetText(8));
          insert_session.Bind(9, sessions.GetText(9));
          insert_session.Bind(10, sessions.GetText(10));
          insert_session.Bind(11, sessions.GetText(11));
          insert_session.Bind(12, sessions.GetText(12));
          CopyTyped("sessions", typed, sessions, 13, insert_session, 13);
          insert_session.Run();
          insert_session.Reset();
          session_ids[sessions.GetInt64(0)] = dst.LastInsertRowId();
        }
        if (typed) {
          Statement info(src, "SELECT session_id, key, value FROM session_info");
          Statement insert_info(dst, "INSERT INTO session_info (session_id, key, value) VALUES (?, ?, ?)");
          while (info.Step()) {
            insert_info.Bind(1, session_ids.at(info.GetInt64(0)));
            insert_info.Bind(2, info.GetText(1));
            insert_info.Bind(3, info.GetText(2));
            insert_info.Run();
            insert_info.Reset();
          }
        }

        Statement trials(src, "SELECT id, session_id, trial_index, block, factors, left_shown, right_shown" +
                                  TypedList("trials", typed) + " FROM trials");
        Statement insert_trial(dst, "INSERT INTO trials (session_id, trial_index, block, factors, left_shown, "
                                    "right_shown" + TypedList("trials", typed) + ") VALUES (?, ?, ?, ?, ?, ?" +
                                    TypedPlaceholders("trials", typed) + ")");
        while (trials.Step()) {
          insert_trial.Bind(1, session_ids.at(trials.GetInt64(1)));
          insert_trial.Bind(2, trials.GetInt64(2));
          insert_trial.Bind(3, trials.GetInt64(3));
          for (int column = 4; column <= 6; ++column) insert_trial.Bind(column, trials.GetText(column));
          CopyTyped("trials", typed, trials, 7, insert_trial, 7);
          insert_trial.Run();
          insert_trial.Reset();
          trial_ids[trials.GetInt64(0)] = dst.LastInsertRowId();
        }

        Statement responses(src, "SELECT trial_id, choice, rt_ms, adjustment, answered_at, " +
                                     std::string(SchemaVersion(src) >= 5 ? "shown" : "'{}'") +
                                     TypedList("responses", typed) + " FROM responses");
        Statement insert_response(dst, "INSERT INTO responses (trial_id, choice, rt_ms, adjustment, answered_at, "
                                       "shown" + TypedList("responses", typed) + ") VALUES (?, ?, ?, ?, ?, ?" +
                                       TypedPlaceholders("responses", typed) + ")");
        while (responses.Step()) {
          insert_response.Bind(1, trial_ids.at(responses.GetInt64(0)));
          insert_response.Bind(2, responses.GetText(1));
          if (responses.IsNull(2)) insert_response.BindNull(3);
          else insert_response.Bind(3, responses.GetDouble(2));
          insert_response.Bind(4, responses.GetText(3));
          insert_response.Bind(5, responses.GetText(4));
          insert_response.Bind(6, responses.GetText(5));
          CopyTyped("responses", typed, responses, 6, insert_response, 7);
          insert_response.Run();
          insert_response.Reset();
        }

        Statement frames(src, "SELECT trial_id, frame_index, flip_time_s, dropped, " +
                                  std::string(SchemaVersion(src) >= 4 ? "r_left_px, r_right_px, y_mm"
                                                                      : "NULL, NULL, NULL") + " FROM frames");
        Statement insert_frame(dst, "INSERT INTO frames (trial_id, frame_index, flip_time_s, dropped, r_left_px, "
                                    "r_right_px, y_mm) VALUES (?, ?, ?, ?, ?, ?, ?)");
        while (frames.Step()) {
          insert_frame.Bind(1, trial_ids.at(frames.GetInt64(0)));
          insert_frame.Bind(2, frames.GetInt64(1));
          insert_frame.Bind(3, frames.GetDouble(2));
          insert_frame.Bind(4, frames.GetInt64(3));
          for (int column = 4; column <= 6; ++column) {
            if (frames.IsNull(column)) insert_frame.BindNull(column + 1);
            else insert_frame.Bind(column + 1, frames.GetDouble(column));
          }
          insert_frame.Run();
          insert_frame.Reset();
        }
        src.Exec("COMMIT");
      }
      // Inputs from before the typed record: their typed columns from their texts, as a migration would.
      DeriveTypedColumns(dst);
      transaction.Commit();
    }  // the last connection closes: the WAL is checkpointed into the file and removed
    MoveIntoPlace(temp, out);
    if (note)
      for (const auto& line : unfinished) note(line);
  } catch (...) {
    RemoveDatabaseFiles(temp);
    throw;
  }
}

}  // namespace blurcue::store
