#include "store/record.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "core/error.h"
#include "store/test_util.h"

namespace blurcue::store {
namespace {

const char* kProtocol = R"({"name":"test1","trials":4})";

std::vector<TrialRecord> Trials(int n) {
  std::vector<TrialRecord> trials;
  for (int i = 0; i < n; ++i) {
    TrialRecord t;
    t.index = i;
    t.block = i / 5;
    t.factors_json = R"({"edge":)" + std::to_string(i % 11 + 1) + R"(,"blur":"measured"})";
    t.left_json = R"("measured")";
    t.right_json = R"("estimated")";
    trials.push_back(t);
  }
  return trials;
}

Response Answer(const std::string& choice) {
  Response r;
  r.choice = choice;
  r.rt_ms = 512.5;
  return r;
}

// Waits for a child and returns its status.
int Wait(pid_t child) {
  int status = 0;
  EXPECT_EQ(waitpid(child, &status, 0), child);
  return status;
}

TEST(Record, NewSessionStartsAtTrialZero) {
  Record record = Record::Open(":memory:");
  const SessionStart start = record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, false);
  EXPECT_FALSE(start.resumed);
  EXPECT_EQ(start.first_unanswered_trial, 0);
  record.SaveTrialList(start.session_id, Trials(10));
  EXPECT_EQ(record.FirstUnansweredTrial(start.session_id), 0);
}

TEST(Record, AnswerAndItsFramesAreOneTransaction) {
  Record record = Record::Open(":memory:");
  const int64_t session = record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, false).session_id;
  record.SaveTrialList(session, Trials(3));
  record.RecordResponse(session, 0, Answer("left"), {{0, 0.0, false}, {1, 0.0167, false}, {2, 0.05, true}});
  EXPECT_EQ(record.database().QueryInt64("SELECT COUNT(*) FROM frames"), 3);
  EXPECT_EQ(record.database().QueryInt64("SELECT SUM(dropped) FROM frames"), 1);
  // A refused second answer adds no frames either: both roll back together.
  EXPECT_THROW(record.RecordResponse(session, 0, Answer("right"), {{0, 0.0, false}}), Error);
  EXPECT_EQ(record.database().QueryInt64("SELECT COUNT(*) FROM frames"), 3);
}

TEST(Record, ResumedTrialListIsCheckedAgainstTheSavedOne) {
  Record record = Record::Open(":memory:");
  const int64_t session = record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, false).session_id;
  record.SaveTrialList(session, Trials(4));
  EXPECT_NO_THROW(record.CheckTrialList(session, Trials(4)));
  std::vector<TrialRecord> changed = Trials(4);
  changed[2].factors_json = R"({"edge":3,"blur":"measured","r_left_px":1.5})";
  try {
    record.CheckTrialList(session, changed);
    ADD_FAILURE() << "a changed trial was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("session 1 trial 2: the saved trial differs"), std::string::npos) << e.what();
  }
  EXPECT_THROW(record.CheckTrialList(session, Trials(5)), Error);
}

TEST(Record, CompletedSessionsOfAParticipant) {
  Record record = Record::Open(":memory:");
  const int64_t first = record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, false).session_id;
  EXPECT_TRUE(record.CompletedSessions("test1", "P01").empty());
  record.FinishSession(first, SessionStatus::kCompleted);
  record.StartOrResumeSession("test2", "P01", kProtocol, 7, {}, false);
  EXPECT_EQ(record.CompletedSessions("test1", "P01"), std::vector<int64_t>{first});
  EXPECT_TRUE(record.CompletedSessions("test2", "P01").empty());
  EXPECT_TRUE(record.CompletedSessions("test1", "P02").empty());
}

TEST(Record, ResponseRecordedTwiceIsRefused) {
  Record record = Record::Open(":memory:");
  const int64_t session = record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, false).session_id;
  record.SaveTrialList(session, Trials(3));
  record.RecordResponse(session, 1, Answer("left"));
  try {
    record.RecordResponse(session, 1, Answer("right"));
    FAIL() << "a second answer to one trial was recorded";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    EXPECT_NE(std::string(e.what()).find("already has a response"), std::string::npos) << e.what();
  }
  EXPECT_EQ(record.database().QueryText("SELECT choice FROM responses"), "left");
  EXPECT_EQ(record.database().QueryInt64("SELECT COUNT(*) FROM responses"), 1);
}

TEST(Record, TrialListIsSavedOnlyOnce) {
  Record record = Record::Open(":memory:");
  const int64_t session = record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, false).session_id;
  record.SaveTrialList(session, Trials(3));
  EXPECT_THROW(record.SaveTrialList(session, Trials(3)), Error);
}

TEST(Record, ResponseToAMissingTrialIsRefused) {
  Record record = Record::Open(":memory:");
  const int64_t session = record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, false).session_id;
  record.SaveTrialList(session, Trials(3));
  EXPECT_THROW(record.RecordResponse(session, 3, Answer("left")), Error);
}

TEST(Record, ResumeReturnsTheFirstUnansweredTrial) {
  testing::TempDir dir;
  int64_t session = 0;
  {
    Record record = Record::Open(dir / "r.sqlite");
    session = record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, false).session_id;
    record.SaveTrialList(session, Trials(10));
    for (int i : {0, 1, 2, 4}) record.RecordResponse(session, i, Answer("left"));
  }
  Record record = Record::Open(dir / "r.sqlite");
  const SessionStart start = record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, true);
  EXPECT_TRUE(start.resumed);
  EXPECT_EQ(start.session_id, session);
  EXPECT_EQ(start.trial_count, 10);
  EXPECT_EQ(start.first_unanswered_trial, 3);
  record.RecordResponse(session, 3, Answer("right"));
  EXPECT_EQ(record.FirstUnansweredTrial(session), 5);
}

TEST(Record, StartingAfreshOverARunningSessionIsRefused) {
  Record record = Record::Open(":memory:");
  record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, false);
  EXPECT_THROW(record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, false), Error);
}

TEST(Record, ResumeWithAnotherProtocolIsRefused) {
  testing::TempDir dir;
  { Record::Open(dir / "r.sqlite").StartOrResumeSession("test1", "P01", kProtocol, 7, {}, false); }
  Record record = Record::Open(dir / "r.sqlite");
  EXPECT_THROW(record.StartOrResumeSession("test1", "P01", R"({"name":"changed"})", 7, {}, true), Error);
  EXPECT_THROW(record.StartOrResumeSession("test1", "P01", kProtocol, 8, {}, true), Error);
}

TEST(Record, FinishedSessionTakesNoMoreAnswersAndANewOneStarts) {
  Record record = Record::Open(":memory:");
  const int64_t session = record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, false).session_id;
  record.SaveTrialList(session, Trials(2));
  record.FinishSession(session, SessionStatus::kAborted);
  EXPECT_THROW(record.RecordResponse(session, 0, Answer("left")), Error);
  EXPECT_EQ(record.database().QueryText("SELECT status FROM sessions"), "aborted");
  const SessionStart next = record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, true);
  EXPECT_FALSE(next.resumed);
  EXPECT_NE(next.session_id, session);
  // The same protocol text is one protocol version.
  EXPECT_EQ(record.database().QueryInt64("SELECT COUNT(*) FROM protocol_versions"), 1);
}

TEST(Record, SeedKeepsAll64Bits) {
  Record record = Record::Open(":memory:");
  const uint64_t seed = 0xfedcba9876543210ULL;
  record.StartOrResumeSession("test1", "P01", kProtocol, seed, {}, false);
  const SessionStart again = record.StartOrResumeSession("test1", "P01", kProtocol, seed, {}, true);
  EXPECT_TRUE(again.resumed);
}

// A child records answers and is killed between two of them, with the next answer's transaction half done;
// the parent finds exactly the committed answers and an intact file.
TEST(Record, KilledSessionKeepsExactlyTheCommittedAnswers) {
  testing::TempDir dir;
  const auto path = dir / "crash.sqlite";
  constexpr int kAnswered = 7;
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    try {
      Record record = Record::Open(path);
      const int64_t session = record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, false).session_id;
      record.SaveTrialList(session, Trials(20));
      for (int i = 0; i < kAnswered; ++i) record.RecordResponse(session, i, Answer(i % 2 ? "left" : "right"));
      // The next answer is under way but not committed when the process dies.
      Transaction transaction(record.database());
      record.database().Exec("INSERT INTO responses (trial_id, choice, rt_ms, adjustment, answered_at) "
                             "SELECT id, 'left', 1.0, '[]', 'now' FROM trials WHERE trial_index = 7");
      kill(getpid(), SIGKILL);
    } catch (...) {
    }
    _exit(1);
  }
  const int status = Wait(child);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "child ended with status " << status;

  Record record = Record::Open(path);
  EXPECT_EQ(record.database().QueryText("PRAGMA integrity_check"), "ok");
  EXPECT_EQ(record.database().QueryInt64("SELECT COUNT(*) FROM responses"), kAnswered);
  EXPECT_EQ(record.database().QueryInt64("SELECT COUNT(*) FROM trials"), 20);
  // The dead child's lock is stale: resuming takes it over and continues at the first unanswered trial.
  const SessionStart start = record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, true);
  EXPECT_TRUE(start.resumed);
  EXPECT_EQ(start.first_unanswered_trial, kAnswered);
  record.RecordResponse(start.session_id, kAnswered, Answer("left"));
}

TEST(Record, SecondRecordObjectCannotWriteARunningSession) {
  testing::TempDir dir;
  Record first = Record::Open(dir / "r.sqlite");
  const int64_t session = first.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, false).session_id;
  first.SaveTrialList(session, Trials(4));
  Record second = Record::Open(dir / "r.sqlite");
  try {
    second.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, true);
    FAIL() << "a second writer took a held session";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    EXPECT_NE(std::string(e.what()).find("pid " + std::to_string(getpid())), std::string::npos) << e.what();
  }
  EXPECT_THROW(second.RecordResponse(session, 0, Answer("left")), Error);
  first.RecordResponse(session, 0, Answer("left"));
}

TEST(Record, LockIsReleasedWhenTheFirstRecordCloses) {
  testing::TempDir dir;
  int64_t session = 0;
  {
    Record first = Record::Open(dir / "r.sqlite");
    session = first.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, false).session_id;
    first.SaveTrialList(session, Trials(4));
  }
  Record second = Record::Open(dir / "r.sqlite");
  EXPECT_EQ(second.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, true).session_id, session);
  second.RecordResponse(session, 0, Answer("left"));
}

// A live second process is refused; once it is gone (killed, its lock left behind) the session is taken over.
TEST(Record, SecondProcessIsRefusedUntilTheFirstIsGone) {
  testing::TempDir dir;
  const auto path = dir / "r.sqlite";
  int ready[2], go[2];
  ASSERT_EQ(pipe(ready), 0);
  ASSERT_EQ(pipe(go), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    char byte = 0;
    try {
      Record record = Record::Open(path);
      const int64_t session = record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, false).session_id;
      record.SaveTrialList(session, Trials(4));
      record.RecordResponse(session, 0, Answer("left"));
      byte = 1;
      if (write(ready[1], &byte, 1) != 1) _exit(2);
      // Hold the lock until the parent has tried, then die without releasing it.
      if (read(go[0], &byte, 1) != 1) _exit(3);
      kill(getpid(), SIGKILL);
    } catch (...) {
    }
    if (write(ready[1], &byte, 1) != 1) _exit(2);
    _exit(4);
  }
  char byte = 0;
  ASSERT_EQ(read(ready[0], &byte, 1), 1);
  ASSERT_EQ(byte, 1) << "the child could not start its session";
  {
    Record record = Record::Open(path);
    try {
      record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, true);
      ADD_FAILURE() << "a second process took a held session";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::kInput);
      EXPECT_NE(std::string(e.what()).find("pid " + std::to_string(child)), std::string::npos) << e.what();
    }
  }
  ASSERT_EQ(write(go[1], &byte, 1), 1);
  Wait(child);
  for (int fd : {ready[0], ready[1], go[0], go[1]}) close(fd);

  Record record = Record::Open(path);
  const SessionStart start = record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, true);
  EXPECT_TRUE(start.resumed);
  EXPECT_EQ(start.first_unanswered_trial, 1);
  record.RecordResponse(start.session_id, 1, Answer("right"));
}

TEST(Record, Fnv1a64MatchesTheReferenceValues) {
  EXPECT_EQ(Fnv1a64Hex(""), "cbf29ce484222325");
  EXPECT_EQ(Fnv1a64Hex("a"), "af63dc4c8601ec8c");
}

}  // namespace
}  // namespace blurcue::store
