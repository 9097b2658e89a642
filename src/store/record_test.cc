#include "store/record.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include <functional>

#include "core/error.h"
#include "core/hash.h"
#include "store/schema.h"
#include "store/test_util.h"

namespace blurcue::store {
namespace {

// A frame of a trial: its index, flip time and whether it was dropped (no radii: a picture's).
FrameRecord Frame(int64_t index, double flip_time_s, bool dropped) {
  FrameRecord f;
  f.frame_index = index, f.flip_time_s = flip_time_s, f.dropped = dropped;
  return f;
}

const char* kProtocol = R"({"name":"test1","trials":4})";

std::vector<TrialRecord> Trials(int n) {
  std::vector<TrialRecord> trials;
  for (int i = 0; i < n; ++i) {
    TrialRecord t;
    t.index = i;
    t.block = i / 5;
    t.factors_json = R"({"edge":)" + std::to_string(i % 11 + 1) + R"(,"blur":"measured"})";
    t.source_json[0] = R"("measured")";
    t.source_json[1] = R"("estimated")";
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
  record.RecordResponse(session, 0, Answer("left"),
                        {Frame(0, 0.0, false), Frame(1, 0.0167, false), Frame(2, 0.05, true)});
  EXPECT_EQ(record.database().QueryInt64("SELECT COUNT(*) FROM frames"), 3);
  EXPECT_EQ(record.database().QueryInt64("SELECT SUM(dropped) FROM frames"), 1);
  // A refused second answer adds no frames either: both roll back together.
  EXPECT_THROW(record.RecordResponse(session, 0, Answer("right"), {Frame(0, 0.0, false)}), Error);
  EXPECT_EQ(record.database().QueryInt64("SELECT COUNT(*) FROM frames"), 3);
}

// The typed record: who answered, where, and what each trial showed, in columns of their own, exactly as given.
TEST(Record, WritesTheTypedColumns) {
  Record record = Record::Open(":memory:");
  SessionMeta meta;
  meta.simulated = true;
  meta.observer_params = "sim:jnd=0.5";
  meta.window = false;
  meta.display_profile = R"({"name":"lab","width_mm":531.4,"height_mm":298.9,"distance_mm":600,"px_per_deg":37.83})";
  meta.participant_info = R"({"age":31,"hand":"left"})";
  const int64_t session = record.StartOrResumeSession("test1", "P01", kProtocol, 7, meta, false).session_id;
  std::vector<TrialRecord> trials = Trials(2);
  trials[0].block_name = "main";
  trials[0].practice = true;
  trials[0].r_px[0] = 1.23456789;
  trials[0].r_scene_px = 0.5;
  trials[1].swapped = true;
  trials[1].source_json[0] = "2.5";
  trials[1].source_json[1] = R"({"arcmin":3})";
  record.SaveTrialList(session, trials);
  Response answer = Answer("left");
  answer.level = 0.125;
  answer.correct = false;
  answer.r_px[1] = 9.87654321;
  record.RecordResponse(session, 1, answer);
  Database& db = record.database();
  EXPECT_EQ(db.QueryText("SELECT observer || '|' || observer_params || '|' || window || '|' || profile_name || '|' || "
                         "px_per_deg FROM sessions"),
            "simulated|sim:jnd=0.5|0|lab|37.83");
  EXPECT_EQ(db.QueryText("SELECT group_concat(key || '=' || value, ',') FROM session_info"), "age=31,hand=left");
  EXPECT_EQ(db.QueryText("SELECT block_name || '|' || practice || '|' || swapped || '|' || left_source || '|' || "
                         "right_source || '|' || coalesce(r_right_px, 'null') FROM trials WHERE trial_index = 0"),
            "main|1|0|measured|estimated|null");
  EXPECT_EQ(db.QueryText("SELECT printf('%.8f', r_left_px) FROM trials WHERE trial_index = 0"), "1.23456789");
  EXPECT_EQ(db.QueryText("SELECT left_source || '|' || left_fixed || '|' || right_source || '|' || right_fixed || "
                         "'|' || swapped FROM trials WHERE trial_index = 1"),
            "fixed_px|2.5|fixed_arcmin|3.0|1");
  EXPECT_EQ(db.QueryText("SELECT level || '|' || correct || '|' || coalesce(r_left_px, 'null') FROM responses"),
            "0.125|0|null");
  EXPECT_EQ(db.QueryText("SELECT printf('%.8f', r_right_px) FROM responses"), "9.87654321");
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
    // What differs, both ways, and the way out.
    EXPECT_NE(std::string(e.what()).find("session 1 trial 2 differs from the one made now (levels "
                                         "{\"edge\":3,\"blur\":\"measured\"} saved, {\"edge\":3,\"blur\":"
                                         "\"measured\",\"r_left_px\":1.5} now)"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--abort 1 (its answers are kept)"), std::string::npos) << e.what();
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
    for (int i : {0, 1, 2}) record.RecordResponse(session, i, Answer("left"));
  }
  Record record = Record::Open(dir / "r.sqlite");
  const SessionStart start = record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, true);
  EXPECT_TRUE(start.resumed);
  EXPECT_EQ(start.session_id, session);
  EXPECT_EQ(start.trial_count, 10);
  EXPECT_EQ(start.first_unanswered_trial, 3);
  record.RecordResponse(session, 3, Answer("right"));
  EXPECT_EQ(record.FirstUnansweredTrial(session), 4);
}

// A session runs its trials in order, so an answer past the first unanswered trial means a record changed outside
// blurcue (an answer deleted from the middle): resuming it is refused, not continued over the gap.
TEST(Record, ResumeOverAGapInTheAnswersIsRefused) {
  testing::TempDir dir;
  {
    Record record = Record::Open(dir / "r.sqlite");
    const int64_t session = record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, false).session_id;
    record.SaveTrialList(session, Trials(10));
    for (int i : {0, 1, 2, 4}) record.RecordResponse(session, i, Answer("left"));
  }
  Record record = Record::Open(dir / "r.sqlite");
  try {
    record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, true);
    ADD_FAILURE() << "resumed over a gap";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    EXPECT_NE(std::string(e.what()).find("its first unanswered trial is 3, but the record holds answers"),
              std::string::npos) << e.what();
  }
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
  EXPECT_THROW(record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, true), Error);  // nothing to resume
  const SessionStart next = record.StartOrResumeSession("test1", "P01", kProtocol, 8, {}, false);
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

std::string ErrorOf(const std::function<void()>& action) {
  try {
    action();
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "no error";
  return {};
}

bool Contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

const char* kFullProtocol = R"({"name":"test1","timing":{"inter_trial_ms":500,"stimulus_ms":0},"trials":4})";

// --resume with nothing to resume says what it found and starts nothing: no session appears.
TEST(Record, ResumeWithNothingToResumeIsRefusedAndStartsNothing) {
  Record record = Record::Open(":memory:");
  EXPECT_TRUE(Contains(ErrorOf([&] { record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, true); }),
                       "--resume: participant P01 of study test1 has no unfinished session to continue (no sessions "
                       "at all); leave out --resume"));
  const int64_t session = record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, false).session_id;
  record.SaveTrialList(session, Trials(1));
  record.RecordResponse(session, 0, Answer("left"));
  record.FinishSession(session, SessionStatus::kCompleted);
  const std::string message =
      ErrorOf([&] { record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, true); });
  EXPECT_TRUE(Contains(message, "(1 completed (last: session 1)); leave out --resume to start a new session, with "
                                "--again")) << message;
  EXPECT_EQ(record.database().QueryInt64("SELECT count(*) FROM sessions"), 1);
}

// A resumed session is answered by the observer it started with: the session row names one. Another simulated
// observer, or a person for a simulated one, is refused naming both; the same canonical parameters resume.
TEST(Record, ResumeWithAnotherObserverIsRefusedNamingBoth) {
  testing::TempDir dir;
  SessionMeta lapse;
  lapse.simulated = true;
  lapse.observer_params = "sim:model=arcmin,weber=0.35,lapse=1";
  { Record::Open(dir / "r.sqlite").StartOrResumeSession("test1", "P01", kProtocol, 7, lapse, false); }
  Record record = Record::Open(dir / "r.sqlite");
  SessionMeta weber = lapse;
  weber.observer_params = "sim:model=arcmin,weber=0.5,lapse=0.04";
  const std::string message = ErrorOf([&] { record.StartOrResumeSession("test1", "P01", kProtocol, 7, weber, true); });
  EXPECT_TRUE(Contains(message, "session 1 was started with --observer sim:model=arcmin,weber=0.35,lapse=1, got "
                                "--observer sim:model=arcmin,weber=0.5,lapse=0.04; resume it with the observer it "
                                "started with, or close it with blurcue sessions --db "))
      << message;
  EXPECT_TRUE(Contains(ErrorOf([&] { record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, true); }),
                       "got a person (no --observer)"));
  EXPECT_TRUE(record.StartOrResumeSession("test1", "P01", kProtocol, 7, lapse, true).resumed);
}

// A simulated observer's times are of its clock: a session started headless (simulated clock) and resumed in a
// window (real clock), or the other way, is refused naming both; resumed as it started, it resumes.
TEST(Record, ResumeInAWindowOfAHeadlessSessionIsRefused) {
  testing::TempDir dir;
  SessionMeta headless;
  headless.simulated = true;
  headless.observer_params = "sim:model=arcmin,weber=0.35,lapse=0.04";
  headless.window = false;
  { Record::Open(dir / "r.sqlite").StartOrResumeSession("test1", "P01", kProtocol, 7, headless, false); }
  Record record = Record::Open(dir / "r.sqlite");
  SessionMeta windowed = headless;
  windowed.window = true;
  const std::string message =
      ErrorOf([&] { record.StartOrResumeSession("test1", "P01", kProtocol, 7, windowed, true); });
  EXPECT_TRUE(Contains(message, "session 1 was started headless, got in a window (--window); resume it the way it "
                                "started, or close it with blurcue sessions --db "))
      << message;
  EXPECT_TRUE(record.StartOrResumeSession("test1", "P01", kProtocol, 7, headless, true).resumed);
}

// Every radius in screen px and arcmin follows the display profile: a session resumed on another is refused naming
// both profiles and what differs; the same profile read from another path resumes.
TEST(Record, ResumeOnAnotherDisplayProfileIsRefusedNamingWhatDiffers) {
  testing::TempDir dir;
  SessionMeta lab;
  lab.display_profile = R"({"distance_mm":570.0,"file":"lab-1.json","name":"lab 1","width_mm":376.0})";
  { Record::Open(dir / "r.sqlite").StartOrResumeSession("test1", "P01", kProtocol, 7, lab, false); }
  Record record = Record::Open(dir / "r.sqlite");
  SessionMeta moved = lab;
  moved.display_profile = R"({"distance_mm":600.0,"file":"lab-1.json","name":"lab 1","width_mm":376.0})";
  const std::string message = ErrorOf([&] { record.StartOrResumeSession("test1", "P01", kProtocol, 7, moved, true); });
  EXPECT_TRUE(Contains(message, "session 1 was started with display profile \"lab 1\", got \"lab 1\" (/distance_mm "
                                "570.0 -> 600.0); resume it with the --display (or the protocol's display.profile) it "
                                "started with, or close it with blurcue sessions --db "))
      << message;
  SessionMeta other = lab;
  other.display_profile = R"({"distance_mm":570.0,"file":"lab-2.json","name":"lab 2","width_mm":520.0})";
  EXPECT_TRUE(Contains(ErrorOf([&] { record.StartOrResumeSession("test1", "P01", kProtocol, 7, other, true); }),
                       "display profile \"lab 1\", got \"lab 2\" (/width_mm 376.0 -> 520.0)"));
  SessionMeta elsewhere = lab;
  elsewhere.display_profile = R"({"distance_mm":570.0,"file":"../lab/lab-1.json","name":"lab 1","width_mm":376.0})";
  EXPECT_TRUE(record.StartOrResumeSession("test1", "P01", kProtocol, 7, elsewhere, true).resumed);
  // A recorded profile that is not JSON (a damaged record) is refused, not taken for the same display.
  record.database().Exec("UPDATE sessions SET display_profile = '{\"distance_mm\": 57' WHERE id = 1");
  EXPECT_TRUE(Contains(ErrorOf([&] { record.StartOrResumeSession("test1", "P01", kProtocol, 7, lab, true); }),
                       "display profile (unreadable: the record's display_profile is not JSON)"));
}

// An editor's newline, CRLF line ends, indentation and key order are the same protocol: the session resumes.
TEST(Record, ReformattedProtocolResumesTheSameSession) {
  testing::TempDir dir;
  int64_t session = 0;
  {
    Record first = Record::Open(dir / "r.sqlite");
    session = first.StartOrResumeSession("test1", "P01", kFullProtocol, 7, {}, false).session_id;
    first.SaveTrialList(session, Trials(4));
    first.RecordResponse(session, 0, Answer("left"));
  }
  const std::string reformatted =
      "{\r\n  \"trials\": 4,\r\n  \"timing\": {\"stimulus_ms\": 0, \"inter_trial_ms\": 500},\r\n"
      "  \"name\": \"test1\"\r\n}\r\n\n";
  Record second = Record::Open(dir / "r.sqlite");
  const SessionStart start = second.StartOrResumeSession("test1", "P01", reformatted, 7, {}, true);
  EXPECT_TRUE(start.resumed);
  EXPECT_EQ(start.session_id, session);
  EXPECT_EQ(start.first_unanswered_trial, 1);
}

// A protocol that really changed is refused naming the change and the command that closes the session; the
// abort keeps its answers and a new session can start.
TEST(Record, ChangedProtocolNamesTheChangeAndAbortKeepsTheAnswers) {
  testing::TempDir dir;
  int64_t session = 0;
  {
    Record first = Record::Open(dir / "r.sqlite");
    session = first.StartOrResumeSession("test1", "P01", kFullProtocol, 7, {}, false).session_id;
    first.SaveTrialList(session, Trials(4));
    first.RecordResponse(session, 0, Answer("left"));
    first.RecordResponse(session, 1, Answer("right"));
  }
  const std::string changed = R"({"name":"test1","timing":{"inter_trial_ms":800,"stimulus_ms":0},"trials":4})";
  Record record = Record::Open(dir / "r.sqlite");
  const std::string message = ErrorOf([&] { record.StartOrResumeSession("test1", "P01", changed, 7, {}, true); });
  EXPECT_TRUE(Contains(message, "session 1 was started with another version of the protocol "
                                "(/timing/inter_trial_ms 500 -> 800)")) << message;
  EXPECT_TRUE(Contains(message, "blurcue sessions --db " + (dir / "r.sqlite").string() + " --abort 1")) << message;
  // Neither does a plain run go on: it points at the same way out.
  EXPECT_TRUE(Contains(ErrorOf([&] { record.StartOrResumeSession("test1", "P01", changed, 7, {}, false); }),
                       "--abort 1 (its answers are kept)"));
  record.AbortSession(session);
  EXPECT_EQ(record.database().QueryText("SELECT status FROM sessions WHERE id = 1"), "aborted");
  EXPECT_EQ(record.database().QueryInt64("SELECT count(*) FROM responses"), 2);
  EXPECT_TRUE(Contains(ErrorOf([&] { record.AbortSession(session); }), "session 1 is aborted; only a running"));
  // Started anew, the changed text is a new version of the study's protocol, with a seed of its own.
  SessionMeta v2;
  v2.protocol_version = 2;
  const SessionStart fresh = record.StartOrResumeSession(
      "test1", "P01", R"({"name":"test1","timing":{"inter_trial_ms":800,"stimulus_ms":0},"trials":4,"version":2})", 8,
      v2, false);
  EXPECT_NE(fresh.session_id, session);
}

// Abort is refused while a live writer holds the session.
TEST(Record, AbortIsRefusedWhileALiveWriterHoldsTheSession) {
  testing::TempDir dir;
  Record writer = Record::Open(dir / "r.sqlite");
  const int64_t session = writer.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, false).session_id;
  Record other = Record::Open(dir / "r.sqlite");
  EXPECT_TRUE(Contains(ErrorOf([&] { other.AbortSession(session); }), "is being written by pid"));
  EXPECT_EQ(other.database().QueryText("SELECT status FROM sessions"), "running");
}

// Sets the session's lock row as another writer would have left it.
void PlantLock(Database& db, int64_t session, const std::string& host, int64_t pid, double age_s) {
  const int64_t now_ms = std::chrono::duration_cast<std::chrono::milliseconds>(
                             std::chrono::system_clock::now().time_since_epoch()).count();
  Statement plant(db, "UPDATE sessions SET lock_host = ?, lock_pid = ?, lock_token = 'planted', "
                      "lock_heartbeat_ms = ? WHERE id = ?");
  plant.Bind(1, host);
  plant.Bind(2, pid);
  plant.Bind(3, now_ms - static_cast<int64_t>(age_s * 1000));
  plant.Bind(4, session);
  plant.Run();
}

// A crashed writer's pid reused by another live program on this host: a fresh heartbeat keeps the lock, an old
// one (the runner beats every 5 s) makes it stale.
TEST(Record, LockOfAReusedPidIsStaleByItsHeartbeatAge) {
  testing::TempDir dir;
  int64_t session = 0;
  {
    Record first = Record::Open(dir / "r.sqlite");
    session = first.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, false).session_id;
  }
  Record record = Record::Open(dir / "r.sqlite");
  // pid 1 is always alive: the reused pid.
  PlantLock(record.database(), session, HostName(), 1, 5);
  EXPECT_TRUE(Contains(ErrorOf([&] { record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, true); }),
                       "is being written by pid 1 on host " + HostName() + ", heartbeat 5 s ago (alive)"));
  PlantLock(record.database(), session, HostName(), 1, 61);
  EXPECT_TRUE(Contains(record.Lock(session).text, "(silent for over 60 s: a stale lock"));
  EXPECT_TRUE(record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, true).resumed);
}

// Eight stations starting one participant at once: those refused are told another process is running that session
// right now, not to --resume or --abort it; once its lock is stale the usual way out is offered.
TEST(Record, StartingAParticipantAnotherStationIsRunningSaysSo) {
  testing::TempDir dir;
  int64_t session = 0;
  {
    Record first = Record::Open(dir / "r.sqlite");
    session = first.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, false).session_id;
  }
  Record record = Record::Open(dir / "r.sqlite");
  PlantLock(record.database(), session, HostName(), 1, 2);
  const std::string live = ErrorOf([&] { record.StartOrResumeSession("test1", "P01", kProtocol, 8, {}, false); });
  EXPECT_TRUE(Contains(live, "participant P01 of study test1 is being run right now in session 1 by pid 1 on host " +
                                 HostName() + ", heartbeat 2 s ago (alive); check the participant id")) << live;
  EXPECT_FALSE(Contains(live, "--resume")) << live;
  PlantLock(record.database(), session, HostName(), 1, 61);
  EXPECT_TRUE(Contains(ErrorOf([&] { record.StartOrResumeSession("test1", "P01", kProtocol, 8, {}, false); }),
                       "has an unfinished session 1; continue it with --resume"));
}

// A lock from another host is kept for 10 minutes; the experimenter can break it explicitly.
TEST(Record, BreakLockFreesASessionHeldFromAnotherHost) {
  testing::TempDir dir;
  int64_t session = 0;
  {
    Record first = Record::Open(dir / "r.sqlite");
    session = first.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, false).session_id;
  }
  Record record = Record::Open(dir / "r.sqlite");
  PlantLock(record.database(), session, "other-station", 4242, 30);
  EXPECT_TRUE(Contains(ErrorOf([&] { record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, true); }),
                       "--break-lock 1"));
  const LockState broken = record.BreakLock(session);
  EXPECT_TRUE(Contains(broken.text, "pid 4242 on host other-station, heartbeat 30 s ago")) << broken.text;
  EXPECT_TRUE(Contains(ErrorOf([&] { record.BreakLock(session); }), "holds no lock"));
  EXPECT_TRUE(record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, true).resumed);
}

// Another program's SQLite file is refused and left byte for byte as it was, with no WAL beside it.
TEST(Record, ForeignDatabaseIsRefusedUntouched) {
  testing::TempDir dir;
  const auto path = dir / "customers.sqlite";
  {
    Database db(path);
    db.Exec("CREATE TABLE customers (id INTEGER PRIMARY KEY, name TEXT); INSERT INTO customers (name) VALUES ('x')");
  }
  const std::string before = testing::FileBytes(path);
  const std::string message = ErrorOf([&] { Record::Open(path); });
  EXPECT_TRUE(Contains(message, "customers.sqlite: not a blurcue record: it holds 1 tables (customers)")) << message;
  EXPECT_EQ(testing::FileBytes(path), before);
  EXPECT_FALSE(std::filesystem::exists(path.string() + "-wal"));
  // An empty file is a new record; so is a record stamped before (only its tables tell).
  std::ofstream(dir / "empty.sqlite").close();
  EXPECT_NO_THROW(Record::Open(dir / "empty.sqlite"));
}

// A record of schema version 1 (raw-text hashes, no application id) migrates: its protocol hashes become those of
// the canonical text, so its running sessions resume with the same protocol file.
TEST(Record, VersionOneRecordMigratesToCanonicalHashes) {
  testing::TempDir dir;
  const auto path = dir / "old.sqlite";
  const std::string raw = "{\n  \"name\": \"test1\",\n  \"trials\": 4\n}\n";
  {
    Database db(path);
    db.Exec(Migrations()[0].sql);
    db.Exec("PRAGMA user_version = 1");
    db.Exec("INSERT INTO studies VALUES (1, 'test1', 'then'); INSERT INTO participants VALUES (1, 1, 'P01', 'then')");
    Statement protocol(db, "INSERT INTO protocol_versions VALUES (1, 1, ?, ?, 'then')");
    protocol.Bind(1, raw);
    protocol.Bind(2, HashHex(Fnv1a64(raw)));
    protocol.Run();
    db.Exec("INSERT INTO sessions (participant_id, protocol_version_id, seed, software_version, host, display, "
            "started, status) VALUES (1, 1, 7, 'old', 'h', 'd', 'then', 'running')");
  }
  Record record = Record::Open(path);
  EXPECT_EQ(SchemaVersion(record.database()), CurrentSchemaVersion());
  EXPECT_EQ(record.database().QueryInt64("PRAGMA application_id"), kApplicationId);
  EXPECT_EQ(record.database().QueryText("SELECT hash FROM protocol_versions"),
            ProtocolHash(CanonicalProtocolText(raw)));
  EXPECT_TRUE(record.StartOrResumeSession("test1", "P01", raw, 7, {}, true).resumed);
  // Sessions from before display profiles read as '{}'.
  EXPECT_EQ(record.database().QueryText("SELECT display_profile FROM sessions"), "{}");
}

TEST(Record, EachSessionKeepsTheDisplayProfileItRanWith) {
  Record record = Record::Open(":memory:");
  SessionMeta meta;
  meta.display_profile = R"({"name":"lab 1","px_per_deg":33.87})";
  const int64_t session = record.StartOrResumeSession("test1", "P01", kProtocol, 7, meta, false).session_id;
  EXPECT_EQ(record.database().QueryText("SELECT display_profile FROM sessions WHERE id = " + std::to_string(session)),
            meta.display_profile);
}

// A truncated record is an input error naming the file, never an internal one.
TEST(Record, TruncatedRecordIsAnInputErrorNamingTheFile) {
  testing::TempDir dir;
  const auto path = dir / "r.sqlite";
  {
    Record record = Record::Open(path);
    const int64_t session = record.StartOrResumeSession("test1", "P01", kProtocol, 7, {}, false).session_id;
    record.SaveTrialList(session, Trials(400));
    for (int i = 0; i < 400; ++i)
      record.RecordResponse(session, i, Answer("left"), {Frame(0, 0.0, false), Frame(1, 0.017, false)});
  }  // the last connection checkpoints the WAL into the file
  const auto size = std::filesystem::file_size(path);
  ASSERT_GT(size, 16384u);
  std::filesystem::resize_file(path, size / 2);
  const std::string message = ErrorOf([&] { Record::Open(path); });
  EXPECT_TRUE(Contains(message, path.string() + ": ")) << message;
  EXPECT_TRUE(Contains(message, "damaged")) << message;
  EXPECT_TRUE(Contains(ErrorOf([&] {
                         Database reader(path, OpenMode::kReadOnly);
                         RequireReadableRecord(reader);
                       }),
                       "damaged"));
}

// Forks `n` stations that wait on one pipe, then run station(c) at the same moment; each must end without an Error
// (a station exits with its Error's code, or with its own code to fail a check of its own).
void AtTheSameMoment(int n, const std::string& round, const std::function<void(int station)>& station) {
  int go[2];
  ASSERT_EQ(pipe(go), 0);
  std::vector<pid_t> children;
  for (int c = 0; c < n; ++c) {
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      char byte;
      if (read(go[0], &byte, 1) != 1) _exit(5);
      try {
        station(c);
      } catch (const Error& e) {
        std::fprintf(stderr, "station %d: %s\n", c, e.what());
        _exit(e.exit_code());
      }
      _exit(0);
    }
    children.push_back(child);
  }
  ASSERT_EQ(write(go[1], std::string(n, 'g').data(), n), n);
  for (pid_t child : children) {
    const int status = Wait(child);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << round << ": status " << status;
  }
  close(go[0]);
  close(go[1]);
}

// Two stations starting on the same new file at the same moment: both proceed (the WAL switch waits its turn).
TEST(Record, ConcurrentFirstStartsOnANewFileBothProceed) {
  testing::TempDir dir;
  for (int round = 0; round < 10; ++round) {
    const auto path = dir / ("new-" + std::to_string(round) + ".sqlite");
    AtTheSameMoment(2, "round " + std::to_string(round), [&](int c) {
      Record record = Record::Open(path);
      const std::string participant = "P" + std::to_string(c);
      const int64_t session = record.StartOrResumeSession("test1", participant, kProtocol, 7, {}, false).session_id;
      record.SaveTrialList(session, Trials(3));
      record.RecordResponse(session, 0, Answer("left"));
    });
    Record record = Record::Open(path);
    EXPECT_EQ(record.database().QueryInt64("SELECT count(*) FROM responses"), 2) << "round " << round;
  }
}

// Stations starting at once on one file see each other's sessions when they decide a balanced group: the count and
// the insert are one transaction, so four starts give two sessions to each of two groups, every time.
TEST(Record, ConcurrentStartsCountEachOtherForABalancedGroup) {
  testing::TempDir dir;
  for (int round = 0; round < 5; ++round) {
    const auto path = dir / ("groups-" + std::to_string(round) + ".sqlite");
    AtTheSameMoment(4, "round " + std::to_string(round), [&](int c) {
      Record record = Record::Open(path);
      SessionMeta meta;
      meta.assign_group = [](const std::map<std::string, int64_t>& sessions) {
        const auto count = [&](const char* g) { return sessions.count(g) ? sessions.at(g) : 0; };
        return count("a") <= count("b") ? std::string("a") : std::string("b");
      };
      const SessionStart start = record.StartOrResumeSession("test1", "P" + std::to_string(c), kProtocol, 7, meta, false);
      if (start.group != record.database().QueryText("SELECT group_name FROM sessions WHERE id = " +
                                                      std::to_string(start.session_id)))
        _exit(6);
      // A station runs its session while the others start: it stays alive (its lock live) until all four have
      // started. A session whose process ended unfinished counts for nothing (SessionsPerGroup), as a killed one.
      for (int wait = 0; wait < 400 && record.database().QueryInt64("SELECT count(*) FROM sessions") < 4; ++wait)
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    });
    Record record = Record::Open(path);
    EXPECT_EQ(record.database().QueryText("SELECT group_concat(g) FROM (SELECT group_name || '=' || count(*) g "
                                          "FROM sessions GROUP BY group_name ORDER BY group_name)"),
              "a=2,b=2")
        << "round " << round;
  }
}

TEST(Record, Fnv1a64MatchesTheReferenceValues) {
  EXPECT_EQ(ProtocolHash(""), "cbf29ce484222325");
  EXPECT_EQ(ProtocolHash("a"), "af63dc4c8601ec8c");
}

}  // namespace
}  // namespace blurcue::store
