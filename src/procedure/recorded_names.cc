#include "procedure/recorded_names.h"

#include <cctype>
#include <map>
#include <set>

#include "core/error.h"
#include "store/export.h"

namespace blurcue::procedure {
namespace {

// Where a design variable is given: its name, what gives it (in words) and the JSON pointer of that.
struct Origin {
  std::string name, what, pointer;
};

// A name a model formula reads as one variable: letters (any script: bytes of UTF-8 beyond ASCII), digits and _,
// not starting with a digit.
bool IsFormulaName(const std::string& name) {
  if (name.empty() || std::isdigit(static_cast<unsigned char>(name.front()))) return false;
  for (const char c : name) {
    const auto u = static_cast<unsigned char>(c);
    if (!(u >= 0x80 || std::isalnum(u) || c == '_')) return false;
  }
  return true;
}

}  // namespace

std::vector<std::string> RecordedNameProblems(const protocol::Protocol& protocol) {
  std::vector<std::string> problems;
  const std::string file = protocol.file.string();
  auto why = [](const std::string& name) {
    const std::string column = store::DesignColumn(name);
    return column == name ? std::string()
                          : " (" + name + " is a column trials.csv writes itself, so a design's " + name +
                                " is recorded as " + column + ")";
  };
  // Column -> the first variable recorded in it, over the whole protocol (one column of trials.csv holds one
  // variable in every block); a name given again in another block is the same variable.
  std::map<std::string, Origin> columns;
  for (const protocol::Block& block : protocol.blocks) {
    // Name -> the factor that gives it in this block (a trial records one value per name).
    std::map<std::string, std::string> given;
    const bool table = block.factors_pointer.size() >= 11 &&
                       block.factors_pointer.compare(block.factors_pointer.size() - 11, 11, "/conditions") == 0;
    const std::string path = table ? block.conditions : "";
    auto add = [&](const Origin& o, const std::string& factor) {
      const auto [in_block, first] = given.emplace(o.name, factor);
      // Two factors of object levels each with ids: the id column keeps the first's, and each factor's own column
      // shows its level by its id, so nothing is lost.
      if (!first && in_block->second != factor && !(o.name == "id" && !factor.empty() && !in_block->second.empty())) {
        problems.push_back(file + ": " + o.pointer + ": " + o.what + " gives " + o.name + " again in a block whose " +
                           (in_block->second.empty() ? "factor " + o.name : "factor " + in_block->second + "'s levels") +
                           " give it already: a trial would record one of them and drop the other; rename one, got " +
                           Json(o.name).dump());
        return;
      }
      const std::string column = store::DesignColumn(o.name);
      if (store::IsRecordedName(column)) {
        problems.push_back(file + ": " + o.pointer + ": " + o.what + " would be recorded in " + column +
                           ", a column trials.csv writes itself; rename it, got " + Json(o.name).dump());
        return;
      }
      const auto [at, fresh] = columns.emplace(column, o);
      if (!fresh && at->second.name != o.name)
        problems.push_back(file + ": " + o.pointer + ": " + o.what + " is recorded in the column " + column +
                           ", as is " + at->second.what + " (" + at->second.pointer + ")" +
                           why(at->second.name) + why(o.name) +
                           ": one of them would be stored nowhere; rename one, got " + Json(o.name).dump());
    };
    for (const protocol::Factor& f : block.factors) {
      const std::string at = block.factors_pointer + (table ? "" : "/" + JsonPointerToken(f.name));
      bool objects = false;
      for (const protocol::Level& level : f.levels) objects = objects || level.object;
      // A conditions table's rows (factor "row") and any factor of object levels named row: only their keys are
      // recorded (TrialVariables).
      if (!(f.name == "row" && objects)) add({f.name, "the factor " + f.name, at}, "");
      // A factor of object levels is named freely, and the report analyses it: its name is a term of the models'
      // formulas (Python's patsy, R's lme4), so it is a name they read as one. A factor side/pair validated, ran
      // and stopped the report (exit 10: patsy read side divided by pair). Any other factor or key is a name
      // blurcue reads or a label, which no model reads.
      if (objects && !IsFormulaName(f.name))
        problems.push_back(file + ": " + at + ": the factor " + f.name + " names a term of the report's models (R "
                           "and Python formulas): letters, digits and _ only, not starting with a digit; got " +
                           Json(f.name).dump());
      std::set<std::string> keys;  // each key once per factor (every row of a table has every column)
      for (size_t i = 0; i < f.levels.size(); ++i) {
        for (const auto& [key, value] : f.levels[i].fields) {
          // The sides are recorded as such.
          if (protocol::ParseWord<protocol::Side>(key) || key == "object" || !keys.insert(key).second) continue;
          if (table)
            add({key, "the column " + key + " of the conditions table " + (path.empty() ? "" : path), at}, f.name);
          else
            add({key, "the key " + key + " of the factor " + f.name + "'s levels",
                 at + "/" + std::to_string(i) + "/" + JsonPointerToken(key)},
                f.name);
        }
      }
    }
  }
  // A block inheriting the top level's factors finds their problems again.
  std::vector<std::string> once;
  std::set<std::string> said;
  for (std::string& p : problems)
    if (said.insert(p).second) once.push_back(std::move(p));
  return once;
}

void CheckRecordedNames(const protocol::Protocol& protocol) {
  const std::vector<std::string> problems = RecordedNameProblems(protocol);
  if (!problems.empty()) throw Error(ErrorKind::kInput, problems);
}

}  // namespace blurcue::procedure
