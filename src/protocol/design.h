#pragma once
// The design as the record and its tables see it: every column a protocol's design puts in trials.csv, with its role
// (within subject, between-subject group, procedure cell, recorded label, practice flag), its type and unit, and the
// values the protocol allows - plain typed data, so the record, the codebook and the analysis read one description.
#include <optional>
#include <string>
#include <vector>

#include "protocol/protocol.h"
#include "protocol/trials.h"

namespace blurcue::protocol {

// What a design column is to the analysis: varied within subject, the between-subject group, a factor that splits a
// procedure into cells (each its own track and threshold), recorded only, or the practice flag.
enum class Role { kWithin, kGroup, kProcedureCell, kLabel, kPractice };
enum class ValueType { kInteger, kNumber, kString, kBoolean };

// "within" | "group" | "procedure_cell" | "label" | "practice"; "integer" | "number" | "string" | "boolean".
std::string ToString(Role role);
std::string ToString(ValueType type);

struct DesignColumn {
  std::string name;    // the level's name (a factor, an object level's key), or the column's: group, info_KEY, ...
  bool level = false;  // a level of the design: recorded under store::DesignColumn(name), which may prefix factor_
  Role role = Role::kWithin;
  ValueType type = ValueType::kString;
  std::string unit;                  // from the name's unit suffix (_mm, _cm_s, _ms, ...), else ""
  std::vector<double> numbers;       // numeric levels, ascending, each once
  std::vector<std::string> names;    // text levels (an object level by its id) or choices, in the protocol's order
  std::optional<double> min, max;    // a range: a procedure's [min, max], a rating's 1..n, an answer's bounds
};

// Every column the design of `protocol` puts in trials.csv, in this order: each factor's level and each key of an
// object level or conditions row (in block and factor order, each name once; a factor of any procedure block is a
// procedure cell, else within; an object level's id is a label), the procedure's level (its [min, max] or its QUEST+ stimuli), the rating (1..n),
// the group, each participant_info key (info_KEY: its choices or range), and practice (0|1).
std::vector<DesignColumn> DescribeDesign(const Protocol& protocol);

// A level as trials.csv shows it: a string bare, a number as JSON (LevelValue::text, both), an object by its id (else
// its members as key=value;... : "left=measured;right=estimated"), as the export's TidyCell does.
std::string LevelName(const Level& level);

// A procedure trial's cell by its levels: its block's factors as NAME=LEVEL joined by ';' in name order ("edge=9",
// "edge=9;speed_cm_s=3"; numbers as LevelText, an object level by its id); "" for a trial outside a procedure.
std::string CellLevels(const Protocol& protocol, const Trial& trial);

}  // namespace blurcue::protocol
