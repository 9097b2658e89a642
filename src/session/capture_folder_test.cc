// --capture's folder is checked before a session starts (issue 24): links are not followed, another capture or other
// files are not overwritten, and a folder that cannot be written stops the run before its first trial.
#include <sys/stat.h>

#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "core/error.h"
#include "session/runner.h"
#include "store/test_util.h"

namespace blurcue::session {
namespace {

namespace fs = std::filesystem;

std::string ErrorOf(const fs::path& dir, const std::string& participant = "P1") {
  try {
    CheckCaptureFolder(dir, "study", participant);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(CaptureFolder, NewOrEmptyFolderIsMadeAndTaken) {
  store::testing::TempDir dir;
  EXPECT_EQ(ErrorOf(dir / "new" / "shots"), "");
  EXPECT_TRUE(fs::is_directory(dir / "new" / "shots"));
  EXPECT_TRUE(fs::is_empty(dir / "new" / "shots"));  // the write probe is gone
}

TEST(CaptureFolder, ALinkIsNotFollowed) {
  store::testing::TempDir dir;
  fs::create_directories(dir / "elsewhere");
  fs::create_directory_symlink(dir / "elsewhere", dir / "link");
  EXPECT_NE(ErrorOf(dir / "link").find("--capture: is a symbolic link"), std::string::npos);
  fs::create_directories(dir / "shots");
  fs::create_symlink(dir / "elsewhere", dir / "shots" / "trial-0001.png");
  EXPECT_NE(ErrorOf(dir / "shots").find("holds a symbolic link, 'trial-0001.png'"), std::string::npos);
}

TEST(CaptureFolder, OnlyThisParticipantsEarlierCaptureMayBeThere) {
  store::testing::TempDir dir;
  fs::create_directories(dir / "shots");
  std::ofstream(dir / "shots" / "trial-0001.json") << R"({"protocol": "study", "participant": "P1"})";
  std::ofstream(dir / "shots" / "trial-0001.png") << "png";
  EXPECT_EQ(ErrorOf(dir / "shots", "P1"), "");  // a resumed session goes on in its own capture
  const std::string other = ErrorOf(dir / "shots", "P2");
  EXPECT_NE(other.find("holds the capture of participant P1 of study study (trial-0001.json), which this session "
                       "would overwrite"), std::string::npos) << other;
  std::ofstream(dir / "shots" / "notes.txt") << "mine";
  const std::string notes = ErrorOf(dir / "shots");
  EXPECT_NE(notes.find("holds 'notes.txt', which is not a capture"), std::string::npos) << notes;
}

TEST(CaptureFolder, ImagesWithoutACapturesJsonAreSomeonesOwn) {
  store::testing::TempDir dir;
  fs::create_directories(dir / "shots");
  std::ofstream(dir / "shots" / "trial-0001.png") << "my own photo";  // was overwritten by the first trial's frame
  const std::string own = ErrorOf(dir / "shots", "P1");
  EXPECT_NE(own.find("holds 'trial-0001.png' and no trial-NNNN.json: images, not a capture"), std::string::npos)
      << own;
}

TEST(CaptureFolder, AFolderThatCannotBeWrittenStopsBeforeTheSession) {
  store::testing::TempDir dir;
  fs::create_directories(dir / "shots");
  // Root writes into a 0555 folder anyway; a file where the folder should be cannot be written by anyone.
  std::ofstream(dir / "file") << "x";
  EXPECT_NE(ErrorOf(dir / "file").find("--capture: cannot make a folder here"), std::string::npos);
  if (geteuid() != 0) {
    ::chmod((dir / "shots").c_str(), 0555);
    EXPECT_NE(ErrorOf(dir / "shots").find("--capture: cannot write here"), std::string::npos);
    ::chmod((dir / "shots").c_str(), 0755);
  }
}

}  // namespace
}  // namespace blurcue::session
