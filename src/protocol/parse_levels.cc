#include "protocol/parser.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string_view>

#include "core/csv.h"
#include "core/json_io.h"
#include "core/names.h"
#include "core/typed.h"

namespace blurcue::protocol::detail {

void Parser::CheckReadName(const std::string& name, const std::string& what, const std::string& ptr,
                           const std::string& where) {
  // "label_" alone names no label: its column would be one more "label_" beside any other such.
  if (name == "label_") {
    Problem(ptr, where + "a label needs a name after label_ (e.g. label_stim_id)");
    return;
  }
  // A label's name becomes a column of the tables and a heading of the report: refused as any other name would be
  // when it holds a bidirectional control (label_\u202Ex read backwards) or could run as a spreadsheet formula.
  if (const std::string why = UnsafeIdReason(name); !why.empty()) {
    Problem(ptr, where + "the " + what + " name " + Echo(name) + " " + why);
    return;
  }
  if (IsValueName(name) || IsLabelName(name)) return;
  // A name with a space at either end ("edge " from a CSV header) is quoted and said to be so: it used to read
  // "a column edge  (did you mean edge?)", the difference invisible.
  const bool padded = !name.empty() && (std::isspace((unsigned char)name.front()) || std::isspace((unsigned char)name.back()));
  const std::string shown = padded ? "\"" + name + "\" (a space at its start or end)" : name;
  // A misspelt name used to be taken as a label: recorded with every trial while the level it meant was never set.
  Problem(ptr, where + "no part of blurcue reads a " + what + " " + shown + DidYouMean(name, ReadNames()) +
                   "; to record it as a label nobody reads, name it label_" + name);
}

// Checks a value by the name it goes by (a factor's name, or a key of an object level).
void Parser::CheckLevelValue(const std::string& name, const Json& v, const std::string& ptr,
                             const std::string& where) {
  auto report = [&](const std::string& what) { Problem(ptr, what + ", got " + Got(v) + where); };
  auto integer_in = [&](int lo, int hi, const std::string& what) {
    if (!IntegerIn(v, lo, hi)) report(what + " must be an integer in " + Range(lo, hi, ""));
  };
  auto number_in = [&](double lo, double hi, const std::string& unit, const std::string& what) {
    if (!NumberIn(v, lo, hi)) report(what + " must be a number in " + Range(lo, hi, unit));
  };
  // An edge or a section of the calibrated board where it is known (so one past it is named with every other
  // problem; the trial list refuses it too), else of the largest board a calibration can have.
  auto board_level = [&](int most, int most_on_board, const std::string& what) {
    if (options_.board_rows <= 0) return integer_in(1, most, what);
    if (!IntegerIn(v, 1, most_on_board))
      report(what + " must be an integer in " + Range(1, most_on_board, "") + ", the calibrated board's (" +
             BoardLevelsText(options_.board_cols, options_.board_rows) + ")");
  };
  if (name == "edge" || name == "from_edge" || name == "to_edge")
    board_level(kEdges, options_.board_rows + 1, "an edge");
  else if (name == "section")
    board_level(kEdges - 1, options_.board_rows, "a section (edge s to s + 1)");
  // A place on the board in mm (x across it from its left edge, y along it from edge 1): up to 10 m away.
  else if (name == "y_mm" || name == "from_y_mm" || name == "to_y_mm" || name == "left_x_mm" || name == "right_x_mm")
    number_in(-10000, 10000, "mm", "a place on the board");
  // The thesis rolled at 1.8 and 3 cm/s; 1 mm/s takes 4 minutes over the board, 1 m/s a quarter second.
  else if (name == "speed_cm_s") number_in(0.1, 100, "cm/s", "a speed");
  else if (name == "height_mm") number_in(0, 1000, "mm", "a height above the table");
  else if (name == "rotation_deg") number_in(-180, 180, "deg", "a rotation about the vertical");
  else if (name == "distance_m") number_in(0.1, 100, "m", "a distance");
  // Cycles per picture width; 0 shows the picture unfiltered.
  else if (name == "cutoff") number_in(0, 1000, "cycles per picture width", "a cut-off");
  else if (ParseWord<Side>(name) || name == "object") {
    if (!IsBlurSource(v)) {
      std::string words;
      for (const std::string& word : BlurSourceWords()) words += word + ", ";
      report("a blur source must be " + words + "a radius in " + Range(0, kMaxFixedRadiusPx, "photo px") +
             ", {\"screen_px\": r} with r in " + Range(0, kMaxFixedRadiusPx, "") + " or {\"arcmin\": r} with r in " +
             Range(0, 600, "") + (v.is_string() ? DidYouMean(v.get<std::string>(), BlurSourceWords()) : std::string()));
    }
  } else if (name == "id") {
    // An id names a row or a pattern in the tables, the report's file names and its charts: text a spreadsheet
    // shows as written, or a whole number every reader holds exactly (1e308 and 2^64 - 1 are neither).
    constexpr double kExact = 9007199254740992.0;  // 2^53
    if (v.is_string()) {
      if (const std::string why = UnsafeIdReason(v.get<std::string>()); !why.empty()) report("an id " + why);
    } else if (!v.is_number_integer() || std::abs(v.get<double>()) >= kExact) {
      report("an id must be text or a whole number below 2^53 (9007199254740992)");
    }
  } else if (v.is_number() && !std::isfinite(v.get<double>())) {
    report("must be a finite number");
  }
}

namespace {

// A level as typed once it has been checked. A value the parser refused (an object, a list, true or null, inside an
// object level or as the level) is kept as its JSON text, so the design's counts stay as written and the refusal
// names its field: the protocol is refused anyway. (A pattern's right: true used to stop validate with "a level
// must be a number or a string, got true", naming neither the file nor the field.)
Json Kept(const Json& value) { return value.is_string() || value.is_number() ? value : Json(value.dump()); }

Level Typed(const std::string& factor, const Json& level) {
  if (!level.is_object()) return LevelOf(factor, Kept(level));
  Json scalars = Json::object();
  for (const auto& [key, value] : level.items()) scalars[key] = Kept(value);
  return LevelOf(factor, scalars);
}

}  // namespace

std::vector<Factor> Parser::ParseFactors(const Json& v, const std::string& ptr) {
  std::vector<Factor> factors;
  if (!v.is_object()) {
    Problem(ptr, "must be an object mapping factor names to lists of levels", v);
    return factors;
  }
  if (v.empty()) Problem(ptr, "must name at least one factor", v);
  if (v.size() > kMaxFactors) {
    Problem(ptr, "may name at most " + std::to_string(kMaxFactors) + " factors, got " + std::to_string(v.size()));
    return factors;
  }
  int carrying_sides = 0;
  for (const auto& [name, levels] : v.items()) {
    const std::string fp = ptr + "/" + Escape(name);
    if (name.empty() || Utf8Length(name) > kMaxNameChars || !IsPrintableUtf8(name)) {
      Problem(fp, "a factor name must be 1 to " + std::to_string(kMaxNameChars) +
                      " characters without control characters", Json(name));
      continue;
    }
    if (!levels.is_array()) {
      Problem(fp, "must be a list of levels", levels);
      continue;
    }
    if (levels.empty()) {
      Problem(fp, "must list at least one level", levels);
      continue;
    }
    if (levels.size() > kMaxLevels) {
      Problem(fp, "may list at most " + std::to_string(kMaxLevels) + " levels, got " + std::to_string(levels.size()));
      continue;
    }
    // A factor's name is what reads its levels (edge, speed_cm_s, ...), unless its levels are objects whose keys are.
    if (!std::all_of(levels.begin(), levels.end(), [](const Json& level) { return level.is_object(); }))
      CheckReadName(name, "factor", fp);
    else if (const std::string why = UnsafeIdReason(name); !why.empty())
      Problem(fp, "the factor name " + Echo(name) + " " + why);
    Factor f{name, {}};
    bool sides = false;
    std::set<std::string> keys_checked;  // an object level's key is named once, at the first level that has it
    std::map<std::string, size_t> seen;  // a level's text -> its first index
    for (size_t i = 0; i < levels.size(); ++i) {
      const Json& level = levels[i];
      const std::string lp = fp + "/" + std::to_string(i);
      if (!level.is_number() && !level.is_string() && !level.is_object()) {
        Problem(lp, "a level must be a number, a string or an object", level);
        continue;
      }
      // Repeats found by the text of each level (numbers by value: 2 and 2.0 are one level), in linear time.
      const std::string text = level.is_number() ? Json(level.get<double>()).dump() : level.dump();
      if (const auto [first, fresh] = seen.emplace(text, i); !fresh)
        Problem(lp, "repeats the level at " + fp + "/" + std::to_string(first->second) +
                        " (a factor lists each of its levels once; repetitions sets how often each is shown)",
                level);
      // A factor named for a value (edge, speed_cm_s, ...) holds that value itself; any other factor's object
      // levels carry named values.
      if (level.is_object() && !IsValueName(name)) {
        for (const auto& [key, value] : level.items()) {
          if (keys_checked.insert(key).second) CheckReadName(key, "level key", lp + "/" + Escape(key));
          if (!value.is_number() && !value.is_string())
            Problem(lp + "/" + Escape(key), "must be a number or a string", value);
          else CheckLevelValue(key, value, lp + "/" + Escape(key));
        }
        const bool l = level.contains(ToString(Side::kLeft)), r = level.contains(ToString(Side::kRight));
        const Side has = l ? Side::kLeft : Side::kRight;
        if (l != r) Problem(lp, "has \"" + ToString(has) + "\" but no \"" + ToString(Other(has)) + "\"", level);
        if (level.contains("object") && (l || r))
          Problem(lp, "has an \"object\" (layout single) and left/right (a pair): give one or the other", level);
        if ((l && r) || level.contains("object")) sides = true;
        if (level.contains("from_edge") && level.contains("to_edge") && level["from_edge"].is_number_integer() &&
            level["to_edge"].is_number_integer() && level["from_edge"] == level["to_edge"])
          Problem(lp, "from_edge and to_edge must differ", level);
      } else {
        CheckLevelValue(name, level, lp);
      }
      f.levels.push_back(Typed(name, level));
    }
    if (sides) ++carrying_sides;
    factors.push_back(std::move(f));
  }
  if (carrying_sides > 1) Problem(ptr, "at most one factor may carry left and right", v);
  return factors;
}

namespace {

// A decimal's digits without leading or trailing zeros and the power of ten of its first: "0.0250" and "2.5e-2"
// are ("25", -2). For comparing what a cell says with what a double holds.
std::pair<std::string, int> Digits(std::string_view text) {
  std::string digits;
  int exponent = 0, point = -1;
  size_t i = (!text.empty() && (text[0] == '+' || text[0] == '-')) ? 1 : 0;
  for (; i < text.size() && text[i] != 'e' && text[i] != 'E'; ++i) {
    if (text[i] == '.') point = int(digits.size());
    else digits += text[i];
  }
  if (i < text.size()) exponent = std::atoi(std::string(text.substr(i + 1)).c_str());
  if (point < 0) point = int(digits.size());
  const size_t first = digits.find_first_not_of('0');
  if (first == std::string::npos) return {"0", 0};
  exponent += point - int(first) - 1;
  digits = digits.substr(first);
  digits.erase(digits.find_last_not_of('0') + 1);
  return {digits, exponent};
}

// Whether the double nearest to the decimal `cell` is the decimal itself as a reader sees it: its shortest
// round-trip form has the same digits ("0.1" yes; "9007199254740993" and "0.12345678901234567" no).
bool HoldsExactly(std::string_view cell, double value) {
  char text[40];
  for (int precision = 1; precision <= 17; ++precision) {
    std::snprintf(text, sizeof text, "%.*g", precision, value);
    if (std::strtod(text, nullptr) == value) break;
  }
  return Digits(cell) == Digits(text);
}

}  // namespace

// A conditions table instead of factors: a CSV file (RFC 4180, as spreadsheets save it: core/csv.h) whose header
// names the levels (edge, speed_cm_s, left, right, any label) and whose every row is one design row - for designs
// that are not full crossings. It becomes one factor "row" whose levels are the rows as objects, checked like any
// level, at /.../conditions/row/K/COLUMN (K counting the table's data rows from 0); a problem there names the
// file's line and column instead (table_places_), once however many blocks use the table. A label's cell (id, label, label_*) stays the text it is ("007" and "7" are two ids); any other
// cell that is a number is that number exactly, or refused.
std::vector<Factor> Parser::ParseConditions(const Json& v, const std::string& ptr) {
  const auto text = Text(v, "conditions", ptr.substr(0, ptr.rfind('/')), true, kMaxPathChars, true);
  if (!text) return {};
  const fs::path file = (base_ / *text).lexically_normal();
  const std::string where = file.string();
  std::string csv;
  if (options_.conditions_tables) {
    // A recorded version's table, as it was read when the version ran (no file is read).
    const auto recorded = options_.conditions_tables->find(*text);
    if (recorded == options_.conditions_tables->end()) {
      Problem(ptr, "no recorded conditions table " + Echo(*text), Json(*text));
      return {};
    }
    csv = recorded->second;
  } else {
    if (!CheckFile(file, ptr, Json(*text))) return {};
    std::error_code size_error;
    const uintmax_t bytes = fs::file_size(file, size_error);
    if (!size_error && bytes > kMaxJsonBytes) {
      Problem(ptr, where + ": a conditions table may have at most 16 MiB (" + std::to_string(kMaxTrials) +
                       " rows); this file has " + std::to_string(bytes) + " bytes", Json(*text));
      return {};
    }
    try {
      csv = ReadTextFile(file, "a conditions table");
    } catch (const std::exception& e) {
      Problem(ptr, e.what(), Json(*text));
      return {};
    }
  }
  tables_[*text] = csv;
  const CsvText table = ParseCsv(csv, size_t(kMaxTrials) + 1);
  auto at = [&](size_t line, size_t column) {
    return where + " line " + std::to_string(line) + (column ? ", column " + std::to_string(column) : "");
  };
  if (!table.problems.empty()) {
    const CsvProblem& p = table.problems.front();
    Problem(ptr, at(p.line, p.column) + ": " + p.message, Json(*text));
    return {};
  }
  const std::vector<CsvRecord>& rows = table.records;
  if (rows.size() < 2) {
    Problem(ptr, where + (rows.empty() ? ": is empty" : ": has a header but no rows") +
                     "; a conditions table needs a header naming its columns and at least one row", Json(*text));
    return {};
  }
  if (rows.size() > size_t(kMaxTrials) + 1) {
    Problem(ptr, where + ": more than " + std::to_string(kMaxTrials) + " rows", Json(*text));
    return {};
  }
  const std::vector<std::string>& header = rows.front().fields;
  // A spreadsheet set to another list separator (a German or French Excel's "CSV") writes ';' or a tab: the header
  // is then one column "edge;left;right", which was refused as a misspelt name to be recorded as label_edge;left;right.
  if (header.size() == 1)
    for (const char separator : {';', '\t'})
      if (header.front().find(separator) != std::string::npos) {
        Problem(ptr, at(rows.front().line, 0) + ": has one column, " + Echo(header.front()) + "; the columns of a "
                         "conditions table are separated by commas, and this one uses " +
                         (separator == ';' ? "';'" : "tabs") + " (save it as CSV with commas)", Json(*text));
        return {};
      }
  std::set<std::string> names;
  for (size_t c = 0; c < header.size(); ++c) {
    const std::string& name = header[c];
    if (name.empty() || Utf8Length(name) > kMaxNameChars || !IsPrintableUtf8(name) || !names.insert(name).second) {
      Problem(ptr, at(rows.front().line, c + 1) + " (" + Echo(name) + "): the header must name each column once, "
                       "1-100 characters", Json(*text));
      return {};
    }
  }
  // Each column is a level's name: read (edge, left, ...) or a label (id, label, label_*).
  for (size_t c = 0; c < header.size(); ++c) CheckReadName(header[c], "column", ptr, at(rows.front().line, c + 1) + ": ");
  Factor factor;
  factor.name = "row";
  for (size_t r = 1; r < rows.size(); ++r) {
    const std::string rp = ptr + "/row/" + std::to_string(r - 1);
    table_places_[rp] = at(rows[r].line, 0);
    if (rows[r].fields.size() != header.size()) {
      Problem(rp, "has " + std::to_string(rows[r].fields.size()) + " fields, the header " +
                      std::to_string(header.size()));
      continue;
    }
    Json level = Json::object();
    bool printable = true;
    for (size_t c = 0; c < header.size(); ++c) {
      const std::string& cell = rows[r].fields[c];
      const std::string cp = rp + "/" + Escape(header[c]);
      table_places_[cp] = at(rows[r].line, c + 1) + " (" + header[c] + ")";
      // A cell becomes a level, a label in the record, the tables and the report: text they can all hold as it
      // is. A Latin-1 byte or a NUL used to reach the record raw, or to stop validate with a JSON library error.
      if (!IsPrintableUtf8(cell)) {
        Problem(cp, "must be printable UTF-8 text on one line (no control characters or line breaks; save the "
                    "file as UTF-8), got " + Echo(cell));
        printable = false;
        continue;
      }
      if (cell.empty()) {
        Problem(cp, "is empty, got \"\"");
        continue;
      }
      const std::optional<double> number = IsLabelName(header[c]) ? std::nullopt : ParseDecimal(cell);
      if (number && !HoldsExactly(cell, *number)) {
        Problem(cp, "has more digits than a number holds exactly (it would be recorded as " +
                        Json(*number).dump() + "), got " + Echo(cell) +
                        "; a value that names something belongs in a label column (label_NAME), kept as text");
        continue;
      }
      level[header[c]] = !number                                             ? Json(cell)
                         : IsWholeDecimal(cell) && std::abs(*number) < 9e15 ? Json(int64_t(*number))
                                                                             : Json(*number);
      CheckLevelValue(header[c], level[header[c]], cp);
    }
    if (!printable) continue;
    factor.levels.push_back(LevelOf(factor.name, level));
  }
  return {factor};
}
}  // namespace blurcue::protocol::detail
