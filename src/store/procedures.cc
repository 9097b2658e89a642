// The procedures table (procedures.h): its one list of columns, a parsed procedure as a row, and the rows of a version
// recorded before the table (from its text, read in memory).
#include "store/procedures.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "core/error.h"
#include "core/json_io.h"
#include "core/names.h"
#include "core/typed.h"
#include "protocol/protocol.h"
#include "protocol/vocabulary.h"
#include "store/sqlite.h"

namespace blurcue::store {
namespace {

// A column of the table (and of procedures.csv unless `exported` is false), NOT NULL: a row is a whole procedure.
ProcedureColumn ProcedureKept(ColumnSpec spec, const std::string& sql, const std::string& check,
                              std::function<Value(const ProcedureRecord&)> of, bool exported = true) {
  ProcedureColumn c;
  static_cast<ColumnSpec&>(c) = std::move(spec);
  c.sql = sql, c.check = check, c.required = true, c.since = 10, c.of = std::move(of), c.exported = exported;
  return c;
}
// A column of procedures.csv read from the protocol version's study or the version itself.
ProcedureColumn ProcedureJoined(ColumnSpec spec, const std::string& select) {
  ProcedureColumn c;
  static_cast<ColumnSpec&>(c) = std::move(spec);
  c.select = select;
  return c;
}

std::string ProcedureWords(const std::vector<std::string>& words, const char* separator) {
  std::string text;
  for (const std::string& w : words) text += (text.empty() ? "" : separator) + w;
  return text;
}

std::vector<ProcedureColumn> MakeProcedureColumns() {
  using R = ProcedureRecord;
  const std::vector<std::string> kinds = protocol::Words<protocol::ProcedureKind>();
  const std::vector<std::string> variables = protocol::Words<protocol::ProcedureVariable>();
  return WithCells(std::vector<ProcedureColumn>{
      ProcedureJoined({"study", "string", "", "", "the study (protocol name)"}, "st.name"),
      ProcedureJoined(
          {"protocol_hash", "string", "", "16 hex digits", "the protocol version, as trials.csv's protocol_hash"},
          "pv.hash"),
      ProcedureKept({"block", "integer", "", "", "the block's index in the protocol, as trials.csv's block"}, "INTEGER",
                    "block >= 0", [](const R& r) { return Value(r.block); }),
      ProcedureKept({"block_name", "string", "", "", "the block's name"}, "TEXT", "",
                    [](const R& r) { return Value(r.block_name); }),
      // No CHECK from the vocabularies: a shipped migration's SQL never changes, and a later word must fit.
      ProcedureKept({"procedure", "string", "", ProcedureWords(kinds, "|"), "the adaptive procedure"}, "TEXT", "",
                    [](const R& r) { return Value(r.procedure); }),
      // Typed in the table for SQL over the record; procedures.csv gives them in parameters.
      ProcedureKept(
          {"variable", "string", "", ProcedureWords(variables, "|"), "the procedure's variable"}, "TEXT", "",
          [](const R& r) { return Value(r.variable); }, false),
      ProcedureKept(
          {"trials", "integer", "", ">= 1", "trials per crossing of the block's factors"}, "INTEGER", "trials >= 1",
          [](const R& r) { return Value(r.trials); }, false),
      ProcedureKept(
          {"guess", "number", "", "0..1", "the chance rate the procedure assumes"}, "REAL", "guess BETWEEN 0 AND 1",
          [](const R& r) { return Value(r.guess); }, false),
      ProcedureKept(
          {"parameters", "string", "", "JSON",
           "the procedure's parameters as the protocol parser reads them: procedure, variable, reference, trials; a "
           "staircase's start, min, max, up, down, steps, stop_reversals and guess (1/n of an odd one out's n "
           "intervals, else 0.5); QUEST+'s stimuli, thresholds, slopes, lapses (its grid, uniform prior) and guess"},
          "TEXT", "json_valid(parameters)", [](const R& r) { return Value(r.parameters); }),
  });
}

// The parameters as procedures.csv gives them (analysis/tracks.py reads them): the shared ones, then the kind's.
Json ParametersOf(const protocol::Procedure& p) {
  Json out = {{"procedure", protocol::ToString(p.kind)},
              {"variable", protocol::ToString(p.variable)},
              {"reference", protocol::ToJson(std::optional<protocol::BlurSpec>(p.reference))},
              {"trials", p.trials}};
  switch (p.kind) {
    case protocol::ProcedureKind::kStaircase:
      out.update({{"start", p.start},
                  {"min", p.min},
                  {"max", p.max},
                  {"up", p.up},
                  {"down", p.down},
                  {"steps", p.steps},
                  {"stop_reversals", p.stop_reversals},
                  {"guess", p.guess}});
      break;
    case protocol::ProcedureKind::kQuestPlus:
      out.update({{"stimuli", p.stimuli},
                  {"thresholds", p.thresholds},
                  {"slopes", p.slopes},
                  {"lapses", p.lapses},
                  {"guess", p.guess}});
      break;
  }
  return out;
}

}  // namespace

const std::vector<ProcedureColumn>& ProcedureColumns() {
  static const std::vector<ProcedureColumn> columns = MakeProcedureColumns();
  return columns;
}

std::vector<ProcedureRecord> ProcedureRecords(const std::vector<protocol::Block>& blocks) {
  std::vector<ProcedureRecord> records;
  for (size_t b = 0; b < blocks.size(); ++b) {
    if (!blocks[b].procedure) continue;
    const protocol::Procedure& p = *blocks[b].procedure;
    records.push_back({int64_t(b), blocks[b].name, protocol::ToString(p.kind), protocol::ToString(p.variable), p.trials,
                       p.guess, ParametersOf(p).dump()});
  }
  return records;
}

std::vector<ProcedureRecord> RecordedProcedures(const std::string& text) {
  try {
    Json json = ParseJson(text, "protocol");
    // What the record keeps beside the protocol's own fields: its conditions tables (protocol::RecordedText), read
    // from here instead of files, and a video study's take (stimulus::TakeIdentity), which the parser does not read.
    std::map<std::string, std::string> tables;
    if (json.is_object() && json.contains("recorded_conditions")) {
      for (const auto& [path, table] : json["recorded_conditions"].items())
        tables[path] = table.is_string() ? table.get<std::string>() : std::string();
      json.erase("recorded_conditions");
    }
    if (json.is_object()) json.erase("recorded_take");
    protocol::ValidateOptions options{false};
    options.conditions_tables = &tables;
    return ProcedureRecords(protocol::ParseProtocol(json, "protocol.json", options).blocks);
  } catch (const std::exception&) {
    // A text the parser refuses (an older blurcue's): no parameters to give; the analysis says its intervals are not
    // determined.
    return {};
  }
}

void SaveProcedures(Database& db, int64_t protocol_version_id, const std::vector<ProcedureRecord>& procedures) {
  Statement insert(db, InsertSql("procedures", "protocol_version_id", ProcedureColumns(), "INSERT OR IGNORE"));
  for (const ProcedureRecord& r : procedures) {
    insert.Bind(1, protocol_version_id);
    BindRow(ProcedureColumns(), insert, 2, r);
    insert.Run();
    insert.Reset();
  }
}

namespace {

// What a reader needs of one parameter: a number, a whole number >= 1 (or >= 0), or a non-empty list of numbers (positive ones
// for a staircase's steps).
enum class Need { kNumber, kCount, kCountOrNone, kNumbers, kPositiveNumbers };

std::string CheckedParameter(const Json& parameters, const std::string& name, Need need) {
  if (!parameters.contains(name)) return "parameters." + name + ": missing";
  const Json& v = parameters[name];
  const std::string said = "parameters." + name + ": " + Echo(v.dump()) + ": ";
  switch (need) {
    case Need::kNumber:
      return v.is_number() && std::isfinite(v.get<double>()) ? "" : said + "not a number";
    case Need::kCount:
      return v.is_number_integer() && v.get<int64_t>() >= 1 ? "" : said + "not a whole number >= 1";
    case Need::kCountOrNone:  // 0: no such rule (a staircase without a stop rule)
      return v.is_number_integer() && v.get<int64_t>() >= 0 ? "" : said + "not a whole number >= 0";
    case Need::kNumbers:
    case Need::kPositiveNumbers:
    {
      const std::string list = need == Need::kPositiveNumbers ? "not a list of positive numbers" : "not a list of numbers";
      if (!v.is_array() || v.empty()) return said + list;
      for (const Json& x : v)
        if (!x.is_number() || !std::isfinite(x.get<double>()) || (need == Need::kPositiveNumbers && !(x.get<double>() > 0)))
          return said + list;
      return "";
    }
  }
  return "";
}

// What is wrong with one row, "" when nothing.
std::string ProcedureRowProblem(const ProcedureRecord& r) {
  const std::vector<std::string> kinds = protocol::Words<protocol::ProcedureKind>();
  const std::vector<std::string> variables = protocol::Words<protocol::ProcedureVariable>();
  if (std::find(kinds.begin(), kinds.end(), r.procedure) == kinds.end())
    return "procedure " + Echo(r.procedure) + ": not one of " + ProcedureWords(kinds, ", ") + DidYouMean(r.procedure, kinds);
  if (std::find(variables.begin(), variables.end(), r.variable) == variables.end())
    return "variable " + Echo(r.variable) + ": not one of " + ProcedureWords(variables, ", ") +
           DidYouMean(r.variable, variables);
  if (!(r.guess >= 0 && r.guess < 1)) return "guess " + Num(r.guess) + ": not a rate in [0, 1)";
  Json p;
  try {
    p = ParseJson(r.parameters, "parameters");  // the project's parser: its depth guard, its duplicate-key check
  } catch (const std::exception&) {
    return "parameters " + Echo(r.parameters) + ": not JSON";
  }
  if (!p.is_object()) return "parameters " + Echo(r.parameters) + ": not a JSON object";
  if (p.value("procedure", Json()) != Json(r.procedure)) return "parameters.procedure: not the row's procedure " + Echo(r.procedure);
  if (p.value("variable", Json()) != Json(r.variable)) return "parameters.variable: not the row's variable " + Echo(r.variable);
  if (p.value("trials", Json()) != Json(r.trials)) return "parameters.trials: not the row's trials " + std::to_string(r.trials);
  if (!p.contains("guess") || !p["guess"].is_number() || p["guess"].get<double>() != r.guess)
    return "parameters.guess: not the row's guess " + Num(r.guess);
  if (!p.contains("reference")) return "parameters.reference: missing";
  const bool staircase = r.procedure == protocol::ToString(protocol::ProcedureKind::kStaircase);
  const std::vector<std::pair<const char*, Need>> needs =
      staircase ? std::vector<std::pair<const char*, Need>>{{"start", Need::kNumber}, {"min", Need::kNumber},
                                                             {"max", Need::kNumber}, {"up", Need::kCount},
                                                             {"down", Need::kCount}, {"stop_reversals", Need::kCountOrNone},
                                                             {"steps", Need::kPositiveNumbers}}
                : std::vector<std::pair<const char*, Need>>{{"stimuli", Need::kNumbers}, {"thresholds", Need::kNumbers},
                                                             {"slopes", Need::kNumbers}, {"lapses", Need::kNumbers}};
  for (const auto& [name, need] : needs)
    if (std::string problem = CheckedParameter(p, name, need); !problem.empty()) return problem;
  if (staircase && !(p["min"].get<double>() <= p["start"].get<double>() && p["start"].get<double>() <= p["max"].get<double>()))
    return "parameters.start " + Num(p["start"].get<double>()) + ": not within [min, max] = [" + Num(p["min"].get<double>()) +
           ", " + Num(p["max"].get<double>()) + "]";
  return "";
}

}  // namespace

void CheckProcedures(Database& db, const std::string& file) {
  Statement rows(db, "SELECT pv.hash, pr.block, pr.block_name, pr.procedure, pr.variable, pr.trials, pr.guess, "
                     "pr.parameters, pr.protocol_version_id FROM procedures pr LEFT JOIN protocol_versions pv "
                     "ON pv.id = pr.protocol_version_id ORDER BY pr.protocol_version_id, pr.block");
  while (rows.Step()) {
    const std::string row = "procedures row (protocol version " +
                            (rows.IsNull(0) ? std::to_string(rows.GetInt64(8)) : rows.GetText(0)) + ", block " +
                            std::to_string(rows.GetInt64(1)) + ")";
    if (rows.IsNull(0)) throw InputError(file, row + ": no such protocol version in the record");
    const ProcedureRecord r{rows.GetInt64(1), rows.GetText(2), rows.GetText(3), rows.GetText(4),
                            rows.GetInt64(5), rows.GetDouble(6), rows.GetText(7)};
    if (r.block < 0) throw InputError(file, row + ": block " + std::to_string(r.block) + ": not a block's index");
    if (const std::string problem = ProcedureRowProblem(r); !problem.empty())
      throw InputError(file, row + ": " + problem + " (a hand-edited record?)");
  }
}

void DeriveProcedures(Database& db, const std::string& where) {
  Statement versions(
      db, "SELECT id, json FROM protocol_versions" + (where.empty() ? "" : " WHERE " + where) + " ORDER BY id");
  std::vector<std::pair<int64_t, std::string>> texts;
  while (versions.Step()) texts.emplace_back(versions.GetInt64(0), versions.GetText(1));
  for (const auto& [id, text] : texts) SaveProcedures(db, id, RecordedProcedures(text));
}

}  // namespace blurcue::store
