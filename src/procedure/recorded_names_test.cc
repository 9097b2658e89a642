#include "procedure/recorded_names.h"

#include <gtest/gtest.h>

#include <fstream>

#include "core/error.h"
#include "protocol/protocol_test_util.h"

namespace blurcue::procedure {
namespace {

using protocol::test::Contains;
using protocol::test::SceneFolder;
using protocol::test::Valid;

std::vector<std::string> ProblemsOf(const Json& json) {
  const auto file = SceneFolder() / "p.json";
  return RecordedNameProblems(protocol::ParseProtocol(json, file));
}
std::string All(const std::vector<std::string>& problems) {
  std::string all;
  for (const auto& p : problems) all += p + "\n";
  return all;
}

// Object levels named by their ids: a factor of them may have any name (its keys are what is read).
Json Ids(const char* a, const char* b) { return Json::array({{{"id", a}}, {{"id", b}}}); }

// The adversary's case (issue 24): status is a column trials.csv writes itself, so the factor status is recorded as
// factor_status - the column of the factor factor_status. It validated and recorded factor_status as a1/a2 (b1/b2
// stored nowhere). A factor of text levels may no longer be named either (no part of blurcue reads it); a factor of
// object levels may. Refused, naming both factors, the column and the name.
TEST(RecordedNames, AFactorRecordedInAnotherFactorsColumnIsRefusedNamingBoth) {
  Json j = Valid();
  j["blocks"] = {{{"name", "b"},
                  {"factors",
                   {{"pattern", Valid()["blocks"][0]["factors"]["pattern"]},
                    {"edge", {2, 5}},
                    {"status", Ids("a1", "a2")},
                    {"factor_status", Ids("b1", "b2")}}}}};
  const auto problems = ProblemsOf(j);
  ASSERT_EQ(problems.size(), 1u) << All(problems);
  EXPECT_TRUE(Contains(problems[0], "p.json: /blocks/0/factors/status: the factor status is recorded in the column "
                                    "factor_status, as is the factor factor_status (/blocks/0/factors/factor_status)"))
      << problems[0];
  EXPECT_TRUE(Contains(problems[0], "status is a column trials.csv writes itself")) << problems[0];
  EXPECT_TRUE(Contains(problems[0], "got \"status\"")) << problems[0];
  EXPECT_THROW(CheckRecordedNames(protocol::ParseProtocol(j, SceneFolder() / "p.json")), Error);
  // correct and factor_correct: the same.
  j["blocks"][0]["factors"].erase("status");
  j["blocks"][0]["factors"].erase("factor_status");
  j["blocks"][0]["factors"]["correct"] = Ids("0", "1");
  j["blocks"][0]["factors"]["factor_correct"] = Ids("x", "y");
  ASSERT_EQ(ProblemsOf(j).size(), 1u) << All(ProblemsOf(j));
  EXPECT_TRUE(Contains(ProblemsOf(j)[0], "the column factor_correct")) << ProblemsOf(j)[0];
}

// One of them alone is fine: status is recorded as factor_status, factor_status as itself.
TEST(RecordedNames, ANameLikeARecordedColumnAloneHasAColumnOfItsOwn) {
  Json j = Valid();
  j["blocks"][0]["factors"]["status"] = Ids("a1", "a2");
  EXPECT_TRUE(ProblemsOf(j).empty()) << All(ProblemsOf(j));
  j["blocks"][0]["factors"].erase("status");
  j["blocks"][0]["factors"]["factor_status"] = Ids("b1", "b2");
  EXPECT_TRUE(ProblemsOf(j).empty()) << All(ProblemsOf(j));
  EXPECT_TRUE(ProblemsOf(Valid()).empty()) << All(ProblemsOf(Valid()));
}

// A conditions table's header status,factor_status (or correct,factor_correct) cannot reach the record: a table's
// columns are names blurcue reads or labels, so the parser refuses both columns, naming the file, line and column
// (and a label_status beside a label_factor_status are two columns of their own).
TEST(RecordedNames, AConditionsTablesStatusAndFactorStatusAreRefusedAsColumnsNobodyReads) {
  const auto dir = SceneFolder();
  std::ofstream(dir / "recorded-names-status.csv") << "edge,left,right,status,factor_status\n1,measured,none,a1,b1\n"
                                                      "9,estimated,none,a2,b2\n";
  Json j = Valid();
  j["blocks"] = {{{"name", "rows"}, {"conditions", "recorded-names-status.csv"}}};
  try {
    protocol::ParseProtocol(j, dir / "p.json");
    ADD_FAILURE() << "a table with columns status and factor_status was accepted";
  } catch (const Error& e) {
    EXPECT_TRUE(Contains(e.what(), "recorded-names-status.csv line 1, column 4: no part of blurcue reads a column "
                                   "status")) << e.what();
    EXPECT_TRUE(Contains(e.what(), "column 5: no part of blurcue reads a column factor_status")) << e.what();
  }
  std::ofstream(dir / "recorded-names-labels.csv") << "edge,left,right,label_status,label_factor_status\n"
                                                      "1,measured,none,a1,b1\n";
  j["blocks"][0]["conditions"] = "recorded-names-labels.csv";
  EXPECT_TRUE(ProblemsOf(j).empty()) << All(ProblemsOf(j));
}

// A factor and an object level's key of one name in one block: a trial would record one of the two values.
TEST(RecordedNames, AFactorAndALevelsKeyOfOneNameInOneBlockAreRefused) {
  Json j = Valid();
  j["blocks"][0]["factors"]["speed_cm_s"] = {1, 2};  // the pattern's levels give speed_cm_s too
  const auto problems = ProblemsOf(j);
  ASSERT_EQ(problems.size(), 1u) << All(problems);
  EXPECT_TRUE(Contains(problems[0], "/blocks/0/factors/speed_cm_s: the factor speed_cm_s gives speed_cm_s again in a "
                                    "block whose factor pattern's levels give it already"))
      << problems[0];
}

// A factor of object levels is named freely and analysed: side/pair stopped the report (patsy read side / pair).
// Refused naming it; a label's name (recorded, never a term of a model) may hold a '/'.
TEST(RecordedNames, AnAnalysedFactorsNameIsOneAModelFormulaReads) {
  Json j = Valid();
  j["blocks"][0]["factors"]["side/pair"] = Ids("m/e", "e/n");
  auto problems = ProblemsOf(j);
  ASSERT_EQ(problems.size(), 1u) << All(problems);
  EXPECT_TRUE(Contains(problems[0], "/blocks/0/factors/side~1pair: the factor side/pair names a term of the report's "
                                    "models")) << problems[0];
  for (const char* bad : {"2nd", "a b", "a-b"}) {
    Json k = Valid();
    k["blocks"][0]["factors"][bad] = Ids("x", "y");
    EXPECT_EQ(ProblemsOf(k).size(), 1u) << bad;
  }
  for (const char* good : {"side_pair", "Gr\u00f6\u00dfe", "_p2"}) {
    Json k = Valid();
    k["blocks"][0]["factors"][good] = Ids("x", "y");
    EXPECT_TRUE(ProblemsOf(k).empty()) << good << ": " << All(ProblemsOf(k));
  }
  Json k = Valid();
  k["blocks"][0]["factors"]["label_a/b"] = {"p/q", "r/s"};
  EXPECT_TRUE(ProblemsOf(k).empty()) << All(ProblemsOf(k));
}

}  // namespace
}  // namespace blurcue::procedure
