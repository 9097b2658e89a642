#include "core/image.h"

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
  auto path = std::filesystem::temp_directory_path() / "blurcue_not_an_image.png";
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
  auto path = std::filesystem::temp_directory_path() / "blurcue_rw" / "a.png";
  cv::Mat img(4, 5, CV_8UC3, cv::Scalar(10, 20, 30));
  WriteImage(path, img);
  cv::Mat back = ReadImage(path);
  EXPECT_EQ(cv::norm(img, back, cv::NORM_INF), 0);
  std::filesystem::remove_all(path.parent_path());
}

}  // namespace
}  // namespace blurcue
