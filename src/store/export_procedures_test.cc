// procedures.csv: each procedure's parameters as the protocol parser reads the recorded text - defaults filled in,
// which the text alone does not say (a QUEST+ guess rate left out is chance, 1/2; a staircase's up/down 1 and 2).
#include "store/export_procedures.h"

#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "core/error.h"
#include "protocol/protocol.h"
#include "store/export.h"
#include "store/record.h"
#include "store/schema.h"
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
  for (const ProcedureColumn* c : CsvColumns(ProcedureColumns()))
    EXPECT_NE(text.str().find("procedures.csv," + c->name + ","), std::string::npos) << c->name;
}

// The kTwoProcedures study whose second block reads a conditions table, as a session records it: the recorded text
// (the table kept beside it) and the protocol the session parsed from the file.
struct WithTable {
  std::string recorded;
  protocol::Protocol parsed;
};
WithTable TwoProceduresWithATable(const std::filesystem::path& dir) {
  std::string text = kTwoProcedures;
  const std::string factors = R"("factors": {"edge": [3, 5]})";
  text.replace(text.find(factors), factors.size(), R"("conditions": "../tables/rows.csv")");
  std::filesystem::create_directories(dir / "protocols");
  std::filesystem::create_directories(dir / "tables");
  std::ofstream(dir / "protocols" / "p.json") << text;
  std::ofstream(dir / "tables" / "rows.csv") << "edge\r\n3\r\n5\r\n";
  WithTable out;
  out.parsed = protocol::LoadProtocol(dir / "protocols" / "p.json", protocol::ValidateOptions{false});
  out.recorded = protocol::RecordedText(text, out.parsed);
  std::filesystem::remove_all(dir / "tables");
  return out;
}

// A staircase over a conditions table: the record keeps the table beside the text (protocol::RecordedText), and the
// export parses the text with it - one row, though the table's file is gone.
TEST(ExportProcedures, AVersionReadingAConditionsTableKeepsItsRow) {
  testing::TempDir dir;
  const std::string recorded = TwoProceduresWithATable(dir.path()).recorded;
  ASSERT_NE(recorded.find("recorded_conditions"), std::string::npos);
  {
    Record record = Record::Open(dir / "r.sqlite");
    record.StartOrResumeSession("two-procedures", "P1", recorded, 7, {}, false);
  }
  ExportCsv(dir / "r.sqlite", dir / "out");
  const std::vector<std::string> lines = Lines(dir / "out" / "procedures.csv");
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_NE(lines[2].find(",1,s,staircase,"), std::string::npos) << lines[2];
}


// The table's rows as one text, in order.
std::string TableRows(Database& db) {
  return db.QueryText("SELECT coalesce(group_concat(r, '\n'), '') FROM (SELECT protocol_version_id || '|' || block || "
                      "'|' || block_name || '|' || procedure || '|' || variable || '|' || trials || '|' || guess || "
                      "'|' || parameters AS r FROM procedures ORDER BY protocol_version_id, block)");
}

// A session records the procedures it was given (as the runner gives them, parsed) when its protocol version is first
// recorded, and export writes procedures.csv from them: parameters no parse of the text would give (a marker start)
// are what the file shows, so nothing was parsed again. A later session of the version keeps the first one's rows.
TEST(ProceduresTable, WrittenWhenAVersionIsFirstRecordedFromTheProceduresGiven) {
  testing::TempDir dir;
  SessionMeta meta;
  std::vector<ProcedureRecord> given = ProcedureRecords(
      protocol::ParseProtocol(ParseJson(kTwoProcedures, "p"), "p.json", protocol::ValidateOptions{false}).blocks);
  ASSERT_EQ(given.size(), 2u);
  auto marked = [&](double start) {
    Json p = ParseJson(given[1].parameters, "p");
    p["start"] = start;
    given[1].parameters = p.dump();
    return given;
  };
  meta.procedures = marked(0.777);
  {
    Record record = Record::Open(dir / "r.sqlite");
    const int64_t session =
        record.StartOrResumeSession("two-procedures", "P1", kTwoProcedures, 7, meta, false).session_id;
    record.FinishSession(session, SessionStatus::kCompleted);
    meta.procedures = marked(0.888);
    record.StartOrResumeSession("two-procedures", "P2", kTwoProcedures, 8, meta, false);
    EXPECT_NE(TableRows(record.database()).find(R"("start":0.777)"), std::string::npos);
    EXPECT_EQ(TableRows(record.database()).find(R"("start":0.888)"), std::string::npos);
  }
  ExportCsv(dir / "r.sqlite", dir / "out");
  const std::vector<std::string> lines = Lines(dir / "out" / "procedures.csv");
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_NE(lines[2].find(R"(""start"":0.777)"), std::string::npos) << lines[2];
}

// The table as a reader trusts it (CheckProcedures): a hand-edited row - its JSON broken, a parameter of the wrong type
// or missing, a word not of the vocabulary, a row of no protocol version, a guess no rate - is refused by export and
// merge with one line naming the record, the row and the field (it exported, merged or crashed the report before);
// two inputs that recorded one version's parameters differently are refused by merge (it kept the first silently).
TEST(ProceduresTable, AHandEditedRowIsRefusedByExportAndMerge) {
  testing::TempDir dir;
  {
    Record record = Record::Open(dir / "r.sqlite");
    record.StartOrResumeSession("two-procedures", "P1", kTwoProcedures, 7, {}, false);
  }
  const std::vector<std::pair<std::string, std::string>> edits = {
      {"UPDATE procedures SET parameters = '{not json' WHERE block = 1", "parameters '{not json': not JSON"},
      {"UPDATE procedures SET parameters = json_set(parameters, '$.steps', 'x') WHERE block = 1",
       "parameters.steps: '\"x\"': not a list of positive numbers"},
      {"UPDATE procedures SET parameters = json_set(parameters, '$.up', json('[1]')) WHERE block = 1",
       "parameters.up: '[1]': not a whole number >= 1"},
      {"UPDATE procedures SET parameters = json_remove(parameters, '$.down') WHERE block = 1",
       "parameters.down: missing"},
      {"UPDATE procedures SET parameters = json_set(parameters, '$.thresholds', 'half') WHERE block = 0",
       "parameters.thresholds: '\"half\"': not a list of numbers"},
      {"UPDATE procedures SET parameters = json_set(parameters, '$.start', 5) WHERE block = 1",
       "parameters.start 5: not within [min, max] = [0.02, 2]"},
      {"UPDATE procedures SET procedure = 'bogus' WHERE block = 1", "procedure 'bogus': not one of"},
      {"UPDATE procedures SET procedure = 'quest_plus' WHERE block = 1",
       "parameters.procedure: not the row's procedure 'quest_plus'"},
      {"UPDATE procedures SET guess = 5, parameters = json_set(parameters, '$.guess', 5) WHERE block = 1",
       "guess 5: not a rate in [0, 1)"},
      {"UPDATE procedures SET block = -1 WHERE block = 1", "block -1: not a block's index"},
      {"UPDATE procedures SET protocol_version_id = 99 WHERE block = 1", "(protocol version 99, block 1): no such"},
  };
  for (const auto& [sql, message] : edits) {
    const std::filesystem::path edited = dir / "edited.sqlite";
    std::filesystem::copy_file(dir / "r.sqlite", edited, std::filesystem::copy_options::overwrite_existing);
    {
      Database db(edited);
      db.Exec("PRAGMA ignore_check_constraints = ON; PRAGMA foreign_keys = OFF; " + sql);
    }
    for (const bool merge : {false, true}) {
      std::filesystem::remove_all(dir / "out");
      std::filesystem::remove(dir / "merged.sqlite");
      try {
        if (merge)
          MergeDatabases({edited}, dir / "merged.sqlite");
        else
          ExportCsv(edited, dir / "out");
        ADD_FAILURE() << (merge ? "merged: " : "exported: ") << sql;
      } catch (const Error& e) {
        EXPECT_EQ(e.kind(), ErrorKind::kInput) << sql;
        EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << sql << "\n" << e.what();
        EXPECT_NE(std::string(e.what()).find("edited.sqlite"), std::string::npos) << e.what();
      }
      EXPECT_FALSE(std::filesystem::exists(dir / "merged.sqlite")) << sql;
    }
  }
  // One version, two stations, its start changed in one to another valid value: merge refuses, in either order.
  std::filesystem::copy_file(dir / "r.sqlite", dir / "other.sqlite");
  {
    Database db(dir / "other.sqlite");
    db.Exec("UPDATE procedures SET parameters = json_set(parameters, '$.start', 1.5) WHERE block = 1");
  }
  for (const bool swapped : {false, true}) {
    std::filesystem::remove(dir / "merged.sqlite");
    const std::vector<std::filesystem::path> inputs =
        swapped ? std::vector<std::filesystem::path>{dir / "other.sqlite", dir / "r.sqlite"}
                : std::vector<std::filesystem::path>{dir / "r.sqlite", dir / "other.sqlite"};
    try {
      MergeDatabases(inputs, dir / "merged.sqlite");
      ADD_FAILURE() << "merged two records that recorded one version's parameters differently";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::kInput);
      EXPECT_NE(std::string(e.what()).find("its parameters differ from those an earlier input recorded"),
                std::string::npos) << e.what();
    }
  }
}

// What the runner records (ProcedureRecords of the blocks it parsed from the file, conditions table read from disk)
// equals what a recorded text gives when parsed with its recorded tables in memory (RecordedProcedures: how a record
// of before the table gets its rows) - the two ways the table is filled agree, and the second reads no file.
TEST(ProceduresTable, TheParsedBlocksAndTheRecordedTextGiveTheSameRows) {
  testing::TempDir dir;
  const WithTable study = TwoProceduresWithATable(dir.path());
  const std::vector<ProcedureRecord> parsed = ProcedureRecords(study.parsed.blocks);
  const std::vector<ProcedureRecord> recorded = RecordedProcedures(study.recorded);
  ASSERT_EQ(parsed.size(), 2u);
  ASSERT_EQ(recorded.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(recorded[i].block, parsed[i].block);
    EXPECT_EQ(recorded[i].block_name, parsed[i].block_name);
    EXPECT_EQ(recorded[i].procedure, parsed[i].procedure);
    EXPECT_EQ(recorded[i].parameters, parsed[i].parameters);
  }
  EXPECT_EQ(parsed[1].parameters.rfind(R"({"down":2,)", 0), 0u) << parsed[1].parameters;
  EXPECT_EQ(parsed[0].guess, 0.5);
  // The table the text names, missing from what it recorded: no rows (the parser refuses), not a read of the disk.
  Json without = ParseJson(study.recorded, "recorded");
  without["recorded_conditions"] = Json::object();
  EXPECT_TRUE(RecordedProcedures(without.dump()).empty());
}

// A record of schema 9 (no procedures table) holding the kTwoProcedures text with its conditions table: export (a
// migrated copy in memory) gives procedures.csv as export parsed it before the table, and a writer that opens it
// migrates it in place, its rows derived from the recorded text.
TEST(ProceduresTable, ARecordOfSchemaNineGetsItsRowsFromItsRecordedTexts) {
  testing::TempDir dir;
  const WithTable study = TwoProceduresWithATable(dir.path());
  {
    Database db(dir / "old.sqlite");
    for (int i = 0; i < 9; ++i) {
      const Migration& step = Migrations()[size_t(i)];
      if (!step.sql.empty()) db.Exec(step.sql);
      if (step.data) step.data(db);
    }
    db.Exec("PRAGMA user_version = 9; PRAGMA application_id = " + std::to_string(kApplicationId));
    const std::string canonical = CanonicalProtocolText(study.recorded);
    Statement insert(db, "INSERT INTO protocol_versions (study_id, json, hash, created, version) VALUES (1, ?, ?, "
                         "'now', 1)");
    db.Exec("INSERT INTO studies (name, created) VALUES ('two-procedures', 'now')");
    insert.Bind(1, canonical);
    insert.Bind(2, ProtocolHash(canonical));
    insert.Run();
    EXPECT_EQ(db.QueryInt64("SELECT count(*) FROM sqlite_schema WHERE name = 'procedures'"), 0);
  }
  ExportCsv(dir / "old.sqlite", dir / "out");
  const std::vector<std::string> lines = Lines(dir / "out" / "procedures.csv");
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_NE(lines[1].find(",0,q,quest_plus,"), std::string::npos) << lines[1];
  EXPECT_NE(lines[1].find(R"(""guess"":0.5)"), std::string::npos) << lines[1];
  EXPECT_NE(lines[2].find(",1,s,staircase,"), std::string::npos) << lines[2];
  EXPECT_NE(lines[2].find(R"(""steps"":[0.2,0.1])"), std::string::npos) << lines[2];
  // Merged as it is (merge reads its inputs unmigrated): the merged record derives them as the migration would.
  MergeDatabases({dir / "old.sqlite"}, dir / "merged.sqlite");
  EXPECT_EQ(Database(dir / "merged.sqlite", OpenMode::kReadOnly).QueryInt64("SELECT count(*) FROM procedures"), 2);
  Record record = Record::Open(dir / "old.sqlite");
  EXPECT_EQ(SchemaVersion(record.database()), CurrentSchemaVersion());
  EXPECT_EQ(record.database().QueryText("SELECT group_concat(block || ':' || procedure || ':' || trials, ',') FROM "
                                        "(SELECT * FROM procedures ORDER BY block)"),
            "0:quest_plus:4,1:staircase:3");
}

// Merge copies the procedures of every input, once per protocol version (the first input's), with the versions' new
// ids; an input of schema 9 gets them from its texts.
TEST(ProceduresTable, MergeCopiesEachVersionsRowsOnce) {
  testing::TempDir dir;
  for (const char* name : {"a", "b"}) {
    Record record = Record::Open(dir / (std::string(name) + ".sqlite"));
    // A version only b records first gives b's study its own id in the merged record.
    if (std::string(name) == "b") record.StartOrResumeSession("other", "Q1", R"({"name": "other"})", 3, {}, false);
    const int64_t session =
        record.StartOrResumeSession("two-procedures", std::string("P") + name, kTwoProcedures, 7, {}, false).session_id;
    record.FinishSession(session, SessionStatus::kCompleted);
  }
  MergeDatabases({dir / "a.sqlite", dir / "b.sqlite"}, dir / "merged.sqlite");
  Database merged(dir / "merged.sqlite", OpenMode::kReadOnly);
  EXPECT_EQ(merged.QueryInt64("SELECT count(*) FROM procedures"), 2);
  EXPECT_EQ(merged.QueryText("SELECT group_concat(st.name || ':' || pr.block || ':' || pr.procedure, ',') FROM "
                             "procedures pr JOIN protocol_versions pv ON pv.id = pr.protocol_version_id JOIN studies "
                             "st ON st.id = pv.study_id"),
            "two-procedures:0:quest_plus,two-procedures:1:staircase");
  Database a(dir / "a.sqlite", OpenMode::kReadOnly);
  EXPECT_EQ(merged.QueryText("SELECT group_concat(parameters, '|') FROM procedures"),
            a.QueryText("SELECT group_concat(parameters, '|') FROM procedures"));
}

}  // namespace
}  // namespace blurcue::store
