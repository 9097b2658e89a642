#include "core/output_guard.h"

#include <sys/stat.h>
#include <unistd.h>

#include <fstream>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/temp_dir_test_util.h"

namespace blurcue {
namespace {

namespace fs = std::filesystem;

class OutputGuardTest : public test::TempDirTest {
 protected:
  OutputGuardTest() : TempDirTest("blurcue_guard_") {}
  void Write(const fs::path& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }
  // The kind and message of what Check() throws; kInternal and "" when it passes.
  std::pair<ErrorKind, std::string> Refusal(const OutputGuard& guard) {
    try {
      guard.Check();
    } catch (const Error& e) {
      return {e.kind(), e.what()};
    }
    return {ErrorKind::kInternal, ""};
  }
};

TEST_F(OutputGuardTest, AnOutputThatIsAnInputIsRefused) {
  Write(dir_ / "take.avi", "frames");
  fs::create_symlink(dir_ / "take.avi", dir_ / "link.avi");
  const auto [kind, message] = Refusal(OutputGuard().Input("INPUT", dir_ / "take.avi").OutputFile("--out", dir_ / "link.avi"));
  EXPECT_EQ(kind, ErrorKind::kUsage);
  EXPECT_NE(message.find("--out " + (dir_ / "link.avi").string() + ": is also the input INPUT"), std::string::npos)
      << message;
}

TEST_F(OutputGuardTest, AFolderHoldingAnInputOrInsideAnInputFolderIsRefused) {
  fs::create_directories(dir_ / "frames");
  Write(dir_ / "frames" / "frame-0000.png", "png");
  EXPECT_EQ(Refusal(OutputGuard().Input("INPUT", dir_ / "frames" / "frame-0000.png").OutputFolder("--frames", dir_ / "frames")).first,
            ErrorKind::kUsage);
  EXPECT_EQ(Refusal(OutputGuard().Input("--track", dir_ / "frames").OutputFile("--out", dir_ / "frames" / "x.avi")).first,
            ErrorKind::kUsage);
  EXPECT_EQ(Refusal(OutputGuard().Input("--track", dir_ / "frames").OutputFile("--out", dir_ / "x.avi")).first,
            ErrorKind::kInternal);
}

TEST_F(OutputGuardTest, TwoOutputsOnOnePathAreRefused) {
  const auto [kind, message] =
      Refusal(OutputGuard().OutputFile("--out", dir_ / "g.avi").OutputFile("--csv", dir_ / "." / "g.avi"));
  EXPECT_EQ(kind, ErrorKind::kUsage);
  EXPECT_NE(message.find("is also --out"), std::string::npos) << message;
}

TEST_F(OutputGuardTest, ARecordIsNotReplacedByACommandThatWritesNone) {
  Write(dir_ / "study.sqlite", std::string("SQLite format 3\0rest", 20));
  EXPECT_EQ(Refusal(OutputGuard().OutputFile("--csv", dir_ / "study.sqlite")).first, ErrorKind::kInput);
  EXPECT_EQ(Refusal(OutputGuard().OutputFile("--db", dir_ / "study.sqlite", true)).first, ErrorKind::kInternal);
}

TEST_F(OutputGuardTest, AnOutputOfAnotherKindIsRefused) {
  Write(dir_ / "afile", "x");
  fs::create_directories(dir_ / "folder");
  fs::create_symlink(dir_ / "nowhere", dir_ / "dangling");
  ASSERT_EQ(mkfifo((dir_ / "fifo").c_str(), 0600), 0);
  for (const auto& [path, folder] : std::vector<std::pair<fs::path, bool>>{{dir_ / "afile", true},
                                                                         {dir_ / "folder", false},
                                                                         {dir_ / "dangling", false},
                                                                         {dir_ / "fifo", false},
                                                                         {dir_ / "afile" / "x.avi", false},
                                                                         {dir_ / "afile" / "a" / "b", true},
                                                                         {"/proc/blurcue-x/out.csv", false}}) {
    OutputGuard guard;
    folder ? guard.OutputFolder("--out", path) : guard.OutputFile("--out", path);
    const auto [kind, message] = Refusal(guard);
    EXPECT_EQ(kind, ErrorKind::kInput) << path;
    EXPECT_NE(message.find(path.string()), std::string::npos) << message;
  }
  EXPECT_EQ(Refusal(OutputGuard().OutputFolder("--out", dir_ / "new" / "deeper")).first, ErrorKind::kInternal);
}

TEST_F(OutputGuardTest, AFifoInputIsRefusedAtOnce) {
  ASSERT_EQ(mkfifo((dir_ / "fifo").c_str(), 0600), 0);
  try {
    OutputGuard().Input("INPUT", dir_ / "fifo");
    FAIL() << "a FIFO was taken as an input";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    EXPECT_NE(std::string(e.what()).find("is a FIFO"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace blurcue
