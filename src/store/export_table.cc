// The tables an export writes beside trials.csv (summaries, frames) and the helpers every writer shares.
#include "store/export_table.h"
#include "store/frame_columns.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <map>
#include <optional>
#include <set>

#include "core/json_io.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/hash.h"
#include "core/typed.h"
#include "protocol/vocabulary.h"
#include "store/record.h"

namespace blurcue::store {

// A JSON value as a cell: strings bare, null empty, anything else as compact JSON.
std::string Cell(const Json& value) {
  if (value.is_string()) return value.get<std::string>();
  if (value.is_null()) return {};
  return value.dump();
}

Json ParseColumn(const std::string& text, const std::string& where) { return ParseJson(text, where); }

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
                     name == "procedures.csv" || name == "codebook.csv" || name.rfind("summary-", 0) == 0;
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

void RemoveDatabaseFiles(const std::filesystem::path& path) {
  std::error_code ignored;
  for (const char* suffix : {"", "-wal", "-shm", "-journal"})
    std::filesystem::remove(path.string() + suffix, ignored);
}
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
                 "CASE r.choice WHEN '" + protocol::ToString(protocol::Side::kLeft) + "' THEN t.left_shown WHEN '" +
                     protocol::ToString(protocol::Side::kRight) + "' THEN t.right_shown END "
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
    for (const auto& c : columns) codebook += CodebookRow(file, c);
    for (const auto& name : answer_names[study])
      codebook += CodebookRow(file, {"n_" + name, "integer", "", ">= 0",
                                     "how often the answer " + name + " was given (forced choice: the source chosen, "
                                     "or cant_tell; adjustment: the level accepted)"});
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

std::string CodebookRow(const std::string& table, const ColumnSpec& column, const std::string& role) {
  return CsvLine({table, column.name, column.type, column.unit, column.allowed, column.meaning, role});
}

// OUT/frames.csv: every recorded display flip, one row each (FrameColumns): what each frame showed of a pair, empty
// where nothing was shown and for pictures.
void WriteFrames(Database& db, const std::filesystem::path& out_dir) {
  const std::vector<FrameColumn>& columns = FrameColumns();
  std::string text = CsvLine(CsvHeader(columns));
  Statement rows(db, "SELECT " + CsvSelect(columns, "f") +
                         " FROM frames f JOIN trials t ON t.id = f.trial_id JOIN sessions s ON s.id = t.session_id "
                         "JOIN participants p ON p.id = s.participant_id JOIN studies st ON st.id = p.study_id "
                         "ORDER BY st.name, p.code, s.id, t.trial_index, f.frame_index");
  while (rows.Step()) text += CsvLine(CsvCells(columns, rows));
  WriteFileAtomically(out_dir / "frames.csv", text);
}

std::string FileStem(const std::string& name) {
  constexpr size_t kMaxBytes = 100, kHashBytes = 17;  // "-" and 16 hex digits
  const auto plain = [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' || c == '_' || c == '.';
  };
  // A byte outside `plain` is written '_' - an upper-case letter too, so that the hash tells "A" from "a" where the
  // file system does not.
  std::string safe = name;
  for (char& c : safe)
    if (!plain(c) && !(c >= 'A' && c <= 'Z')) c = '_';
  if (!safe.empty() && safe[0] == '.') safe[0] = '_';  // neither hidden nor "." nor ".."
  // A plain name shaped like a stem with its hash is hashed too, so no plain name equals another's SAFE-HASH.
  const bool looks_hashed = name.size() > kHashBytes && name[name.size() - kHashBytes] == '-' &&
                            name.find_first_not_of("0123456789abcdef", name.size() - 16) == std::string::npos;
  if (!name.empty() && name.size() <= kMaxBytes && name[0] != '.' && !looks_hashed &&
      std::all_of(name.begin(), name.end(), plain))
    return name;
  return safe.substr(0, kMaxBytes - kHashBytes) + "-" + HashHex(Fnv1a64(name));
}

std::string SummaryFileName(const std::string& study) { return "summary-" + FileStem(study) + ".csv"; }

}  // namespace blurcue::store
