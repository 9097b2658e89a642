// Sessions numbered per participant, seeds of their own, protocol versions kept apart and the design recorded
// (schema 8): the record's side, on :memory: and on real files.
#include <chrono>
#include <functional>
#include <map>
#include <utility>
#include <thread>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "store/export.h"
#include "store/record.h"
#include "store/schema.h"
#include "store/test_util.h"

namespace blurcue::store {
namespace {

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

const char* kV1 = R"({"name":"s","timing":{"stimulus_ms":1500},"version":1})";

SessionMeta Version(int64_t version) {
  SessionMeta meta;
  meta.protocol_version = version;
  return meta;
}

// Starts, saves one trial and completes a session; returns its start.
SessionStart Complete(Record& record, const std::string& participant, const std::string& protocol, uint64_t seed,
                      const SessionMeta& meta = {}) {
  const SessionStart start = record.StartOrResumeSession("s", participant, protocol, seed, meta, false);
  TrialRecord trial;
  record.SaveTrialList(start.session_id, {trial});
  record.FinishSession(start.session_id, SessionStatus::kCompleted);
  return start;
}

MergeOptions SamePerson(std::vector<std::string> codes) {
  MergeOptions options;
  options.same_person = std::move(codes);
  return options;
}

TEST(Record, AgainSessionGetsNextNumberAndANewSeed) {
  Record record = Record::Open(":memory:");
  EXPECT_EQ(Complete(record, "P1", kV1, 11).session_number, 1);
  EXPECT_EQ(Complete(record, "P2", kV1, 21).session_number, 1);  // numbered per participant
  const SessionStart second = Complete(record, "P1", kV1, 12);
  EXPECT_EQ(second.session_number, 2);
  EXPECT_EQ(record.database().QueryText("SELECT group_concat(session_number || ':' || seed, ',') FROM "
                                        "(SELECT * FROM sessions ORDER BY id)"),
            "1:11,1:21,2:12");
}

TEST(Record, ResumedSessionKeepsItsNumber) {
  Record record = Record::Open(":memory:");
  Complete(record, "P1", kV1, 11);
  const SessionStart running = record.StartOrResumeSession("s", "P1", kV1, 12, {}, false);
  const SessionStart resumed = record.StartOrResumeSession("s", "P1", kV1, 12, {}, true);
  EXPECT_TRUE(resumed.resumed);
  EXPECT_EQ(running.session_number, 2);
  EXPECT_EQ(resumed.session_number, 2);
}

TEST(Record, GivenSeedOfAnEarlierSessionIsRefusedSayingWhyAndWhatToDo) {
  Record record = Record::Open(":memory:");
  Complete(record, "P1", kV1, 11);
  SessionMeta given;
  given.seed_given = true;
  EXPECT_EQ(ErrorOf([&] { record.StartOrResumeSession("s", "P1", kV1, 11, given, false); }),
            ":memory:: --seed 11 is the seed of participant P1 of study s's session number 1 (session 1): a session "
            "with it repeats that session's trial order; leave out --seed (each session number gets a seed of its "
            "own) or give another");
  EXPECT_EQ(record.database().QueryInt64("SELECT count(*) FROM sessions"), 1);
  // Another participant may have that seed: only a participant's own sessions are copies of each other.
  EXPECT_EQ(record.StartOrResumeSession("s", "P2", kV1, 11, given, false).session_number, 1);
}

TEST(Record, SeedDerivedForAnotherSessionNumberIsRefused) {
  Record record = Record::Open(":memory:");
  Complete(record, "P1", kV1, 11);
  SessionMeta meta;
  meta.seed_for_number = 1;  // prepared before the first session was recorded
  EXPECT_NE(ErrorOf([&] { record.StartOrResumeSession("s", "P1", kV1, 99, meta, false); })
                .find("was prepared as session number 1 with its seed, but the record now gives it number 2"),
            std::string::npos);
  meta.seed_for_number = 2;
  EXPECT_EQ(record.StartOrResumeSession("s", "P1", kV1, 99, meta, false).session_number, 2);
}

TEST(Record, PeekSaysTheNextSessionNumberAndTheRunningSessionsSeedWithoutWriting) {
  testing::TempDir dir;
  EXPECT_EQ(PeekSessions(dir / "none.sqlite", "s", "P1").next_number, 1);
  {
    Record record = Record::Open(dir / "r.sqlite");
    Complete(record, "P1", kV1, 11);
    record.StartOrResumeSession("s", "P1", kV1, 12, {}, false);
  }
  const SessionsSoFar p1 = PeekSessions(dir / "r.sqlite", "s", "P1");
  EXPECT_EQ(p1.next_number, 3);
  EXPECT_TRUE(p1.unfinished);
  EXPECT_EQ(p1.unfinished_seed, 12u);
  EXPECT_EQ(p1.unfinished_number, 2);
  EXPECT_EQ(PeekSessions(dir / "r.sqlite", "s", "P2").next_number, 1);
  EXPECT_FALSE(PeekSessions(dir / "r.sqlite", "other", "P1").unfinished);
}

TEST(Record, ChangedProtocolUnderTheSameVersionIsRefusedNamingTheFirstDifference) {
  testing::TempDir dir;
  Record record = Record::Open(dir / "r.sqlite");
  Complete(record, "P1", kV1, 11, Version(1));
  const std::string changed = R"({"name":"s","timing":{"stimulus_ms":300},"version":1})";
  EXPECT_EQ(ErrorOf([&] { record.StartOrResumeSession("s", "P2", changed, 21, Version(1), false); }),
            (dir / "r.sqlite").string() + ": study s records protocol version 1 with another text "
            "(/timing/stimulus_ms: 1500 in the record, 300 now); raise \"version\" to 2 to record it as a new "
            "version, or use another record (--db)");
  EXPECT_EQ(record.database().QueryInt64("SELECT count(*) FROM protocol_versions"), 1);
  EXPECT_EQ(record.database().QueryInt64("SELECT count(*) FROM participants"), 1);  // rolled back: P2 not added
  // The same text reformatted is the same protocol: fine, as before.
  EXPECT_EQ(record.StartOrResumeSession("s", "P2", R"({ "version": 1, "timing": {"stimulus_ms": 1500}, "name": "s" })",
                                        21, Version(1), false).session_number, 1);
}

TEST(Record, RaisedVersionIsRecordedBesideTheFirstAndEachSessionSaysWhichItRan) {
  Record record = Record::Open(":memory:");
  Complete(record, "P1", kV1, 11, Version(1));
  const std::string v2 = R"({"name":"s","timing":{"stimulus_ms":300},"version":2})";
  Complete(record, "P2", v2, 21, Version(2));
  Complete(record, "P1", kV1, 12, Version(1));  // version 1's own text still runs
  EXPECT_EQ(record.database().QueryText("SELECT group_concat(version, ',') FROM (SELECT version FROM "
                                        "protocol_versions ORDER BY id)"),
            "1,2");
  EXPECT_EQ(record.database().QueryText("SELECT group_concat(p.code || ':' || v.version, ',') FROM (SELECT * FROM "
                                        "sessions ORDER BY id) s JOIN participants p ON p.id = s.participant_id "
                                        "JOIN protocol_versions v ON v.id = s.protocol_version_id"),
            "P1:1,P2:2,P1:1");
}

TEST(Record, LowerVersionWithAnotherTextIsRefused) {
  Record record = Record::Open(":memory:");
  Complete(record, "P1", R"({"name":"s","timing":{"stimulus_ms":300},"version":3})", 11, Version(3));
  EXPECT_EQ(ErrorOf([&] { record.StartOrResumeSession("s", "P2", kV1, 21, Version(1), false); }),
            ":memory:: study s records protocol version 3, this protocol says version 1 with another text "
            "(/timing/stimulus_ms: 300 in the record, 1500 now); raise \"version\" to 4 to record it as a new "
            "version, or use another record (--db)");
}

TEST(Record, DesignIsRecordedOncePerProtocolVersionWithNumericLevelsInOrder) {
  Record record = Record::Open(":memory:");
  SessionMeta meta = Version(1);
  DesignColumnRecord edge{"edge", "within", "integer", "", {2, 6, 10}, {}, {}, {}};
  DesignColumnRecord group{"group", "group", "string", "", {}, {"a", "b"}, {}, {}};
  DesignColumnRecord level{"level", "within", "number", "", {}, {}, 0.0, 1.5};
  DesignColumnRecord age{"info_age", "label", "integer", "years", {}, {}, 18.0, {}};
  meta.design = {edge, group, level, age};
  Complete(record, "P1", kV1, 11, meta);
  Complete(record, "P2", kV1, 21, meta);
  EXPECT_EQ(record.database().QueryText("SELECT group_concat(name || ':' || role || ':' || type || ':' || unit || ':' "
                                        "|| allowed, ',') FROM (SELECT * FROM design_columns ORDER BY position)"),
            "edge:within:integer::2|6|10,group:group:string::a|b,level:within:number::0..1.5,"
            "info_age:label:integer:years:>= 18");
}

// A conditions table is a file the protocol names, not part of its text: edited (edge 2 -> 3) under an unchanged
// text, a new session used to be recorded under the same version, its codebook giving the first table's values.
// Now the design recorded with the version is compared, and a different one refused as a changed protocol.
TEST(Record, SameTextWithAnotherDesignIsRefusedAsAChangedProtocol) {
  Record record = Record::Open(":memory:");
  SessionMeta meta = Version(1);
  meta.design = {DesignColumnRecord{"edge", "within", "integer", "", {2, 9}, {}, {}, {}}};
  Complete(record, "P1", kV1, 11, meta);
  Complete(record, "P2", kV1, 21, meta);  // the same design: fine
  meta.design[0].numbers = {3, 9};
  EXPECT_EQ(ErrorOf([&] { record.StartOrResumeSession("s", "P3", kV1, 31, meta, false); }),
            ":memory:: study s records protocol version 1 with another design (column edge: 2|9 in the record, 3|9 "
            "now): the text is the same, so a file it names (a conditions table) has changed; raise \"version\" to "
            "2 to record it as a new version, or use another record (--db)");
  EXPECT_EQ(record.database().QueryInt64("SELECT count(*) FROM sessions"), 2);
  // A column the levels set, new: refused; a label or a column a later build describes otherwise: not compared.
  meta.design[0].numbers = {2, 9};
  meta.design.push_back(DesignColumnRecord{"speed_cm_s", "within", "number", "cm/s", {1.8}, {}, {}, {}});
  EXPECT_NE(ErrorOf([&] { record.StartOrResumeSession("s", "P3", kV1, 31, meta, false); }).find(
                "(column speed_cm_s absent in the record, present now)"),
            std::string::npos);
  meta.design.back() = DesignColumnRecord{"label", "label", "string", "", {}, {"near"}, {}, {}};
  EXPECT_EQ(record.StartOrResumeSession("s", "P3", kV1, 31, meta, false).session_number, 1);
}

TEST(Record, ProcedureTrialKeepsItsCellByLevels) {
  Record record = Record::Open(":memory:");
  const int64_t session = record.StartOrResumeSession("s", "P1", kV1, 11, {}, false).session_id;
  TrialRecord cell, plain;
  cell.cell = "edge=9";
  plain.index = 1;
  record.SaveTrialList(session, {cell, plain});
  EXPECT_EQ(record.database().QueryText("SELECT group_concat(coalesce(cell, 'NULL'), ',') FROM (SELECT cell FROM "
                                        "trials ORDER BY trial_index)"),
            "edge=9,NULL");
}

// A record of version 7 knew no session numbers nor declared versions: the migration numbers each participant's
// sessions by start and reads the version off each protocol text.
// `sessions` says what became of each session the record keeps running (unfinished): run now by a live writer, left
// by its run (quit, --stop-after: the lock released), or interrupted (a writer that died holding the lock); the
// record's own status stays running for all three, as export and report read it.
TEST(Sessions, ARunningSessionIsListedByWhatBecameOfIt) {
  testing::TempDir dir;
  const auto path = dir / "r.sqlite";
  Record live = Record::Open(path);
  live.StartOrResumeSession("s", "LIVE", kV1, 1, {}, false);
  {
    Record left = Record::Open(path);
    left.StartOrResumeSession("s", "LEFT", kV1, 2, {}, false);
  }  // its run ended without completing it: quit, or --stop-after
  int64_t died = 0;
  {
    Record dead = Record::Open(path);
    died = dead.StartOrResumeSession("s", "DIED", kV1, 3, {}, false).session_id;
  }
  // The lock a killed writer of this host leaves: pid 1 is alive (a reused pid), silent for two minutes.
  const int64_t old_ms = std::chrono::duration_cast<std::chrono::milliseconds>(
                             std::chrono::system_clock::now().time_since_epoch()).count() - 120000;
  live.database().Exec("UPDATE sessions SET lock_host = '" + HostName() + "', lock_pid = 1, lock_token = 'x', "
                       "lock_heartbeat_ms = " + std::to_string(old_ms) + " WHERE id = " + std::to_string(died));
  Complete(live, "DONE", kV1, 4);
  std::map<std::string, std::pair<std::string, std::string>> listed;  // participant -> (state, status)
  for (const SessionSummary& s : ListSessions(path)) listed[s.participant] = {s.state, s.status};
  EXPECT_EQ(listed["LIVE"], std::make_pair(std::string("running"), std::string("running")));
  EXPECT_EQ(listed["LEFT"], std::make_pair(std::string("unfinished"), std::string("running")));
  EXPECT_EQ(listed["DIED"], std::make_pair(std::string("interrupted"), std::string("running")));
  EXPECT_EQ(listed["DONE"], std::make_pair(std::string("completed"), std::string("completed")));
}

TEST(Schema, VersionSevenRecordGetsSessionNumbersByStartAndVersionsFromItsTexts) {
  testing::TempDir dir;
  {
    Database db(dir / "old.sqlite");
    for (int i = 0; i < 7; ++i) {
      const Migration& step = Migrations()[size_t(i)];
      if (!step.sql.empty()) db.Exec(step.sql);
      if (step.data) step.data(db);
    }
    db.Exec("PRAGMA user_version = 7");
    db.Exec("INSERT INTO studies (name, created) VALUES ('s', 'now');"
            "INSERT INTO protocol_versions (study_id, json, hash, created) VALUES (1, '{\"version\":3}', 'a', 'now'),"
            "  (1, '{}', 'b', 'now');"
            "INSERT INTO participants (study_id, code, created) VALUES (1, 'P1', 'now'), (1, 'P2', 'now');"
            "INSERT INTO sessions (participant_id, protocol_version_id, seed, software_version, host, display, "
            "  started, status) VALUES (1, 1, 1, 'v', 'h', 'd', '2024-01-02T00:00:00.000Z', 'completed'),"
            "  (2, 1, 2, 'v', 'h', 'd', '2024-01-01T00:00:00.000Z', 'completed'),"
            "  (1, 2, 3, 'v', 'h', 'd', '2024-01-01T00:00:00.000Z', 'aborted');"
            "INSERT INTO trials (session_id, trial_index, block, factors, left_shown, right_shown) VALUES "
            "  (1, 0, 0, '{\"odd_interval\": 2}', 'null', 'null'), (1, 1, 0, '{\"odd_interval\": 3}', 'null', 'null'),"
            "  (1, 2, 0, '{\"odd_interval\": 3}', 'null', 'null'), (1, 3, 0, '{}', 'null', 'null');"
            "INSERT INTO responses (trial_id, choice, adjustment, answered_at) VALUES (1, '2', '[]', 'now'), "
            "  (2, '1', '[]', 'now'), (3, 'none', '[]', 'now'), (4, '2', '[]', 'now');");
  }
  Record record = Record::Open(dir / "old.sqlite");
  EXPECT_EQ(record.database().QueryText("SELECT group_concat(session_number, ',') FROM (SELECT * FROM sessions "
                                        "ORDER BY id)"),
            "2,1,1");  // P1's session 3 started first
  EXPECT_EQ(record.database().QueryText("SELECT group_concat(version, ',') FROM (SELECT * FROM protocol_versions "
                                        "ORDER BY id)"),
            "3,1");
  EXPECT_EQ(record.StartOrResumeSession("s", "P1", R"({"version":4})", 4, Version(4), false).session_number, 3);
  // An odd one out answered before the answer's correctness was recorded is scored once, here: 2 of 2 right, 1 of 3
  // wrong; a timeout and a trial without an odd interval have no correct answer.
  EXPECT_EQ(record.database().QueryText("SELECT group_concat(coalesce(correct, 'NULL'), ',') FROM (SELECT * FROM "
                                        "responses ORDER BY id)"),
            "1,0,NULL,NULL");
}

// Two stations each ran a participant's first session: merged, the participant's sessions are numbered by start.
TEST(Merge, SessionNumbersFollowTheStartAcrossInputsAndChangesAreTold) {
  testing::TempDir dir;
  for (const char* name : {"a.sqlite", "b.sqlite"}) {
    Record record = Record::Open(dir / name);
    Complete(record, "P1", kV1, name[0] == 'a' ? 11 : 12);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));  // b starts later, by the clock's milliseconds
  }
  std::vector<std::string> notes;
  MergeDatabases({dir / "b.sqlite", dir / "a.sqlite"}, dir / "m.sqlite",
                 [&](const std::string& line) { notes.push_back(line); }, SamePerson({"P1"}));
  Record merged = Record::Open(dir / "m.sqlite");
  // a's session started first (made first above), so it is session 1 although b was merged first.
  EXPECT_EQ(merged.database().QueryText("SELECT group_concat(seed || ':' || session_number, ',') FROM (SELECT * FROM "
                                        "sessions ORDER BY session_number)"),
            "11:1,12:2");
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("b.sqlite: session 1 (study s, participant P1) is session number 1 there and 2 in the "
                          "merged record"),
            std::string::npos)
      << notes[0];
}

}  // namespace
}  // namespace blurcue::store

namespace blurcue::store {
namespace {

// Two stations each ran P1's first session with the default seed (so one trial order): merged as one person (the
// experimenter says so), P1 has sessions 1 and 2 with one seed, which run refuses to make - a likely mistake.
TEST(Merge, OneParticipantsSessionsWithOneSeedAtTwoStationsAreTold) {
  testing::TempDir dir;
  for (const char* name : {"a.sqlite", "b.sqlite"}) {
    Record record = Record::Open(dir / name);
    Complete(record, "P1", kV1, 11);
    Complete(record, "P2", kV1, name[0] == 'a' ? 21 : 22);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  std::vector<std::string> notes;
  MergeDatabases({dir / "a.sqlite", dir / "b.sqlite"}, dir / "m.sqlite",
                 [&](const std::string& line) { notes.push_back(line); }, SamePerson({"P1", "P2"}));
  ASSERT_FALSE(notes.empty());
  EXPECT_EQ(notes.back(), "study s, participant P1: sessions 1, 2 in the merged record ran with one seed, so in one "
                          "trial order - two people given one id at two stations, or one person shown the same order "
                          "twice; check before analysing them as one participant");
  for (const std::string& line : notes) EXPECT_EQ(line.find("participant P2: sessions"), std::string::npos) << line;
}

TEST(Merge, AVersionRunWithTwoTextsAtTwoStationsIsMergedAndTold) {
  testing::TempDir dir;
  {
    Record a = Record::Open(dir / "a.sqlite");
    Complete(a, "P1", kV1, 11, Version(1));
    Record b = Record::Open(dir / "b.sqlite");
    Complete(b, "P2", R"({"name":"s","timing":{"stimulus_ms":300},"version":1})", 21, Version(1));
  }
  std::vector<std::string> notes;
  MergeDatabases({dir / "a.sqlite", dir / "b.sqlite"}, dir / "m.sqlite",
                 [&](const std::string& line) { notes.push_back(line); });
  EXPECT_EQ(notes, (std::vector<std::string>{"study s: protocol version 1 has 2 different texts in the merged record "
                                             "(protocol_hash tells their sessions apart)"}));
}

MergeOptions::Rename Rename(const std::filesystem::path& input, std::string from, std::string to) {
  return {input, std::move(from), std::move(to)};
}

// Two stations gave one id to two people (issue 24): merge refuses to join them, naming both ways out; renamed, they
// stay two participants; declared one person, they are one. A rename or a same-person code that names nothing is
// refused with the nearest name.
TEST(Merge, OneIdAtTwoStationsIsRefusedUntilTheExperimenterSaysWhoItIs) {
  testing::TempDir dir;
  for (const char* name : {"a.sqlite", "b.sqlite"}) {
    Record record = Record::Open(dir / name);
    Complete(record, "P1", kV1, name[0] == 'a' ? 11 : 12);
  }
  const std::string refused = ErrorOf([&] { MergeDatabases({dir / "a.sqlite", dir / "b.sqlite"}, dir / "m.sqlite"); });
  EXPECT_NE(refused.find("b.sqlite: participant P1 of study s is also in an earlier input of this merge: two people "
                         "with one id, or one person who ran at two stations? Two people: give one another id with "
                         "--rename " + (dir / "b.sqlite").string() + ":P1=NEW; one person: say so with --same-person P1"),
            std::string::npos) << refused;
  EXPECT_FALSE(std::filesystem::exists(dir / "m.sqlite"));

  MergeOptions two;
  two.renames = {Rename(dir / "b.sqlite", "P1", "P1b")};
  MergeDatabases({dir / "a.sqlite", dir / "b.sqlite"}, dir / "two.sqlite", {}, two);
  Record merged = Record::Open(dir / "two.sqlite");
  EXPECT_EQ(merged.database().QueryText("SELECT group_concat(p.code || ':' || s.seed, ',') FROM (SELECT * FROM "
                                        "sessions ORDER BY seed) s JOIN participants p ON p.id = s.participant_id"),
            "P1:11,P1b:12");

  MergeDatabases({dir / "a.sqlite", dir / "b.sqlite"}, dir / "one.sqlite", {}, SamePerson({"P1"}));
  EXPECT_EQ(Record::Open(dir / "one.sqlite").database().QueryInt64("SELECT count(*) FROM participants"), 1);

  MergeOptions typo;
  typo.renames = {Rename(dir / "b.sqlite", "p1", "P1b")};
  EXPECT_NE(ErrorOf([&] { MergeDatabases({dir / "a.sqlite", dir / "b.sqlite"}, dir / "t.sqlite", {}, typo); })
                .find("holds no participant 'p1' (did you mean P1?)"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { MergeDatabases({dir / "a.sqlite", dir / "b.sqlite"}, dir / "t.sqlite", {}, SamePerson({"P2"})); })
                .find("--same-person: no input holds a participant 'P2'"),
            std::string::npos);
  MergeOptions unsafe;
  unsafe.renames = {Rename(dir / "b.sqlite", "P1", "=P1")};
  EXPECT_NE(ErrorOf([&] { MergeDatabases({dir / "a.sqlite", dir / "b.sqlite"}, dir / "t.sqlite", {}, unsafe); })
                .find("the new id begins with ="),
            std::string::npos);
}

// A rename onto an id the same record gives another person of the study would join two people the station kept
// apart: refused naming both (it was blamed on "an earlier input", and the --same-person it offered made b's P1 and
// P2 one participant). Two ids renamed to one are refused; a rename onto an id that is itself renamed away is not.
TEST(Merge, ARenameOntoAnIdTheSameRecordGivesAnotherPersonIsRefused) {
  testing::TempDir dir;
  {
    Record a = Record::Open(dir / "a.sqlite");
    Complete(a, "P1", kV1, 11);
    Record b = Record::Open(dir / "b.sqlite");
    Complete(b, "P1", kV1, 12);
    Complete(b, "P2", kV1, 13);
  }
  const std::string b = (dir / "b.sqlite").string();
  MergeOptions onto;
  onto.renames = {Rename(dir / "b.sqlite", "P1", "P2")};
  onto.same_person = {"P2"};
  EXPECT_EQ(ErrorOf([&] { MergeDatabases({dir / "a.sqlite", dir / "b.sqlite"}, dir / "m.sqlite", {}, onto); }),
            "--rename: " + b + ":P1=P2: " + b + " already holds a participant P2 of study s, another person than P1; "
            "give P1 an id that record does not hold");
  EXPECT_FALSE(std::filesystem::exists(dir / "m.sqlite"));
  MergeOptions both;
  both.renames = {Rename(dir / "b.sqlite", "P1", "S2"), Rename(dir / "b.sqlite", "P2", "S2")};
  EXPECT_EQ(ErrorOf([&] { MergeDatabases({dir / "a.sqlite", dir / "b.sqlite"}, dir / "m.sqlite", {}, both); }),
            "--rename: gives participants P1 and P2 of " + b + " one new id 'S2'; they are two people there");
  MergeOptions chain;
  chain.renames = {Rename(dir / "b.sqlite", "P1", "P2"), Rename(dir / "b.sqlite", "P2", "P3")};
  MergeDatabases({dir / "a.sqlite", dir / "b.sqlite"}, dir / "chain.sqlite", {}, chain);
  EXPECT_EQ(Record::Open(dir / "chain.sqlite").database().QueryText(
                "SELECT group_concat(p.code || ':' || s.seed, ',') FROM (SELECT * FROM sessions ORDER BY seed) s "
                "JOIN participants p ON p.id = s.participant_id"),
            "P1:11,P2:12,P3:13");
}

}  // namespace
}  // namespace blurcue::store
