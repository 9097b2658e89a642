#include "store/export.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdlib>
#include <map>
#include <set>
#include <string>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json_io.h"
#include "store/record.h"
#include "store/schema.h"
#include "store/sqlite.h"

namespace blurcue::store {
namespace {

const std::vector<std::string>& LeadingColumns() {
  static const std::vector<std::string> columns = {"study", "protocol_hash", "participant", "session",
                                                   "seed",  "trial_index",   "block"};
  return columns;
}

const std::vector<std::string>& TrailingColumns() {
  static const std::vector<std::string> columns = {"left", "right", "choice", "rt_ms", "adjustment", "answered_at"};
  return columns;
}

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
  const bool table = name == "trials.csv" || name == "frames.csv" || name.rfind("summary-", 0) == 0;
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
// cant_tell, for adjustment the level accepted. Writes OUT/summary-STUDY.csv for every study.
void WriteSummaries(Database& db, const std::filesystem::path& out_dir) {
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
      char* ea = nullptr;
      char* eb = nullptr;
      const double x = std::strtod(a.c_str(), &ea), y = std::strtod(b.c_str(), &eb);
      const bool na = !a.empty() && *ea == '\0', nb = !b.empty() && *eb == '\0';
      if (na != nb) return na;
      return na && x != y ? x < y : a < b;
    }
  };
  std::map<std::string, std::set<std::string, Natural>> answer_names;
  Statement rows(db,
                 "SELECT st.name, p.code, s.id, s.status, r.id IS NOT NULL, r.choice, r.rt_ms, "
                 "CASE r.choice WHEN 'left' THEN t.left_shown WHEN 'right' THEN t.right_shown END "
                 "FROM trials t JOIN sessions s ON s.id = t.session_id "
                 "JOIN participants p ON p.id = s.participant_id JOIN studies st ON st.id = p.study_id "
                 "LEFT JOIN responses r ON r.trial_id = t.id "
                 "WHERE coalesce(json_extract(t.factors, '$.practice'), 0) = 0 ORDER BY st.name, p.code, s.id");
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
  for (auto& [study, sessions] : studies) {
    std::vector<std::string> header = {"participant", "session", "status", "planned", "answered", "median_rt_ms"};
    for (const auto& name : answer_names[study]) header.push_back("n_" + name);
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
    std::string safe = study;
    for (char& c : safe)
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
    WriteFileAtomically(out_dir / ("summary-" + safe + ".csv"), text);
  }
}

// OUT/frames.csv: every recorded display flip, one row each: study, participant, session, window (1: a real window
// on the real clock, 0: headless on a simulated clock), trial_index, frame_index, flip_time_s (from the trial's
// first flip), dropped (0/1), and what the frame showed of a pair: r_left_px, r_right_px (photo px) and y_mm (the
// objects' place along the board; empty where nothing was shown, for pictures, and in records before schema 4).
void WriteFrames(Database& db, const std::filesystem::path& out_dir) {
  std::string text = CsvLine({"study", "participant", "session", "window", "trial_index", "frame_index",
                              "flip_time_s", "dropped", "r_left_px", "r_right_px", "y_mm"});
  const bool shown = SchemaVersion(db) >= 4;
  Statement rows(db,
                 "SELECT st.name, p.code, s.id, t.trial_index, f.frame_index, f.flip_time_s, f.dropped, "
                 "s.display LIKE 'window%', " +
                     std::string(shown ? "f.r_left_px, f.r_right_px, f.y_mm " : "NULL, NULL, NULL ") +
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

// Schema 7's typed columns, by table, each with its SQLite type: copied as they are from an input of version 7 or
// later; derived from the texts (DeriveTypedColumns) for an older one.
struct TypedColumn {
  const char* name;
  char type;  // 't' text, 'r' real, 'i' integer
};
const std::vector<TypedColumn>& TypedColumns(const std::string& table) {
  static const std::map<std::string, std::vector<TypedColumn>> columns = {
      {"sessions",
       {{"observer", 't'}, {"observer_params", 't'}, {"window", 'i'}, {"profile_name", 't'}, {"screen_width_mm", 'r'},
        {"screen_height_mm", 'r'}, {"viewing_distance_mm", 'r'}, {"px_per_deg", 'r'}}},
      {"trials",
       {{"block_name", 't'}, {"practice", 'i'}, {"swapped", 'i'}, {"left_source", 't'}, {"left_fixed", 'r'},
        {"right_source", 't'}, {"right_fixed", 'r'}, {"r_left_px", 'r'}, {"r_right_px", 'r'}, {"r_scene_px", 'r'}}},
      {"responses", {{"level", 'r'}, {"correct", 'i'}, {"r_left_px", 'r'}, {"r_right_px", 'r'}}}};
  return columns.at(table);
}
// ", a, b, c" for a SELECT or INSERT column list; empty for an input before version 7.
std::string TypedList(const std::string& table, bool typed) {
  std::string list;
  if (typed)
    for (const auto& c : TypedColumns(table)) list += std::string(", ") + c.name;
  return list;
}
std::string TypedPlaceholders(const std::string& table, bool typed) {
  std::string list;
  if (typed)
    for (size_t i = 0; i < TypedColumns(table).size(); ++i) list += ", ?";
  return list;
}
// Binds the typed columns read from `from` (starting at column `first`) to `to` (starting at parameter `at`).
void CopyTyped(const std::string& table, bool typed, Statement& from, int first, Statement& to, int at) {
  if (!typed) return;
  for (const auto& c : TypedColumns(table)) {
    if (from.IsNull(first)) to.BindNull(at);
    else if (c.type == 't') to.Bind(at, from.GetText(first));
    else if (c.type == 'r') to.Bind(at, from.GetDouble(first));
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

int64_t ExportCsv(const std::filesystem::path& db_path, const std::filesystem::path& out_dir,
                  const ProgressNote& note) {
  Note(note, RemoveStaleLeftovers(out_dir));
  Database db(db_path, OpenMode::kReadOnly);
  RequireReadableRecord(db);

  // Pass 1: every factor key in the record (and every key an answer's shown object adds), so every participant gets
  // the same columns.
  std::set<std::string> keys;
  {
    Statement factors(db, "SELECT t.session_id, t.trial_index, t.factors, coalesce(r.shown, '{}') FROM trials t "
                          "LEFT JOIN responses r ON r.trial_id = t.id");
    while (factors.Step()) {
      const std::string where = Where(db_path, factors.GetInt64(0), factors.GetInt64(1));
      for (int column : {2, 3}) {
        const Json object = ParseColumn(factors.GetText(column), where + (column == 2 ? " factors" : " shown"));
        if (!object.is_object())
          throw InputError(where, std::string(column == 2 ? "factors" : "shown") + " must be a JSON object");
        for (const auto& item : object.items()) keys.insert(item.key());
      }
    }
  }
  // Between-subject groups and participant information, when any session has them: a column "group" and one
  // "info_KEY" per key given anywhere.
  bool groups = false;
  std::set<std::string> info_keys;
  if (SchemaVersion(db) >= 6) {
    Statement sessions(db, "SELECT id, group_name, participant_info FROM sessions");
    while (sessions.Step()) {
      groups = groups || !sessions.GetText(1).empty();
      const Json info = ParseColumn(sessions.GetText(2), db_path.string() + ": session " +
                                                             std::to_string(sessions.GetInt64(0)) + " participant_info");
      if (info.is_object())
        for (const auto& item : info.items()) info_keys.insert(item.key());
    }
  }
  std::set<std::string> fixed(LeadingColumns().begin(), LeadingColumns().end());
  fixed.insert(TrailingColumns().begin(), TrailingColumns().end());

  std::vector<std::string> header = LeadingColumns();
  if (groups) header.push_back("group");
  for (const auto& key : info_keys) header.push_back("info_" + key);
  for (const auto& key : keys) header.push_back(fixed.count(key) ? "factor_" + key : key);
  header.insert(header.end(), TrailingColumns().begin(), TrailingColumns().end());
  std::string text = CsvLine(header);

  Statement rows(db,
                 "SELECT st.name, pv.hash, p.code, s.id, s.seed, t.trial_index, t.block, t.factors, t.left_shown, "
                 "t.right_shown, r.choice, r.rt_ms, r.answered_at, r.id IS NULL, r.adjustment, "
                 "coalesce(r.shown, '{}'), " +
                     std::string(SchemaVersion(db) >= 6 ? "s.group_name, s.participant_info " : "'', '{}' ") +
                 "FROM trials t JOIN sessions s ON s.id = t.session_id "
                 "JOIN participants p ON p.id = s.participant_id JOIN studies st ON st.id = p.study_id "
                 "JOIN protocol_versions pv ON pv.id = s.protocol_version_id "
                 "LEFT JOIN responses r ON r.trial_id = t.id "
                 "ORDER BY st.name, p.code, s.id, t.trial_index");
  int64_t count = 0;
  while (rows.Step()) {
    const int64_t session = rows.GetInt64(3);
    const int64_t trial = rows.GetInt64(5);
    const std::string where = Where(db_path, session, trial);
    std::vector<std::string> cells = {rows.GetText(0),
                                      rows.GetText(1),
                                      rows.GetText(2),
                                      std::to_string(session),
                                      std::to_string(static_cast<uint64_t>(rows.GetInt64(4))),
                                      std::to_string(trial),
                                      std::to_string(rows.GetInt64(6))};
    if (groups) cells.push_back(rows.GetText(16));
    if (!info_keys.empty()) {
      const Json info = ParseColumn(rows.GetText(17), where + " participant_info");
      for (const auto& key : info_keys)
        cells.push_back(info.is_object() && info.contains(key) ? Cell(info.at(key)) : std::string());
    }
    // The plan's variables, with what the trial showed when it was shown laid over them (adaptive levels).
    Json factors = ParseColumn(rows.GetText(7), where + " factors");
    const Json shown = ParseColumn(rows.GetText(15), where + " shown");
    if (factors.is_object() && shown.is_object())
      for (const auto& [key, value] : shown.items()) factors[key] = value;
    for (const auto& key : keys) cells.push_back(factors.contains(key) ? Cell(factors.at(key)) : std::string());
    cells.push_back(Cell(ParseColumn(rows.GetText(8), where + " left")));
    cells.push_back(Cell(ParseColumn(rows.GetText(9), where + " right")));
    const bool answered = rows.GetInt64(13) == 0;
    cells.push_back(answered ? rows.GetText(10) : "");
    cells.push_back(answered && !rows.IsNull(11) ? Number(rows.GetDouble(11)) : "");
    // The adjustment path (method of adjustment: every level stepped to, with its time); empty for none.
    const std::string steps = answered ? rows.GetText(14) : "";
    cells.push_back(steps == "[]" ? "" : steps);
    cells.push_back(answered ? rows.GetText(12) : "");
    text += CsvLine(cells);
    ++count;
  }
  // Every table of one export appears together: a kill leaves the previous export whole, never its frames.csv
  // beside a new trials.csv.
  WriteFolderAtomically(
      out_dir,
      [&](const std::filesystem::path& partial) {
        WriteFileAtomically(partial / "trials.csv", text);
        WriteSummaries(db, partial);
        WriteFrames(db, partial);
      },
      IsExportFile);
  return count;
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
  try {
    {
      Database dst(temp);
      Migrate(dst);
      Transaction transaction(dst);
      for (const auto& input : inputs) {
        Database src(input, OpenMode::kReadOnly);
        RequireReadableRecord(src);
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
      }
      // Inputs from before the typed record: their typed columns from their texts, as a migration would.
      DeriveTypedColumns(dst);
      transaction.Commit();
    }  // the last connection closes: the WAL is checkpointed into the file and removed
    MoveIntoPlace(temp, out);
  } catch (...) {
    RemoveDatabaseFiles(temp);
    throw;
  }
}

}  // namespace blurcue::store
