#include "protocol/design.h"

#include "protocol/parser.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

namespace blurcue::protocol {
std::string LevelName(const Level& level) {
  if (!level.object) return level.value.text;
  if (const LevelValue* id = level.Field("id")) return id->text;
  std::string text;
  for (const auto& [key, member] : level.fields) text += (text.empty() ? "" : ";") + key + "=" + member.text;
  return text;
}

namespace {

// The values one column takes, collected over blocks: numbers apart, so they are given in numeric order.
struct Values {
  std::set<double> numbers;
  std::map<double, std::string> number_texts;  // each number as trials.csv writes it (1, not 1.0), first seen
  std::vector<std::string> names;
  bool integers = true, others = false;
  void Add(const LevelValue& v) {
    if (v.IsNumber()) {
      const double x = v.number;
      numbers.insert(x);
      number_texts.emplace(x, v.text);
      if (!(std::isfinite(x) && x == std::floor(x))) integers = false;
      return;
    }
    AddName(v.text);
  }
  void AddName(const std::string& name) {
    others = true;
    if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
  }
  void Into(DesignColumn* c) const {
    if (others) {  // mixed or text: every value as text, in the protocol's order
      c->type = ValueType::kString;
      c->names = names;
      for (double x : numbers) {
        // As the level's own text: a label [1, "a"] used to be allowed "a|1.0" while trials.csv holds 1.
        const std::string& text = number_texts.at(x);
        if (std::find(c->names.begin(), c->names.end(), text) == c->names.end()) c->names.push_back(text);
      }
    } else {
      c->type = integers ? ValueType::kInteger : ValueType::kNumber;
      c->numbers.assign(numbers.begin(), numbers.end());
    }
  }
};

}  // namespace

std::string ToString(Role role) {
  switch (role) {
    case Role::kWithin: return "within";
    case Role::kGroup: return "group";
    case Role::kProcedureCell: return "procedure_cell";
    case Role::kLabel: return "label";
    case Role::kPractice: return "practice";
  }
  return "within";
}

std::string ToString(ValueType type) {
  switch (type) {
    case ValueType::kInteger: return "integer";
    case ValueType::kNumber: return "number";
    case ValueType::kString: return "string";
    case ValueType::kBoolean: return "boolean";
  }
  return "string";
}

std::vector<DesignColumn> DescribeDesign(const Protocol& protocol) {
  // The levels first, in the order the blocks and their factors name them; a name is one column however many blocks
  // vary it (as in trials.csv).
  std::vector<std::string> order;
  std::map<std::string, Values> values;
  std::set<std::string> cells;
  auto add = [&](const std::string& name, bool cell) -> Values& {
    if (!values.count(name)) order.push_back(name);
    if (cell) cells.insert(name);
    return values[name];
  };
  for (const Block& block : protocol.blocks)
    for (const Factor& factor : block.factors) {
      const bool cell = block.procedure.has_value();
      for (const Level& level : factor.levels) {
        // A conditions table's row is no column of its own: its columns are (session/recording.cc TrialVariables).
        if (!level.object) add(factor.name, cell).Add(level.value);
        else if (factor.name != "row") add(factor.name, cell).AddName(LevelName(level));
        for (const auto& [key, value] : level.fields)
          if (!ParseWord<Side>(key) && key != "object" && key != factor.name) add(key, cell).Add(value);
      }
    }
  std::vector<DesignColumn> columns;
  for (const std::string& name : order) {
    DesignColumn c;
    c.name = name;
    c.level = true;
    // An object level's id names the level (a pattern's) rather than varying the stimulus: a label beside it.
    // A label (id, label, label_*: IsLabelName) is read by nothing; it used to be given the role within when a
    // factor or a conditions column, varying nothing.
    c.role = detail::IsLabelName(name) ? Role::kLabel : cells.count(name) ? Role::kProcedureCell : Role::kWithin;
    c.unit = UnitOf(name);
    values[name].Into(&c);
    columns.push_back(std::move(c));
  }
  // The procedure's level: a staircase's bounds, QUEST+'s stimuli (over every procedure block).
  std::optional<DesignColumn> level;
  for (const Block& block : protocol.blocks) {
    if (!block.procedure) continue;
    const Procedure& p = *block.procedure;
    if (!level) {
      level.emplace();
      level->name = "level";
      level->role = Role::kWithin;
      level->type = ValueType::kNumber;
      level->unit = p.variable == ProcedureVariable::kDifferenceArcmin ? "arcmin" : "";
    }
    if (p.kind == Procedure::Kind::kQuestPlus) {
      std::set<double> all(level->numbers.begin(), level->numbers.end());
      all.insert(p.stimuli.begin(), p.stimuli.end());
      level->numbers.assign(all.begin(), all.end());
    } else {
      level->min = level->min ? std::min(*level->min, p.min) : p.min;
      level->max = level->max ? std::max(*level->max, p.max) : p.max;
    }
  }
  if (level) {
    // Staircase and QUEST+ blocks together: one range over both.
    if (level->min && !level->numbers.empty()) {
      level->min = std::min(*level->min, level->numbers.front());
      level->max = std::max(*level->max, level->numbers.back());
      level->numbers.clear();
    }
    columns.push_back(*level);
  }
  if (std::any_of(protocol.blocks.begin(), protocol.blocks.end(),
                  [](const Block& b) { return TraitsOf(b.task).answer == TaskAnswer::kRatingPoint; }) &&
      !protocol.responses.rating.empty()) {
    DesignColumn rating;
    rating.name = "rating";
    rating.role = Role::kLabel;
    rating.type = ValueType::kInteger;
    rating.min = 1;
    rating.max = static_cast<double>(protocol.responses.rating.size());
    columns.push_back(rating);
  }
  if (protocol.groups) {
    DesignColumn group;
    group.name = "group";
    group.role = Role::kGroup;
    group.names = protocol.groups->names;
    columns.push_back(group);
  }
  for (const InfoField& field : protocol.participant_info) {
    DesignColumn info;
    info.name = "info_" + field.key;
    info.role = Role::kLabel;
    info.unit = UnitOf(field.key);
    switch (field.type) {
      case InfoType::kInteger:
      case InfoType::kNumber:
        info.type = field.type == InfoType::kInteger ? ValueType::kInteger : ValueType::kNumber;
        if (field.max > field.min) info.min = field.min, info.max = field.max;
        break;
      case InfoType::kChoice:
      case InfoType::kText: info.names = field.choices; break;
    }
    columns.push_back(info);
  }
  DesignColumn practice;
  practice.name = "practice";
  practice.role = Role::kPractice;
  practice.type = ValueType::kBoolean;
  practice.numbers = {0, 1};
  columns.push_back(practice);
  return columns;
}

std::string CellLevels(const Protocol& protocol, const Trial& trial) {
  const Block* block = BlockOf(protocol, trial);
  if (trial.cell < 0 || !block || !block->procedure) return "";
  std::string text;
  for (const Factor& factor : block->factors) {
    const auto level = std::find_if(trial.levels.begin(), trial.levels.end(),
                                    [&](const Level& l) { return l.factor == factor.name; });
    if (level == trial.levels.end()) continue;
    const std::string value =
        !level->object && level->value.IsNumber() ? LevelText(level->value.number) : LevelName(*level);
    text += (text.empty() ? "" : ";") + factor.name + "=" + value;
  }
  return text;
}

}  // namespace blurcue::protocol
