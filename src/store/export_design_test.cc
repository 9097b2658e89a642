// trials.csv and its codebook from the record's design (schema 8): session numbers, protocol versions, procedure
// cells, and each design column's role and the values the protocol allows.
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "store/export.h"
#include "store/record.h"
#include "store/test_util.h"

namespace blurcue::store {
namespace {

// A CSV without quoted fields, by header name.
std::vector<std::map<std::string, std::string>> Read(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string line;
  std::vector<std::string> header;
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::vector<std::string> cells;
    std::stringstream cells_in(line);
    for (std::string cell; std::getline(cells_in, cell, ',');) cells.push_back(cell);
    if (!line.empty() && line.back() == ',') cells.push_back("");
    if (header.empty()) {
      header = cells;
      continue;
    }
    std::map<std::string, std::string> row;
    for (size_t i = 0; i < header.size() && i < cells.size(); ++i) row[header[i]] = cells[i];
    rows.push_back(row);
  }
  return rows;
}

// The codebook's row of trials.csv's `column`.
std::map<std::string, std::string> Book(const std::filesystem::path& dir, const std::string& column) {
  for (const auto& row : Read(dir / "codebook.csv"))
    if (row.at("table") == "trials.csv" && row.at("column") == column) return row;
  return {};
}

void Session(Record& record, const std::string& participant, uint64_t seed, const SessionMeta& meta,
             const std::vector<std::pair<std::string, std::string>>& trials) {
  const int64_t session =
      record.StartOrResumeSession("s", participant, R"({"version":)" + std::to_string(meta.protocol_version) + "}",
                                  seed, meta, false).session_id;
  std::vector<TrialRecord> list;
  for (const auto& [factors, cell] : trials) {
    TrialRecord t;
    t.index = int64_t(list.size());
    t.factors_json = factors;
    t.cell = cell;
    list.push_back(t);
  }
  record.SaveTrialList(session, list);
  record.FinishSession(session, SessionStatus::kCompleted);
}

TEST(Export, CodebookGivesEachDesignColumnItsRoleAndTheProtocolsValuesNotTheValuesSeen) {
  testing::TempDir dir;
  {
    Record record = Record::Open(dir / "r.sqlite");
    SessionMeta meta;
    meta.design = {{"edge", "procedure_cell", "integer", "", {2, 6, 10}, {}, {}, {}},
                   {"blur", "within", "string", "", {}, {"measured", "none"}, {}, {}},
                   {"practice", "practice", "boolean", "", {0, 1}, {}, {}, {}}};
    Session(record, "P1", 1, meta, {{R"({"edge":6,"blur":"none"})", "edge=6"}, {R"({"edge":10,"blur":"none"})", "edge=10"}});
    Session(record, "P1", 2, meta, {{R"({"edge":2,"blur":"none"})", "edge=2"}});
  }
  ExportCsv(dir / "r.sqlite", dir / "out");
  std::vector<std::string> got;
  for (const auto& row : Read(dir / "out" / "trials.csv"))
    got.push_back(row.at("session_number") + " v" + row.at("protocol_version") + " " + row.at("cell"));
  EXPECT_EQ(got, (std::vector<std::string>{"1 v1 edge=6", "1 v1 edge=10", "2 v1 edge=2"}));
  // 2|6|10 in numeric order (as text 10 sorts first), though 2 and 10 were seen in one session each.
  EXPECT_EQ(Book(dir / "out", "edge")["allowed"], "2|6|10");
  EXPECT_EQ(Book(dir / "out", "edge")["role"], "procedure_cell");
  EXPECT_EQ(Book(dir / "out", "blur")["allowed"], "measured|none");  // measured never shown
  EXPECT_EQ(Book(dir / "out", "practice")["role"], "practice");
  EXPECT_EQ(Book(dir / "out", "rt_ms")["role"], "");  // not a design's column
}

TEST(Export, VersionsOfAStudyGiveTheirValuesTogetherInNumericOrder) {
  testing::TempDir dir;
  {
    Record record = Record::Open(dir / "r.sqlite");
    SessionMeta v1, v2;
    v1.design = {{"edge", "within", "integer", "", {3, 9}, {}, {}, {}}};
    v2.protocol_version = 2;
    v2.design = {{"edge", "within", "integer", "", {1, 10}, {}, {}, {}}};
    Session(record, "P1", 1, v1, {{R"({"edge":3})", ""}});
    Session(record, "P2", 2, v2, {{R"({"edge":10})", ""}});
  }
  ExportCsv(dir / "r.sqlite", dir / "out");
  EXPECT_EQ(Book(dir / "out", "edge")["allowed"], "1|3|9|10");
  std::vector<std::string> versions;
  for (const auto& row : Read(dir / "out" / "trials.csv")) versions.push_back(row.at("protocol_version"));
  EXPECT_EQ(versions, (std::vector<std::string>{"1", "2"}));
}

// A record made before designs were recorded keeps the values seen, and its codebook says so.
TEST(Export, RecordWithoutADesignKeepsTheValuesSeenAndSaysSo) {
  testing::TempDir dir;
  {
    Record record = Record::Open(dir / "r.sqlite");
    Session(record, "P1", 1, {}, {{R"({"edge":10})", ""}, {R"({"edge":2})", ""}});
  }
  ExportCsv(dir / "r.sqlite", dir / "out");
  const auto edge = Book(dir / "out", "edge");
  EXPECT_EQ(edge.at("allowed"), "10|2");  // as before: the values seen, as text
  EXPECT_EQ(edge.at("role"), "");
  EXPECT_NE(edge.at("meaning").find("allowed: the values seen (the record holds sessions from before designs were "
                                    "recorded)"),
            std::string::npos)
      << edge.at("meaning");
}

// The codebook gives a design column the unit its protocol versions give it: a factor speed_cm_s in cm/s, a
// difference_arcmin procedure's level in arcmin, a relative_difference one's (the design's empty unit) as ratio - 1;
// versions that disagree keep the table's words.
TEST(Export, CodebookGivesTheDesignsUnitsAndTheProceduresLevelItsUnit) {
  for (const auto& [units, expect] :
       std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"arcmin"}, "arcmin"},
           {{""}, "ratio - 1 (relative_difference: the test side's radius / the reference's - 1)"},
           {{"arcmin", ""}, "the procedure's variable"}}) {
    testing::TempDir dir;
    {
      Record record = Record::Open(dir / "r.sqlite");
      for (size_t v = 0; v < units.size(); ++v) {
        SessionMeta meta;
        meta.protocol_version = int64_t(v + 1);
        meta.design = {{"speed_cm_s", "within", "number", "cm/s", {1.8, 3}, {}, {}, {}},
                       {"level", "within", "number", units[v], {0.1, 0.2}, {}, {}, {}}};
        Session(record, "P" + std::to_string(v), v + 1, meta, {{R"({"speed_cm_s":3,"level":0.2})", ""}});
      }
    }
    ASSERT_EQ(ExportCsv(dir / "r.sqlite", dir / "out"), int64_t(units.size()));
    EXPECT_EQ(Book(dir / "out", "speed_cm_s")["unit"], "cm/s");
    EXPECT_EQ(Book(dir / "out", "level")["unit"], expect);
  }
}

}  // namespace
}  // namespace blurcue::store
