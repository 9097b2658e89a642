#include "protocol/level.h"

#include "core/error.h"

namespace blurcue::protocol {

std::string UnitOf(const std::string& name) {
  static const std::vector<std::pair<std::string, std::string>> suffixes = {
      {"_cm_s", "cm/s"}, {"_mm", "mm"}, {"_cm", "cm"}, {"_ms", "ms"}, {"_px", "px"}, {"_arcmin", "arcmin"},
      {"_deg", "deg"},   {"_m", "m"},   {"_s", "s"}};
  for (const auto& [suffix, unit] : suffixes)
    if (name.size() > suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0)
      return unit;
  return "";
}

const LevelValue* Level::Field(const std::string& key) const {
  for (const auto& [name, value] : fields)
    if (name == key) return &value;
  return nullptr;
}

LevelValue LevelValueOf(const Json& value) {
  LevelValue v;
  if (value.is_string()) {
    v.kind = LevelValue::Kind::kText;
    v.text = value.get<std::string>();
  } else if (value.is_number()) {
    // nlohmann keeps whether the file wrote a whole number (3) or not (3.0, 1e2): the text it dumps says which, and
    // reads back as the same JSON number.
    v.kind = value.is_number_float() ? LevelValue::Kind::kReal : LevelValue::Kind::kInteger;
    v.number = value.get<double>();
    v.text = value.dump();
  } else {
    throw Error(ErrorKind::kInput, "a level must be a number or a string, got " + value.dump());
  }
  return v;
}

Level LevelOf(const std::string& factor, const Json& level) {
  Level l;
  l.factor = factor;
  l.unit = UnitOf(factor);
  if (level.is_object()) {
    l.object = true;
    for (const auto& [key, value] : level.items()) l.fields.emplace_back(key, LevelValueOf(value));
  } else {
    l.value = LevelValueOf(level);
  }
  return l;
}

std::vector<Level> LevelsOf(const Json& levels) {
  std::vector<Level> out;
  if (!levels.is_object()) return out;
  for (const auto& [name, level] : levels.items()) out.push_back(LevelOf(name, level));
  return out;
}

BlurSpec BlurSpecOf(const Json& side) {
  BlurSpec spec;
  if (side.is_number() || (side.is_object() && side.size() == 1 && (side.contains("screen_px") || side.contains("arcmin")) &&
                           side.front().is_number())) {
    spec.source = BlurSource::kFixed;
    spec.unit = side.is_number() ? RadiusUnit::kPhotoPx
                : side.contains("arcmin") ? RadiusUnit::kArcmin
                                          : RadiusUnit::kScreenPx;
    spec.radius = LevelValueOf(side.is_number() ? side : side.front());
    return spec;
  }
  if (side.is_string())
    if (const auto source = ParseWord<BlurSource>(side.get<std::string>()); source && *source != BlurSource::kFixed) {
      spec.source = *source;
      return spec;
    }
  throw Error(ErrorKind::kInput, "the trial shows no blur source on this side, got " + side.dump());
}

Json ToJson(const LevelValue& value) {
  switch (value.kind) {
    case LevelValue::Kind::kText: return Json(value.text);
    case LevelValue::Kind::kInteger: return Json::parse(value.text);  // exactly: an integer beyond 2^53 too
    case LevelValue::Kind::kReal: return Json(value.number);
  }
  return Json();
}

Json ToJson(const Level& level) {
  if (!level.object) return ToJson(level.value);
  Json j = Json::object();
  for (const auto& [key, value] : level.fields) j[key] = ToJson(value);
  return j;
}

Json ToJson(const std::vector<Level>& levels) {
  Json j = Json::object();
  for (const Level& level : levels) j[level.factor] = ToJson(level);
  return j;
}

Json ToJson(const std::optional<BlurSpec>& side) {
  if (!side) return Json();
  if (side->source != BlurSource::kFixed) return Json(ToString(side->source));
  switch (side->unit) {
    case RadiusUnit::kPhotoPx: return ToJson(side->radius);
    case RadiusUnit::kScreenPx: return Json{{"screen_px", ToJson(side->radius)}};
    case RadiusUnit::kArcmin: return Json{{"arcmin", ToJson(side->radius)}};
  }
  return Json();
}

std::string SideText(const std::optional<BlurSpec>& side) {
  return side && side->source != BlurSource::kFixed ? ToString(side->source) : ToJson(side).dump();
}

namespace {

template <typename T>
int Sign(const T& a, const T& b) {
  return a < b ? -1 : b < a ? 1 : 0;
}

}  // namespace

int Compare(const LevelValue& a, const LevelValue& b) {
  if (a.IsNumber() != b.IsNumber()) return a.IsNumber() ? -1 : 1;
  return a.IsNumber() ? Sign(a.number, b.number) : Sign(a.text, b.text);
}

int Compare(const Level& a, const Level& b) {
  if (int c = Sign(a.factor, b.factor)) return c;
  // As JSON types sort: a number, then an object, then text.
  auto rank = [](const Level& l) { return l.object ? 1 : l.value.IsNumber() ? 0 : 2; };
  if (int c = Sign(rank(a), rank(b))) return c;
  if (!a.object) return Compare(a.value, b.value);
  for (size_t i = 0; i < a.fields.size() && i < b.fields.size(); ++i) {
    if (int c = Sign(a.fields[i].first, b.fields[i].first)) return c;
    if (int c = Compare(a.fields[i].second, b.fields[i].second)) return c;
  }
  return Sign(a.fields.size(), b.fields.size());
}

int Compare(const std::vector<Level>& a, const std::vector<Level>& b) {
  for (size_t i = 0; i < a.size() && i < b.size(); ++i)
    if (int c = Compare(a[i], b[i])) return c;
  return Sign(a.size(), b.size());
}

const LevelValue* FindLevel(const std::vector<Level>& levels, const std::string& name) {
  for (const Level& level : levels)
    if (level.factor == name) return level.object ? nullptr : &level.value;
  for (const Level& level : levels)
    if (const LevelValue* v = level.Field(name)) return v;
  return nullptr;
}

}  // namespace blurcue::protocol
