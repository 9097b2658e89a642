#include "protocol/level.h"

#include <gtest/gtest.h>

#include <string>

#include "core/error.h"
#include "protocol/trials.h"

namespace blurcue::protocol {
namespace {

// A label written "007" is text: never the number 7, and written back with its zeros.
TEST(LevelValue, TextWithLeadingZerosStaysText) {
  const LevelValue v = LevelValueOf(Json::parse(R"("007")"));
  EXPECT_EQ(v.kind, LevelValue::Kind::kText);
  EXPECT_FALSE(v.IsNumber());
  EXPECT_EQ(v.text, "007");
  EXPECT_EQ(ToJson(v).dump(), R"("007")");
}

// A number reads back as the same double and is written as the file wrote its kind: 3 stays 3 (not 3.0), 3.0 stays a
// real, 0.1 is the double nearest 0.1, and a whole number beyond 2^53 keeps every digit.
TEST(LevelValue, NumberRoundTripsExactly) {
  for (const char* text : {"3", "-12", "0.1", "2.5", "3.0", "1e-7", "0.30000000000000004", "18446744073709551615"}) {
    const Json written = Json::parse(text);
    const LevelValue v = LevelValueOf(written);
    EXPECT_TRUE(v.IsNumber()) << text;
    EXPECT_EQ(v.kind == LevelValue::Kind::kInteger, written.is_number_integer()) << text;
    EXPECT_EQ(v.number, written.get<double>()) << text;
    EXPECT_EQ(ToJson(v), written) << text;
    EXPECT_EQ(ToJson(v).dump(), written.dump()) << text;
  }
  EXPECT_EQ(LevelValueOf(Json::parse("3")).text, "3");
  EXPECT_EQ(LevelValueOf(Json::parse("3.0")).kind, LevelValue::Kind::kReal);
  EXPECT_EQ(LevelValueOf(Json::parse("0.1")).number, 0.1);
}

TEST(LevelValue, AnythingButANumberOrTextIsRefused) {
  for (const char* text : {"null", "true", "[1]", R"({"a": 1})"}) {
    try {
      LevelValueOf(Json::parse(text));
      FAIL() << text;
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::kInput) << text;
    }
  }
}

// An object level keeps its keys (name order) with their values, the factor's name states its unit, and FindLevel
// finds a factor's own value or an object level's key, as a trial reads them.
TEST(Level, ObjectLevelAndFindLevel) {
  const std::vector<Level> levels = LevelsOf(Json::parse(
      R"({"speed_cm_s": 1.8, "pattern": {"id": "007", "left": "measured", "right": "none", "section": 3}})"));
  ASSERT_EQ(levels.size(), 2u);
  EXPECT_EQ(levels[0].factor, "pattern");
  EXPECT_TRUE(levels[0].object);
  EXPECT_EQ(levels[0].unit, "");
  EXPECT_EQ(levels[1].unit, "cm/s");
  ASSERT_NE(FindLevel(levels, "speed_cm_s"), nullptr);
  EXPECT_EQ(FindLevel(levels, "speed_cm_s")->number, 1.8);
  ASSERT_NE(FindLevel(levels, "section"), nullptr);
  EXPECT_EQ(FindLevel(levels, "section")->kind, LevelValue::Kind::kInteger);
  EXPECT_EQ(FindLevel(levels, "id")->text, "007");
  EXPECT_EQ(FindLevel(levels, "edge"), nullptr);
  EXPECT_EQ(FindLevel(levels, "pattern"), nullptr);  // an object is no value
  EXPECT_EQ(ToJson(levels).dump(),
            R"({"pattern":{"id":"007","left":"measured","right":"none","section":3},"speed_cm_s":1.8})");
}

// Each way a protocol writes a side: a source's word, a radius in photo px (a bare number), on the screen or in
// arcmin; written back exactly. "fixed" is the vocabulary's name for a radius, not a word a protocol may write.
TEST(BlurSpec, EachWayASideIsWrittenRoundTrips) {
  const BlurSpec measured = BlurSpecOf(Json("measured_section"));
  EXPECT_EQ(measured.source, BlurSource::kMeasuredSection);
  const BlurSpec photo = BlurSpecOf(Json::parse("2"));
  EXPECT_EQ(photo.source, BlurSource::kFixed);
  EXPECT_EQ(photo.unit, RadiusUnit::kPhotoPx);
  EXPECT_EQ(photo.radius.number, 2);
  const BlurSpec screen = BlurSpecOf(Json::parse(R"({"screen_px": 0.5})"));
  EXPECT_EQ(screen.unit, RadiusUnit::kScreenPx);
  EXPECT_EQ(screen.radius.number, 0.5);
  const BlurSpec arcmin = BlurSpecOf(Json::parse(R"({"arcmin": 2})"));
  EXPECT_EQ(arcmin.unit, RadiusUnit::kArcmin);
  for (const char* text : {R"("none")", R"("measured")", R"("estimated")", R"("fitted")", "2", "2.0", "0.25",
                           R"({"screen_px":0.5})", R"({"arcmin":2})"})
    EXPECT_EQ(ToJson(std::optional<BlurSpec>(BlurSpecOf(Json::parse(text)))).dump(), text) << text;
  EXPECT_EQ(ToJson(std::optional<BlurSpec>()).dump(), "null");
  EXPECT_EQ(SideText(measured), "measured_section");
  EXPECT_EQ(SideText(screen), R"({"screen_px":0.5})");
  for (const char* text : {R"("fixed")", R"("Measured")", "null", R"({"mm": 1})", "[1]"})
    EXPECT_THROW(BlurSpecOf(Json::parse(text)), Error) << text;
}

// Levels are listed and keyed in the order their JSON sorts (nlohmann's operator<, an implementation that shares no
// code with Compare): by factor, numbers by value before objects before text, objects key by key.
TEST(Level, CompareOrdersAsTheLevelsJsonSorts) {
  const std::vector<Json> written = {
      Json::parse(R"({"edge": 2})"),           Json::parse(R"({"edge": 10})"),
      Json::parse(R"({"edge": 2.5})"),         Json::parse(R"({"edge": "007"})"),
      Json::parse(R"({"edge": "7"})"),         Json::parse(R"({"edge": {"id": 1, "left": "measured"}})"),
      Json::parse(R"({"edge": {"id": 1, "left": "fitted"}})"),
      Json::parse(R"({"edge": {"id": 2}})"),   Json::parse(R"({"edge": {"left": "none"}})"),
      Json::parse(R"({"edge": 2, "speed_cm_s": 1.8})"),
      Json::parse(R"({"edge": 2, "speed_cm_s": 3})"),
      Json::parse(R"({"section": 1})"),        Json::parse(R"({})")};
  for (const Json& a : written)
    for (const Json& b : written) {
      const int sign = a < b ? -1 : b < a ? 1 : 0;
      const int c = Compare(LevelsOf(a), LevelsOf(b));
      EXPECT_EQ((c > 0) - (c < 0), sign) << a.dump() << " vs " << b.dump();
      EXPECT_EQ(LevelsLess()(LevelsOf(a), LevelsOf(b)), a < b) << a.dump() << " vs " << b.dump();
    }
  // 2 and 2.0 are one value in the order (as in JSON), though they are written differently.
  EXPECT_EQ(Compare(LevelsOf(Json::parse(R"({"edge": 2})")), LevelsOf(Json::parse(R"({"edge": 2.0})"))), 0);
}

}  // namespace
}  // namespace blurcue::protocol
