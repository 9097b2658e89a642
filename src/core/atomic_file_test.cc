#include "core/atomic_file.h"

#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/temp_dir_test_util.h"

namespace blurcue {
namespace {

namespace fs = std::filesystem;

// A fresh folder per test, removed afterwards.
class AtomicFileTest : public test::TempDirTest {
 protected:
  AtomicFileTest() : TempDirTest("blurcue_atomic_") {}
};

std::string Read(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

void Write(const fs::path& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

// Every name in `dir` (not recursive).
std::set<std::string> Names(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.insert(entry.path().filename().string());
  return names;
}

// The PID of a process that has exited and been reaped: no process has it (until the PID is reused).
pid_t DeadPid() {
  const pid_t child = fork();
  if (child == 0) _exit(0);
  waitpid(child, nullptr, 0);
  return child;
}

// Expects `call` to throw Error(kInput) whose message names `where`.
template <typename F>
void ExpectInputErrorNaming(F call, const std::string& where) {
  try {
    call();
    ADD_FAILURE() << "expected an error naming " << where;
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput) << e.what();
    EXPECT_NE(std::string(e.what()).find(where), std::string::npos) << e.what();
  }
}

TEST_F(AtomicFileTest, WriteReplacesTheFileAndLeavesNothingElse) {
  const fs::path path = dir_ / "sub" / "a.json";
  WriteFileAtomically(path, "old");
  WriteFileAtomically(path, "new\n");
  EXPECT_EQ(Read(path), "new\n");
  EXPECT_EQ(Names(dir_ / "sub"), std::set<std::string>{"a.json"});
}

TEST_F(AtomicFileTest, TemporaryIsBesideTheTargetNamedByItAndThisProcess) {
  EXPECT_EQ(TemporaryBeside(dir_ / "a.csv", "tmp"), dir_ / (".a.csv.tmp-" + std::to_string(getpid())));
  // A folder named with a trailing slash is the same folder.
  EXPECT_EQ(TemporaryBeside(dir_ / "out" / "", "partial"), dir_ / (".out.partial-" + std::to_string(getpid())));
}

TEST_F(AtomicFileTest, FailedRenameRemovesTheTemporary) {
  // The target is a non-empty folder: the temporary is written, the rename fails.
  const fs::path path = dir_ / "taken";
  fs::create_directories(path / "inside");
  ExpectInputErrorNaming([&] { WriteFileAtomically(path, "text"); }, path.string());
  EXPECT_EQ(Names(dir_), std::set<std::string>{"taken"});
  EXPECT_TRUE(fs::is_directory(path / "inside"));
}

// The rename would replace whatever has the name: a FIFO or a device (as root, --out /dev/full became a plain file)
// is refused and stays what it was, and nothing is written beside it.
TEST_F(AtomicFileTest, SpecialFileIsRefusedNotReplaced) {
  const fs::path fifo = dir_ / "pipe";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  ExpectInputErrorNaming([&] { WriteFileAtomically(fifo, "text"); }, fifo.string() + ": is not a regular file");
  EXPECT_TRUE(fs::is_fifo(fs::symlink_status(fifo)));
  EXPECT_EQ(Names(dir_), std::set<std::string>{"pipe"});
  fs::create_directory(dir_ / "empty");
  ExpectInputErrorNaming([&] { WriteFileAtomically(dir_ / "empty", "text"); }, "empty: is a folder");
  EXPECT_TRUE(fs::is_directory(dir_ / "empty"));
}

TEST_F(AtomicFileTest, FailedWriteLeavesTheOldFileWholeAndNoTemporary) {
  const fs::path path = dir_ / "a.csv";
  Write(path, "old contents");
  // A file size limit makes write() fail (EFBIG) even for root, like a full disk would.
  struct rlimit saved {};
  getrlimit(RLIMIT_FSIZE, &saved);
  const auto previous = std::signal(SIGXFSZ, SIG_IGN);
  struct rlimit small = saved;
  small.rlim_cur = 1000;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
  bool threw = false;
  try {
    WriteFileAtomically(path, std::string(5000, 'x'));
  } catch (const Error& e) {
    threw = true;
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
  setrlimit(RLIMIT_FSIZE, &saved);
  std::signal(SIGXFSZ, previous);
  EXPECT_TRUE(threw);
  EXPECT_EQ(Read(path), "old contents");
  EXPECT_EQ(Names(dir_), std::set<std::string>{"a.csv"});
}

TEST_F(AtomicFileTest, FolderThatCannotBeCreatedIsAnInputErrorNotAFilesystemException) {
  Write(dir_ / "plain", "a file");
  const fs::path path = dir_ / "plain" / "sub" / "a.json";
  ExpectInputErrorNaming([&] { WriteFileAtomically(path, "{}"); }, path.string());
  EXPECT_EQ(Read(dir_ / "plain"), "a file");
  ExpectInputErrorNaming([&] { WriteFolderAtomically(dir_ / "plain" / "out", [](const fs::path&) {},
                                                     [](const std::string&) { return true; }); },
                         (dir_ / "plain" / "out").string());
}

TEST_F(AtomicFileTest, FolderIsReplacedAsAWhole) {
  const fs::path out = dir_ / "tables";
  fs::create_directories(out);
  Write(out / "a.csv", "old a");
  Write(out / "b.csv", "old b");
  WriteFolderAtomically(
      out,
      [](const fs::path& partial) {
        EXPECT_TRUE(fs::is_empty(partial));
        Write(partial / "a.csv", "new a");
        Write(partial / "c.csv", "new c");
      },
      [](const std::string&) { return true; });
  EXPECT_EQ(Names(out), (std::set<std::string>{"a.csv", "c.csv"}));
  EXPECT_EQ(Read(out / "a.csv"), "new a");
  EXPECT_EQ(Names(dir_), std::set<std::string>{"tables"});
}

TEST_F(AtomicFileTest, FolderBehindASymlinkIsReplacedWhereItIs) {
  fs::create_directories(dir_ / "real");
  Write(dir_ / "real" / "old.csv", "old");
  fs::create_directory_symlink("real", dir_ / "link");
  WriteFolderAtomically(
      dir_ / "link", [](const fs::path& partial) { Write(partial / "new.csv", "new"); },
      [](const std::string&) { return true; });
  EXPECT_TRUE(fs::is_symlink(dir_ / "link"));
  EXPECT_EQ(Names(dir_ / "real"), std::set<std::string>{"new.csv"});
  EXPECT_EQ(Names(dir_), (std::set<std::string>{"link", "real"}));
}

TEST_F(AtomicFileTest, NewFolderAppearsWithItsFiles) {
  WriteFolderAtomically(
      dir_ / "deeper" / "out" / "", [](const fs::path& partial) { Write(partial / "x.csv", "x"); },
      [](const std::string&) { return false; });
  EXPECT_EQ(Read(dir_ / "deeper" / "out" / "x.csv"), "x");
  EXPECT_EQ(Names(dir_ / "deeper"), std::set<std::string>{"out"});
}

TEST_F(AtomicFileTest, FailingFillLeavesTheOldFolderAndNoPartial) {
  const fs::path out = dir_ / "report";
  fs::create_directories(out);
  Write(out / "index.html", "old");
  EXPECT_THROW(WriteFolderAtomically(
                   out,
                   [](const fs::path& partial) {
                     Write(partial / "index.html", "half");
                     throw Error(ErrorKind::kInternal, "the analysis stopped");
                   },
                   [](const std::string&) { return true; }),
               Error);
  EXPECT_EQ(Names(out), std::set<std::string>{"index.html"});
  EXPECT_EQ(Read(out / "index.html"), "old");
  EXPECT_EQ(Names(dir_), std::set<std::string>{"report"});
}

TEST_F(AtomicFileTest, FolderOfOtherFilesIsRefusedUntouched) {
  const fs::path out = dir_ / "results";
  fs::create_directories(out);
  Write(out / "trials.csv", "old");
  Write(out / "study.sqlite", "precious");
  bool filled = false;
  ExpectInputErrorNaming(
      [&] {
        WriteFolderAtomically(
            out, [&](const fs::path&) { filled = true; }, [](const std::string& name) { return name == "trials.csv"; });
      },
      "holds study.sqlite");
  EXPECT_FALSE(filled);
  EXPECT_EQ(Read(out / "study.sqlite"), "precious");
  EXPECT_EQ(Names(dir_), std::set<std::string>{"results"});
}

TEST_F(AtomicFileTest, KilledFolderWriteLeavesTheOldFolderAndALeftoverTheNextRunRemoves) {
  const fs::path out = dir_ / "tables";
  fs::create_directories(out);
  Write(out / "trials.csv", "old trials");
  Write(out / "frames.csv", "old frames");
  const pid_t child = fork();
  if (child == 0) {
    WriteFolderAtomically(
        out,
        [](const fs::path& partial) {
          Write(partial / "trials.csv", "new trials");
          Write(partial / "ready", "");
          for (;;) pause();  // killed here: half of the new folder is written
        },
        [](const std::string&) { return true; });
    _exit(0);
  }
  const fs::path partial = dir_ / (".tables.partial-" + std::to_string(child));
  for (int i = 0; i < 2000 && !fs::exists(partial / "ready"); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_TRUE(fs::exists(partial / "ready"));
  kill(child, SIGKILL);
  waitpid(child, nullptr, 0);

  EXPECT_EQ(Read(out / "trials.csv"), "old trials");
  EXPECT_EQ(Read(out / "frames.csv"), "old frames");
  EXPECT_EQ(Names(dir_), (std::set<std::string>{"tables", partial.filename().string()}));
  EXPECT_EQ(RemoveStaleLeftovers(out), std::vector<fs::path>{partial});
  EXPECT_EQ(Names(dir_), std::set<std::string>{"tables"});
}

TEST_F(AtomicFileTest, StaleLeftoversOfDeadProcessesAreRemovedOthersKept) {
  const std::string dead = std::to_string(DeadPid());
  const std::string alive = std::to_string(getppid());
  const fs::path out = dir_ / "all.sqlite";
  const std::set<std::string> stale = {".all.sqlite.partial-" + dead, ".all.sqlite.partial-" + dead + "-wal",
                                       ".all.sqlite.tmp-" + dead,     "all.sqlite.partial" + dead,
                                       "all.sqlite.partial" + dead + "-shm", "all.sqlite.tmp" + dead};
  const std::set<std::string> kept = {"all.sqlite",
                                      ".all.sqlite.partial-" + alive,  // a merge still running
                                      ".other.sqlite.partial-" + dead, // another target's
                                      ".all.sqlite.partial-" + dead + "-notes", "all.sqlite.partial", "all.sqlite.tmp"};
  for (const auto& name : stale) Write(dir_ / name, "x");
  for (const auto& name : kept) Write(dir_ / name, "x");
  const std::string folder = ".all.sqlite.old-" + dead;  // a replaced folder, half removed
  fs::create_directories(dir_ / folder / "inside");
  std::set<std::string> removed;
  for (const auto& path : RemoveStaleLeftovers(out)) removed.insert(path.filename().string());
  std::set<std::string> expected = stale;
  expected.insert(folder);
  EXPECT_EQ(removed, expected);
  EXPECT_EQ(Names(dir_), kept);
}

TEST_F(AtomicFileTest, MoveIntoPlaceNeverOverwrites) {
  const fs::path temp = dir_ / ".out.sqlite.partial-1", out = dir_ / "out.sqlite";
  Write(temp, "new");
  Write(out, "old");
  ExpectInputErrorNaming([&] { MoveIntoPlace(temp, out); }, out.string() + ": exists; not overwritten");
  EXPECT_EQ(Read(out), "old");
  EXPECT_EQ(Read(temp), "new");
  fs::remove(out);
  MoveIntoPlace(temp, out);
  EXPECT_EQ(Read(out), "new");
  EXPECT_EQ(Names(dir_), std::set<std::string>{"out.sqlite"});
}

}  // namespace
}  // namespace blurcue
