#include "protocol/parser.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>

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
  if (name == "edge" || name == "from_edge" || name == "to_edge") integer_in(1, kEdges, "an edge");
  else if (name == "section") integer_in(1, kEdges - 1, "a section (edge s to s + 1)");
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
  else if (name == "left" || name == "right" || name == "object") {
    if (!IsBlurSource(v))
      report("a blur source must be none, measured, measured_section, estimated, fitted, a radius in " +
             Range(0, kMaxFixedRadiusPx, "photo px") + ", {\"screen_px\": r} with r in " +
             Range(0, kMaxFixedRadiusPx, "") + " or {\"arcmin\": r} with r in " + Range(0, 600, "") +
             (v.is_string() ? DidYouMean(v.get<std::string>(), {"none", "measured", "measured_section", "estimated",
                                                                "fitted"})
                            : std::string()));
  } else if (v.is_number() && !std::isfinite(v.get<double>())) {
    report("must be a finite number");
  }
}

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
    if (name.empty() || name.size() > kMaxNameChars || !IsPrintableUtf8(name)) {
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
        Problem(lp, "repeats level " + std::to_string(first->second), level);
      // A factor named for a value (edge, speed_cm_s, ...) holds that value itself; any other factor's object
      // levels carry named values.
      if (level.is_object() && !IsValueName(name)) {
        for (const auto& [key, value] : level.items()) {
          if (keys_checked.insert(key).second) CheckReadName(key, "level key", lp + "/" + Escape(key));
          if (value.is_object() || value.is_array()) Problem(lp + "/" + Escape(key), "must be a number or a string", value);
          else CheckLevelValue(key, value, lp + "/" + Escape(key));
        }
        const bool l = level.contains("left"), r = level.contains("right");
        if (l != r) Problem(lp, std::string("has \"") + (l ? "left" : "right") + "\" but no \"" + (l ? "right" : "left") + "\"", level);
        if (level.contains("object") && (l || r))
          Problem(lp, "has an \"object\" (layout single) and left/right (a pair): give one or the other", level);
        if ((l && r) || level.contains("object")) sides = true;
        if (level.contains("from_edge") && level.contains("to_edge") && level["from_edge"].is_number_integer() &&
            level["to_edge"].is_number_integer() && level["from_edge"] == level["to_edge"])
          Problem(lp, "from_edge and to_edge must differ", level);
      } else {
        CheckLevelValue(name, level, lp);
      }
      f.levels.push_back(level);
    }
    if (sides) ++carrying_sides;
    factors.push_back(std::move(f));
  }
  if (carrying_sides > 1) Problem(ptr, "at most one factor may carry left and right", v);
  return factors;
}

// A conditions table instead of factors: a CSV file whose header names the levels (edge, speed_cm_s, left, right,
// any label) and whose every row is one design row - for designs that are not full crossings. It becomes one factor
// "row" whose levels are the rows as objects (numbers read as numbers), checked like any level: a problem names
// /.../conditions/row/K/COLUMN, K counting the table's data rows from 0.
std::vector<Factor> Parser::ParseConditions(const Json& v, const std::string& ptr) {
  const auto text = Text(v, "conditions", ptr.substr(0, ptr.rfind('/')), true, kMaxPathChars, true);
  if (!text) return {};
  const fs::path file = (base_ / *text).lexically_normal();
  if (!CheckFile(file, ptr, Json(*text))) return {};
  std::string csv;
  try {
    csv = ReadTextFile(file);
  } catch (const std::exception& e) {
    Problem(ptr, e.what(), Json(*text));
    return {};
  }
  // Excel's "CSV UTF-8" and Notepad begin the file with a byte order mark; it is not part of the first column's
  // name (it used to be, and the column - edge - was refused as an unknown name that looked like edge).
  if (csv.rfind("\xEF\xBB\xBF", 0) == 0) csv.erase(0, 3);
  // Comma-separated, double quotes around a field that holds commas or quotes ("" for one quote); a field does not
  // span lines, so a quote still open at the line's end is an error (it used to swallow the rest of the line).
  struct Row {
    std::vector<std::string> fields{1};
    size_t line = 0;      // in the file, from 1
    bool closed = true;   // every quote closed
  };
  auto split = [](const std::string& line, size_t number) {
    Row row;
    row.line = number;
    bool quoted = false;
    for (size_t i = 0; i < line.size(); ++i) {
      const char c = line[i];
      if (quoted && c == '"' && i + 1 < line.size() && line[i + 1] == '"') row.fields.back() += '"', ++i;
      else if (c == '"') quoted = !quoted;
      else if (c == ',' && !quoted) row.fields.emplace_back();
      else row.fields.back() += c;
    }
    row.closed = !quoted;
    return row;
  };
  std::vector<Row> rows;
  size_t start = 0, number = 0;
  while (start <= csv.size()) {
    size_t end = csv.find('\n', start);
    if (end == std::string::npos) end = csv.size();
    std::string line = csv.substr(start, end - start);
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!line.empty()) rows.push_back(split(line, number));
    start = end + 1;
    if (rows.size() > size_t(kMaxTrials) + 1) break;
  }
  const std::string where = file.string();
  if (rows.size() < 2) {
    Problem(ptr, where + ": needs a header and at least one row", Json(*text));
    return {};
  }
  if (rows.size() > size_t(kMaxTrials) + 1) {
    Problem(ptr, where + ": more than " + std::to_string(kMaxTrials) + " rows", Json(*text));
    return {};
  }
  const std::string unclosed = ": a quoted field is not closed (a field cannot span lines; write \"\" for a quote)";
  if (!rows.front().closed) {
    Problem(ptr, where + " line " + std::to_string(rows.front().line) + unclosed, Json(*text));
    return {};
  }
  const std::vector<std::string>& header = rows.front().fields;
  std::set<std::string> names;
  for (const auto& name : header)
    if (name.empty() || name.size() > kMaxNameChars || !IsPrintableUtf8(name) || !names.insert(name).second) {
      Problem(ptr, where + ": the header must name each column once, 1-100 characters, got \"" + name + "\"",
              Json(*text));
      return {};
    }
  // Each column is a level's name: read (edge, left, ...) or a label (id, label, label_*).
  for (size_t c = 0; c < header.size(); ++c)
    CheckReadName(header[c], "column", ptr,
                  where + " line " + std::to_string(rows.front().line) + ", column " + std::to_string(c + 1) + ": ");
  Factor factor;
  factor.name = "row";
  for (size_t r = 1; r < rows.size(); ++r) {
    const std::string rp = ptr + "/row/" + std::to_string(r - 1);
    const std::string line = where + " line " + std::to_string(rows[r].line);
    if (!rows[r].closed) {
      Problem(rp, line + unclosed, Json(*text));
      continue;
    }
    if (rows[r].fields.size() != header.size()) {
      Problem(rp, line + ": has " + std::to_string(rows[r].fields.size()) + " fields, the header " +
                      std::to_string(header.size()), Json(*text));
      continue;
    }
    Json level = Json::object();
    bool printable = true;
    for (size_t c = 0; c < header.size(); ++c) {
      const std::string& cell = rows[r].fields[c];
      const std::string cp = rp + "/" + Escape(header[c]);
      // A cell becomes a level, a label in the record, the tables and the report: text they can all hold as it
      // is. A Latin-1 byte or a NUL used to reach the record raw, or to stop validate with a JSON library error.
      if (!IsPrintableUtf8(cell)) {
        Problem(cp, line + ", column " + std::to_string(c + 1) + " (" + header[c] +
                        "): must be printable UTF-8 text (no control characters; save the file as UTF-8), got " +
                        Echo(cell));
        printable = false;
        continue;
      }
      const std::optional<double> number = ParseDecimal(cell);
      level[header[c]] = IsWholeDecimal(cell) && std::abs(*number) < 9e15 ? Json(int64_t(*number))
                         : number                                       ? Json(*number)
                                                                        : Json(cell);
      // Where the cell is, for the one who opens the table to fix it.
      const std::string in = " (" + line + ", column " + std::to_string(c + 1) + ")";
      if (cell.empty()) Problem(cp, "is empty, got \"\"" + in);
      else CheckLevelValue(header[c], level[header[c]], cp, in);
    }
    if (!printable) continue;
    factor.levels.push_back(std::move(level));
  }
  return {factor};
}
}  // namespace blurcue::protocol::detail
