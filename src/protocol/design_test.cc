#include "protocol/design.h"

#include <gtest/gtest.h>

namespace blurcue::protocol {
namespace {

Factor Levels(const std::string& name, const std::vector<Json>& levels) {
  Factor f{name, {}};
  for (const Json& level : levels) f.levels.push_back(LevelOf(name, level));
  return f;
}

// A protocol with a crossed block (edge 10, 2, 6 in file order; a pattern of objects), a staircase block split by
// speed, groups, participant information and a rating block.
Protocol Sample() {
  Protocol p;
  p.name = "s";
  Block main;
  main.name = "main";
  main.factors = {Levels("edge", {10, 2, 6}),
                  Levels("pattern", {Json{{"id", "fast"}, {"speed_cm_s", 3}, {"left", "measured"}},
                                     Json{{"id", "slow"}, {"speed_cm_s", 1.8}, {"left", "none"}}})};
  Block stair;
  stair.name = "stair";
  stair.factors = {Levels("speed_cm_s", {3, 1.8})};
  stair.procedure.emplace();
  stair.procedure->min = 0, stair.procedure->max = 2.5;
  Block rate;
  rate.name = "rate";
  rate.task = Task::kRating;
  p.blocks = {main, stair, rate};
  p.responses.rating = {"1", "2", "3", "4", "5"};
  p.groups = Groups{{"near", "far"}, GroupAssign::kBalanced};
  InfoField age;
  age.key = "age";
  age.type = InfoType::kInteger;
  age.min = 18, age.max = 99;
  InfoField hand;
  hand.key = "hand";
  hand.type = InfoType::kChoice;
  hand.choices = {"left", "right"};
  p.participant_info = {age, hand};
  return p;
}

std::string Describe(const DesignColumn& c) {
  std::string text = c.name + " " + ToString(c.role) + " " + ToString(c.type) + " [" + c.unit + "]";
  for (double v : c.numbers) text += " " + LevelText(v);
  for (const std::string& v : c.names) text += " '" + v + "'";
  if (c.min) text += " from " + LevelText(*c.min);
  if (c.max) text += " to " + LevelText(*c.max);
  return text;
}

TEST(DescribeDesign, EveryColumnWithItsRoleAndTheValuesTheProtocolAllows) {
  std::vector<std::string> got;
  for (const DesignColumn& c : DescribeDesign(Sample())) got.push_back(Describe(c));
  EXPECT_EQ(got, (std::vector<std::string>{
                     "edge within integer [] 2 6 10",  // numeric order, not the file's nor the text's (10 < 2)
                     "pattern within string [] 'fast' 'slow'",
                     "id label string [] 'fast' 'slow'",  // the pattern's id: trials.csv has it as a column
                     // varied by main's pattern too, but a procedure's cell in stair: its own track
                     "speed_cm_s procedure_cell number [cm/s] 1.8 3",
                     "level within number [] from 0 to 2.5",
                     "rating label integer [] from 1 to 5",
                     "group group string [] 'near' 'far'",
                     "info_age label integer [] from 18 to 99",
                     "info_hand label string [] 'left' 'right'",
                     "practice practice boolean [] 0 1",
                 }));
}

TEST(DescribeDesign, LevelsOfTheDesignAreMarkedForTheRecordsNaming) {
  for (const DesignColumn& c : DescribeDesign(Sample()))
    EXPECT_EQ(c.level, c.name == "edge" || c.name == "pattern" || c.name == "id" || c.name == "speed_cm_s") << c.name;
}

TEST(DescribeDesign, ConditionsRowIsNoColumnButItsColumnsAre) {
  Protocol p;
  Block b;
  b.factors = {Levels("row", {Json{{"edge", 3}, {"label", "a"}}, Json{{"edge", 1}, {"label", "b"}}})};
  p.blocks = {b};
  std::vector<std::string> got;
  for (const DesignColumn& c : DescribeDesign(p)) got.push_back(Describe(c));
  EXPECT_EQ(got, (std::vector<std::string>{"edge within integer [] 1 3", "label label string [] 'a' 'b'",
                                           "practice practice boolean [] 0 1"}));
}

// A label factor or column (label, label_*) has the role label, not within (it varies nothing); one mixing numbers
// and text allows each number as trials.csv writes it: 1, not 1.0.
TEST(DescribeDesign, LabelsAreLabelsAndMixedLevelsAreWrittenAsTrialsCsvHoldsThem) {
  Protocol p;
  Block b;
  b.factors = {Levels("edge", {2}), Levels("label_x", {1, "a", 2.5}), Levels("label_", {"x"})};
  p.blocks = {b};
  std::vector<std::string> got;
  for (const DesignColumn& c : DescribeDesign(p)) got.push_back(Describe(c));
  EXPECT_EQ(got, (std::vector<std::string>{"edge within integer [] 2", "label_x label string [] 'a' '1' '2.5'",
                                           "label_ label string [] 'x'", "practice practice boolean [] 0 1"}));
}

TEST(CellLevels, AProcedureTrialNamesItsCellByItsLevels) {
  const Protocol p = Sample();
  Trial trial;
  trial.block = "stair";
  trial.cell = 1;
  trial.levels = LevelsOf(Json{{"speed_cm_s", 1.8}});
  EXPECT_EQ(CellLevels(p, trial), "speed_cm_s=1.8");
  Trial plain;
  plain.block = "main";
  plain.levels = LevelsOf(Json{{"edge", 9}});
  EXPECT_EQ(CellLevels(p, plain), "");
}

}  // namespace
}  // namespace blurcue::protocol
