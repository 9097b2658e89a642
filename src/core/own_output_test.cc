#include "core/own_output.h"

#include <fstream>
#include <iterator>
#include <sstream>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/temp_dir_test_util.h"

namespace blurcue {
namespace {

namespace fs = std::filesystem;

class OwnOutputTest : public test::TempDirTest {
 protected:
  OwnOutputTest() : TempDirTest("blurcue_own_") {}
  void Write(const fs::path& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }
  std::string Read(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
  }
  // The message PlaceOwnFiles throws (its kind must be kInput), or "" when it places the files.
  std::string Place(const fs::path& partial) {
    try {
      PlaceOwnFiles("--out", dir_ / "out", partial, "tool.txt", "tool");
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::kInput);
      return e.what();
    }
    return "";
  }
};

TEST_F(OwnOutputTest, AFileOfAnotherKindIsNotReplacedAndItsFirstLineIsShown) {
  Write(dir_ / "protocol.json", "{\"task\": \"left_right\"}\n");
  try {
    RequireOwnFile("--log", dir_ / "protocol.json", "a log animate wrote", BeginsWith("frame,t_s\n"));
    FAIL() << "a protocol was taken for a log";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    EXPECT_NE(std::string(e.what()).find("--log " + (dir_ / "protocol.json").string() +
                                         ": exists and is not a log animate wrote (it begins \"{\"task\""),
              std::string::npos)
        << e.what();
  }
  Write(dir_ / "log.csv", "frame,t_s\n0,0\n");
  EXPECT_NO_THROW(RequireOwnFile("--log", dir_ / "log.csv", "a log", BeginsWith("frame,t_s\n")));
  EXPECT_NO_THROW(RequireOwnFile("--log", dir_ / "new.csv", "a log", BeginsWith("frame,t_s\n")));
  // A header that only starts like the log's is another table.
  Write(dir_ / "other.csv", "frame,t_s,extra\n");
  EXPECT_THROW(RequireOwnFile("--log", dir_ / "other.csv", "a log", BeginsWith("frame,t_s\n")), Error);
}

TEST_F(OwnOutputTest, AnImageIsToldByItsSignatureNotItsName) {
  Write(dir_ / "a.png", std::string("\x89PNG\r\n\x1a\n", 8) + "rest");
  Write(dir_ / "b.png", "\xff\xd8\xff\xe0 a JPEG named .png");
  Write(dir_ / "c.jpg", "\xff\xd8\xff\xe0");
  EXPECT_TRUE(ImageOfExtension(dir_ / "a.png")(Read(dir_ / "a.png")));
  EXPECT_FALSE(ImageOfExtension(dir_ / "b.png")(Read(dir_ / "b.png")));
  EXPECT_TRUE(ImageOfExtension(dir_ / "c.JPG")(Read(dir_ / "c.jpg")));
  EXPECT_FALSE(ImageOfExtension(dir_ / "x.json")("{}"));
  EXPECT_TRUE(AviFile()(std::string("RIFF\x10\0\0\0AVI LIST", 16)));
  EXPECT_FALSE(AviFile()(std::string("RIFF\x10\0\0\0WAVEfmt ", 16)));
}

TEST_F(OwnOutputTest, OnesOwnFileOfTheSameNameIsRefusedAndNothingMoves) {
  fs::create_directories(dir_ / "out");
  fs::create_directories(dir_ / "p1");
  Write(dir_ / "out" / "face.png", "my own face");
  Write(dir_ / "p1" / "face.png", "drawn face");
  Write(dir_ / "p1" / "grid.png", "drawn grid");
  const std::string message = Place(dir_ / "p1");
  EXPECT_NE(message.find("--out " + (dir_ / "out").string() + ": holds face.png, which tool did not write (its "
                         "tool.txt does not list it"),
            std::string::npos)
      << message;
  EXPECT_EQ(Read(dir_ / "out" / "face.png"), "my own face");
  EXPECT_FALSE(fs::exists(dir_ / "out" / "grid.png"));
  EXPECT_FALSE(fs::exists(dir_ / "out" / "tool.txt"));
}

TEST_F(OwnOutputTest, ItsOwnFilesAreReplacedUntilSomeoneChangesThem) {
  fs::create_directories(dir_ / "out");
  Write(dir_ / "out" / "README.md", "someone else's");
  for (const char* run : {"p1", "p2", "p3"}) {
    fs::create_directories(dir_ / run);
    Write(dir_ / run / "face.png", std::string("face of ") + run);
  }
  ASSERT_EQ(Place(dir_ / "p1"), "");
  ASSERT_EQ(Place(dir_ / "p2"), "");  // listed, unchanged: replaced
  EXPECT_EQ(Read(dir_ / "out" / "face.png"), "face of p2");
  EXPECT_EQ(Read(dir_ / "out" / "README.md"), "someone else's");
  Write(dir_ / "out" / "face.png", "edited by hand");
  EXPECT_NE(Place(dir_ / "p3").find("changed since tool wrote it"), std::string::npos);
  EXPECT_EQ(Read(dir_ / "out" / "face.png"), "edited by hand");
}

TEST_F(OwnOutputTest, TheSameBytesNeedNoListAndAForeignListIsRefused) {
  fs::create_directories(dir_ / "out");
  fs::create_directories(dir_ / "p1");
  Write(dir_ / "out" / "face.png", "drawn face");  // as a checked-in copy of the command's output
  Write(dir_ / "p1" / "face.png", "drawn face");
  EXPECT_EQ(Place(dir_ / "p1"), "");
  Write(dir_ / "out" / "tool.txt", "my notes\n");
  fs::create_directories(dir_ / "p2");
  Write(dir_ / "p2" / "face.png", "drawn face");
  EXPECT_NE(Place(dir_ / "p2").find("holds tool.txt, which tool did not write"), std::string::npos);
  EXPECT_EQ(Read(dir_ / "out" / "tool.txt"), "my notes\n");
}

// A file its writer opens by name is written beside its target: the target keeps its old bytes until Finish() (a
// kill before leaves them), and the partial folder is gone afterwards, finished or not.
TEST_F(OwnOutputTest, APartialFileReplacesItsTargetOnlyWhenFinished) {
  const fs::path target = dir_ / "clips" / "anim.avi";
  fs::create_directories(target.parent_path());
  Write(target, "old video");
  fs::path folder;
  {
    PartialFile unfinished(target);
    folder = unfinished.path().parent_path();
    EXPECT_EQ(unfinished.path().filename(), "anim.avi");  // the extension still names the container
    EXPECT_EQ(folder.parent_path(), target.parent_path());
    Write(unfinished.path(), "half a vid");
    EXPECT_EQ(Read(target), "old video");
  }
  EXPECT_FALSE(fs::exists(folder));
  EXPECT_EQ(Read(target), "old video");
  {
    PartialFile done(target);
    Write(done.path(), "new video");
    done.Finish();
    EXPECT_EQ(Read(target), "new video");
  }
  EXPECT_FALSE(fs::exists(folder));
  EXPECT_EQ(std::distance(fs::directory_iterator(target.parent_path()), fs::directory_iterator()), 1);
}

}  // namespace
}  // namespace blurcue
