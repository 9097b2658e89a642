#include "core/image_integrity.h"

#include <unistd.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/error.h"
#include "core/image.h"

namespace blurcue {
namespace {

namespace fs = std::filesystem;

// A folder of this process's own (ctest runs test cases in parallel processes).
fs::path IntegrityFolder() {
  const fs::path dir = fs::temp_directory_path() / ("blurcue-integrity-test-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

std::string FileBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void WriteBytes(const fs::path& path, const std::string& bytes) { std::ofstream(path, std::ios::binary) << bytes; }

// A 320 x 240 photo-like image (a board-like pattern and noise, so that a JPEG has a long scan) written by OpenCV.
fs::path WrittenImage(const std::string& name) {
  cv::Mat image(240, 320, CV_8UC3);
  cv::RNG rng(7);
  rng.fill(image, cv::RNG::UNIFORM, 0, 40);
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x)
      if (((x / 40) + (y / 40)) % 2) image.at<cv::Vec3b>(y, x) += cv::Vec3b(200, 200, 200);
  const fs::path path = IntegrityFolder() / name;
  WriteImage(path, image);
  return path;
}

// ReadImage's error on `path`, which must be an input error; "" when it reads.
std::string ReadRefusal(const fs::path& path) {
  try {
    ReadImage(path);
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput) << e.what();
    return e.what();
  }
  return "";
}

bool Holds(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(ImageIntegrity, JpegCutAt75PercentIsRefusedNamingTheFile) {
  const fs::path good = WrittenImage("good.jpg");
  const std::string bytes = FileBytes(good);
  const fs::path cut = IntegrityFolder() / "cut.jpg";
  WriteBytes(cut, bytes.substr(0, bytes.size() * 3 / 4));
  const std::string what = ReadRefusal(cut);
  EXPECT_TRUE(Holds(what, cut.string() + ": truncated JPEG")) << what;
  EXPECT_TRUE(Holds(what, "FFD9")) << what;
  EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  EXPECT_EQ(ReadRefusal(good), "");  // the whole file still reads
}

TEST(ImageIntegrity, JpegWithoutItsEndMarkerIsRefused) {
  const std::string bytes = FileBytes(WrittenImage("whole.jpg"));
  ASSERT_EQ(bytes.substr(bytes.size() - 2), "\xff\xd9");
  const fs::path path = IntegrityFolder() / "no-eoi.jpg";
  WriteBytes(path, bytes.substr(0, bytes.size() - 2));
  EXPECT_TRUE(Holds(ReadRefusal(path), path.string() + ": truncated JPEG")) << ReadRefusal(path);
}

TEST(ImageIntegrity, JpegCutAndGivenAnEndMarkerIsRefusedOnTheDecodersWord) {
  // The cut hidden behind an EOI: the structure is whole, libjpeg says its data ended early.
  const std::string bytes = FileBytes(WrittenImage("whole2.jpg"));
  const fs::path path = IntegrityFolder() / "cut-eoi.jpg";
  WriteBytes(path, bytes.substr(0, bytes.size() * 3 / 4) + "\xff\xd9");
  const std::string what = ReadRefusal(path);
  EXPECT_TRUE(Holds(what, path.string() + ": damaged image")) << what;
}

TEST(ImageIntegrity, JpegWithBytesAfterItsEndStillReads) {
  // A phone's motion photo appends a video after the JPEG's EOI: the image itself is whole.
  const std::string bytes = FileBytes(WrittenImage("whole3.jpg"));
  const fs::path path = IntegrityFolder() / "appended.jpg";
  WriteBytes(path, bytes + std::string(1000, '\x42'));
  EXPECT_EQ(ReadRefusal(path), "");
}

TEST(ImageIntegrity, PngCutAt75PercentIsRefusedNamingTheFile) {
  const fs::path good = WrittenImage("good.png");
  const std::string bytes = FileBytes(good);
  const fs::path cut = IntegrityFolder() / "cut.png";
  WriteBytes(cut, bytes.substr(0, bytes.size() * 3 / 4));
  const std::string what = ReadRefusal(cut);
  EXPECT_TRUE(Holds(what, cut.string() + ": truncated PNG")) << what;
  EXPECT_EQ(ReadRefusal(good), "");
}

TEST(ImageIntegrity, PngWithAFlippedByteFailsItsChunkCrc) {
  const std::string bytes = FileBytes(WrittenImage("flip.png"));
  const size_t idat = bytes.find("IDAT");
  ASSERT_NE(idat, std::string::npos);
  std::string flipped = bytes;
  flipped[idat + 4 + 10] ^= 0x01;  // one bit of the compressed pixels
  const fs::path path = IntegrityFolder() / "flipped.png";
  WriteBytes(path, flipped);
  const std::string what = ReadRefusal(path);
  EXPECT_TRUE(Holds(what, path.string() + ": damaged PNG: chunk 'IDAT'")) << what;
  EXPECT_TRUE(Holds(what, "CRC-32")) << what;
}

TEST(ImageIntegrity, PngWithoutIendIsRefused) {
  const std::string bytes = FileBytes(WrittenImage("iend.png"));
  ASSERT_EQ(bytes.substr(bytes.size() - 8, 4), "IEND");
  const fs::path path = IntegrityFolder() / "no-iend.png";
  WriteBytes(path, bytes.substr(0, bytes.size() - 12));
  EXPECT_TRUE(Holds(ReadRefusal(path), path.string() + ": truncated PNG: the file ends")) << ReadRefusal(path);
}

TEST(ImageIntegrity, DecoderWarningsOfMissingDataMeanDamage) {
  EXPECT_TRUE(DecoderSaysDamaged("Premature end of JPEG file"));
  EXPECT_TRUE(DecoderSaysDamaged("Corrupt JPEG data: premature end of data segment"));
  EXPECT_TRUE(DecoderSaysDamaged("libpng warning: x; Corrupt JPEG data: bad Huffman code"));
  EXPECT_FALSE(DecoderSaysDamaged("Corrupt JPEG data: 2 extraneous bytes before marker 0xd9"));
  EXPECT_FALSE(DecoderSaysDamaged("libpng warning: iCCP: known incorrect sRGB profile"));
}

TEST(ImageIntegrity, OtherFormatsAreLeftToTheirDecoder) {
  EXPECT_NO_THROW(RequireIntactImage("x.bmp", "BM\x10\x00"));
  EXPECT_NO_THROW(RequireIntactImage("x.txt", ""));
}

}  // namespace
}  // namespace blurcue
