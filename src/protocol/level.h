#pragma once
// A trial's levels and the blur of its sides as typed values: what BuildTrials hands on, so that nothing after
// protocol/ reads raw protocol JSON for them. Each value keeps what it was written as (a number's JSON text, a label's
// characters), so that ToJson gives back exactly the JSON the protocol wrote and the record's text stays as it was.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/json_io.h"
#include "protocol/vocabulary.h"

namespace blurcue::protocol {

// A level's value: a number or a text label, exactly as written - "007" stays the text 007; 3 stays the whole number
// 3 (not 3.0), and 0.1 the double the file's 0.1 reads as.
struct LevelValue {
  enum class Kind { kInteger, kReal, kText };  // kInteger: a JSON number written without a point or an exponent
  Kind kind = Kind::kText;
  double number = 0;  // kInteger, kReal
  std::string text;   // kText: the label; a number: its JSON text, as the record writes it ("3", "2.5")
  bool IsNumber() const { return kind != Kind::kText; }
  bool operator==(const LevelValue& o) const { return kind == o.kind && text == o.text; }
};

// One factor's level in a trial: a value (with the unit the factor's name states: speed_cm_s is in cm/s), or an
// object - a pattern, a conditions table's row - whose keys carry values (its sides' words among them).
struct Level {
  std::string factor;
  std::string unit;  // "" when the name states none (edge, a label)
  bool object = false;
  LevelValue value;                                        // !object
  std::vector<std::pair<std::string, LevelValue>> fields;  // object: its keys in name order
  // The value under `key` of an object level (null when it has none, or for a plain level).
  const LevelValue* Field(const std::string& key) const;
  bool operator==(const Level& o) const {
    return factor == o.factor && object == o.object && value == o.value && fields == o.fields;
  }
};

// What a side shows: a blur source of the calibration, no blur, or a fixed radius in photo px (a bare number), screen
// px ({"screen_px": r}) or arcmin ({"arcmin": r}).
struct BlurSpec {
  BlurSource source = BlurSource::kNone;
  LevelValue radius;                      // kFixed: the radius, as written
  RadiusUnit unit = RadiusUnit::kPhotoPx;  // kFixed: the radius's unit
  bool operator==(const BlurSpec& o) const {
    return source == o.source && (source != BlurSource::kFixed || (radius == o.radius && unit == o.unit));
  }
};

// The unit a value's name states by its suffix, as the house names values (speed_cm_s -> "cm/s", distance_m -> "m",
// stimulus_ms -> "ms"; "" for none).
std::string UnitOf(const std::string& name);

// A number or a string as a LevelValue; Error(kInput) for any other JSON.
LevelValue LevelValueOf(const Json& value);
// One factor's level as written (a number, a string, or an object of numbers and strings); Error(kInput) otherwise.
Level LevelOf(const std::string& factor, const Json& level);
// Every level of {factor: level, ...}, in name order (as a JSON object lists them).
std::vector<Level> LevelsOf(const Json& levels);
// A side's source as the protocol writes it (a word of Vocabulary<BlurSource> but "fixed", a radius in photo px, or
// {"screen_px": r} / {"arcmin": r}); Error(kInput) naming the value otherwise. The parser has checked every side it
// read, so this throws only for a trial made by hand.
BlurSpec BlurSpecOf(const Json& side);

// The JSON each was made from, exactly (numbers with their kind: 3 not 3.0).
Json ToJson(const LevelValue& value);
Json ToJson(const Level& level);
Json ToJson(const std::vector<Level>& levels);  // {factor: level, ...}
Json ToJson(const std::optional<BlurSpec>& side);  // null for no side

// A side as the protocol wrote it, for people to read: a source's word ("measured"), a radius's JSON ("2.5",
// {"screen_px":1}), "null" for no side.
std::string SideText(const std::optional<BlurSpec>& side);

// An order of levels for listings and keys, the one their JSON has (a trial's levels used to be listed by it): by
// factor name, then value - numbers by value (2 before 10; 2 and 2.0 are one) before objects (key by key) before text.
// Negative, zero or positive as `a` comes before, with or after `b`.
int Compare(const LevelValue& a, const LevelValue& b);
int Compare(const Level& a, const Level& b);
int Compare(const std::vector<Level>& a, const std::vector<Level>& b);  // factor by factor; a prefix first
// The order above, for maps and sorts keyed by a trial's levels.
struct LevelsLess {
  bool operator()(const std::vector<Level>& a, const std::vector<Level>& b) const { return Compare(a, b) < 0; }
};

// A trial's level by name: a factor of its own that holds a value, or a key of an object level (a pattern carries
// speed and sides, a conditions table's row every column); null when neither.
const LevelValue* FindLevel(const std::vector<Level>& levels, const std::string& name);

}  // namespace blurcue::protocol
