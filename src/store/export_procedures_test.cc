// procedures.csv: each procedure's parameters as the protocol parser reads the recorded text - defaults filled in,
// which the text alone does not say (a QUEST+ guess rate left out is chance, 1/2; a staircase's up/down 1 and 2).
#include "store/export_procedures.h"

#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "protocol/protocol.h"
#include "store/export.h"
#include "store/record.h"
#include "store/test_util.h"

namespace blurcue::store {
namespace {

constexpr const char* kTwoProcedures = R"({"name": "two-procedures", "version": 1,
 "scene": {"background": "scene.png", "calib": "calib.json"}, "content": {"type": "grid"}, "task": "forced_choice",
 "blocks": [
  {"name": "q", "factors": {"edge": [9]},
   "procedure": {"type": "quest_plus", "variable": "difference_arcmin", "reference": "measured", "trials": 4,
                 "stimuli": [0.5, 1, 2], "threshold": [0.5, 1, 2], "slope": [1, 3], "lapse": [0.02]}},
  {"name": "s", "factors": {"edge": [3, 5]},
   "procedure": {"type": "staircase", "variable": "relative_difference", "reference": "measured", "trials": 3,
                 "start": 0.5, "min": 0.02, "max": 2, "steps": [0.2, 0.1]}}],
 "responses": {"left": "Left", "right": "Right", "cant_tell": null}})";

std::vector<std::string> Lines(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line.substr(0, line.find_last_not_of('\r') + 1));
  return lines;
}

TEST(ExportProcedures, OneRowPerProcedureBlockWithTheParsersDefaults) {
  testing::TempDir dir;
  {
    Record record = Record::Open(dir / "r.sqlite");
    const int64_t session = record.StartOrResumeSession("two-procedures", "P1", kTwoProcedures, 7, {}, false).session_id;
    record.SaveTrialList(session, {});
    record.FinishSession(session, SessionStatus::kCompleted);
    // A text the parser refuses (an older blurcue's, say) gives no rows rather than stopping the export.
    record.StartOrResumeSession("old-study", "P1", R"({"study":"old-study"})", 8, {}, false);
  }
  ExportCsv(dir / "r.sqlite", dir / "out");
  const std::vector<std::string> lines = Lines(dir / "out" / "procedures.csv");
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0], "study,protocol_hash,block,block_name,procedure,parameters");
  EXPECT_EQ(lines[1].rfind("two-procedures,", 0), 0u) << lines[1];
  EXPECT_NE(lines[1].find(",0,q,quest_plus,"), std::string::npos) << lines[1];
  EXPECT_NE(lines[1].find(R"(""guess"":0.5)"), std::string::npos) << lines[1];  // not in the text: chance
  EXPECT_NE(lines[1].find(R"(""thresholds"":[0.5,1.0,2.0])"), std::string::npos) << lines[1];
  EXPECT_NE(lines[1].find(R"(""slopes"":[1.0,3.0])"), std::string::npos) << lines[1];
  EXPECT_NE(lines[2].find(",1,s,staircase,"), std::string::npos) << lines[2];
  EXPECT_NE(lines[2].find(R"(""up"":1)"), std::string::npos) << lines[2];  // not in the text: 1-up/2-down
  EXPECT_NE(lines[2].find(R"(""down"":2)"), std::string::npos) << lines[2];
  EXPECT_NE(lines[2].find(R"(""steps"":[0.2,0.1])"), std::string::npos) << lines[2];
  // The codebook names every column of it.
  std::ifstream codebook(dir / "out" / "codebook.csv");
  std::stringstream text;
  text << codebook.rdbuf();
  for (const auto& c : ProcedureColumns())
    EXPECT_NE(text.str().find("procedures.csv," + c.name + ","), std::string::npos) << c.name;
}

// A staircase over a conditions table: the record keeps the table beside the text (protocol::RecordedText), and the
// export parses the text with it - one row, though the table's file is gone.
TEST(ExportProcedures, AVersionReadingAConditionsTableKeepsItsRow) {
  testing::TempDir dir;
  std::string text = kTwoProcedures;
  const std::string factors = R"("factors": {"edge": [3, 5]})";
  text.replace(text.find(factors), factors.size(), R"("conditions": "../tables/rows.csv")");
  std::filesystem::create_directories(dir / "protocols");
  std::filesystem::create_directories(dir / "tables");
  std::ofstream(dir / "protocols" / "p.json") << text;
  std::ofstream(dir / "tables" / "rows.csv") << "edge\r\n3\r\n5\r\n";
  const protocol::Protocol parsed = protocol::LoadProtocol(dir / "protocols" / "p.json", protocol::ValidateOptions{false});
  const std::string recorded = protocol::RecordedText(text, parsed);
  ASSERT_NE(recorded.find("recorded_conditions"), std::string::npos);
  std::filesystem::remove_all(dir / "tables");
  {
    Record record = Record::Open(dir / "r.sqlite");
    record.StartOrResumeSession("two-procedures", "P1", recorded, 7, {}, false);
  }
  ExportCsv(dir / "r.sqlite", dir / "out");
  const std::vector<std::string> lines = Lines(dir / "out" / "procedures.csv");
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_NE(lines[2].find(",1,s,staircase,"), std::string::npos) << lines[2];
}

}  // namespace
}  // namespace blurcue::store
