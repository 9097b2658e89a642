#include <unistd.h>
#include "core/image.h"
#include "blurcue/source_dir.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "core/error.h"

namespace blurcue {
namespace {

TEST(Srgb, KnownValues) {
  // IEC 61966-2-1: sRGB 0.5 is linear 0.2140; linear 0.5 encodes to 0.7354.
  EXPECT_NEAR(SrgbToLinear(0.5), 0.21404, 1e-4);
  EXPECT_NEAR(LinearToSrgb(0.5), 0.73536, 1e-4);
  EXPECT_NEAR(LinearToSrgb(SrgbToLinear(0.3)), 0.3, 1e-12);
}

TEST(Srgb, EightBitRoundTripIsExact) {
  cv::Mat ramp(1, 256, CV_8U);
  for (int i = 0; i < 256; ++i) ramp.at<uint8_t>(i) = static_cast<uint8_t>(i);
  cv::Mat back = EncodeSrgb8(DecodeSrgb8(ramp));
  EXPECT_EQ(cv::norm(ramp, back, cv::NORM_INF), 0);
}

TEST(ImageFile, UnreadableFileNamesTheFile) {
  auto path = std::filesystem::temp_directory_path() / ("blurcue_not_an_image_" + std::to_string(::getpid()) + ".png");
  { std::FILE* f = std::fopen(path.c_str(), "w"); std::fputs("hello", f); std::fclose(f); }
  try {
    ReadImage(path);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos);
  }
  std::filesystem::remove(path);
  EXPECT_THROW(ReadImage("/nonexistent/x.png"), Error);
}

TEST(ImageFile, WritesAndReadsBack) {
  auto path = std::filesystem::temp_directory_path() / ("blurcue_rw_" + std::to_string(::getpid())) / "a.png";
  cv::Mat img(4, 5, CV_8UC3, cv::Scalar(10, 20, 30));
  WriteImage(path, img);
  cv::Mat back = ReadImage(path);
  EXPECT_EQ(cv::norm(img, back, cv::NORM_INF), 0);
  std::filesystem::remove_all(path.parent_path());
}

// A 16-bit PNG (what a raw converter writes) reads as 8-bit sRGB, 65535 -> 255: every renderer and the blur take 8 bits
// (it was an OpenCV assertion, exit 10, in blur, render, ar and animate).
TEST(ImageFile, SixteenBitImageReadsAsEightBits) {
  auto path = std::filesystem::temp_directory_path() / ("blurcue_16_" + std::to_string(::getpid())) / "a.png";
  WriteImage(path, cv::Mat(4, 5, CV_16UC4, cv::Scalar(257 * 10, 257 * 128, 65535, 65535)));
  const cv::Mat back = ReadImage(path);  // unchanged: alpha and all
  ASSERT_EQ(back.depth(), CV_8U);
  ASSERT_EQ(back.channels(), 4);
  EXPECT_EQ(back.at<cv::Vec4b>(2, 3), cv::Vec4b(10, 128, 255, 255));
  EXPECT_EQ(ReadImage(path, 1 /* colour */).depth(), CV_8U);
  std::filesystem::remove_all(path.parent_path());
}

std::string ReadError(const std::filesystem::path& path) {
  try {
    ReadImage(path);
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput) << e.what();
    return e.what();
  }
  return "";
}

const std::filesystem::path kData = std::filesystem::path(BLURCUE_SOURCE_DIR) / "tests" / "data";

TEST(ImageFile, DirectoryAndDeviceAreRefusedNamingThePath) {
  const auto dir = std::filesystem::temp_directory_path();
  EXPECT_EQ(ReadError(dir), dir.string() + ": is a directory, not an image file");
  EXPECT_EQ(ReadError("/dev/zero"), "/dev/zero: is a character device, not an image file");
}

TEST(ImageFile, HugeHeaderIsRefusedBeforeDecoding) {
  // 66 bytes whose IHDR claims 65535 x 65535 px (tests/data/make_hostile_images.py).
  EXPECT_EQ(ReadError(kData / "huge-header.png"),
            (kData / "huge-header.png").string() +
                ": is 65535 x 65535 px; images are read up to 20000 px a side and 120 Mpx");
}

TEST(ImageFile, LibpngWarningsDoNotReachStderr) {
  // A valid image with a broken iCCP profile: libpng warns about it on fd 2 unless ReadImage keeps it off.
  testing::internal::CaptureStderr();
  const cv::Mat image = ReadImage(kData / "bad-iccp.png");
  const std::string said = testing::internal::GetCapturedStderr();
  EXPECT_EQ(image.cols, 16);
  EXPECT_EQ(image.rows, 12);
  EXPECT_EQ(said, "");
}

TEST(ImageFile, TruncatedImageIsOneLineAndNothingOnStderr) {
  testing::internal::CaptureStderr();
  const std::string what = ReadError(kData / "bad-iccp-truncated.png");
  const std::string said = testing::internal::GetCapturedStderr();
  EXPECT_EQ(said, "");
  EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  // Refused from its structure (core/image_integrity.h) before libpng is asked.
  EXPECT_NE(what.find("bad-iccp-truncated.png: truncated PNG"), std::string::npos) << what;
}

}  // namespace
}  // namespace blurcue
