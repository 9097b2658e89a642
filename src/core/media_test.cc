// The media plugin (src/media, loaded by core/media.cc): image encoding and a lossless video written and read back,
// checked against the pixels put in - not against another call of the same code.
#include "core/media.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "core/temp_dir_test_util.h"

namespace blurcue::media {
namespace {

class MediaTest : public test::TempDirTest {
 protected:
  MediaTest() : TempDirTest("blurcue_media_") {}
};

// A frame no codec can pass unchanged by accident: every pixel a function of its place and the frame.
cv::Mat Pattern(int frame, cv::Size size) {
  cv::Mat m(size, CV_8UC3);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      m.at<cv::Vec3b>(y, x) = cv::Vec3b(uchar((x * 7 + frame * 31) & 255), uchar((y * 5 + x) & 255),
                                        uchar((x ^ y) + frame * 3));
  return m;
}

TEST_F(MediaTest, PluginIsFoundAndNamed) {
  const std::string path = PluginPath();
  EXPECT_TRUE(std::filesystem::is_regular_file(path)) << path;
  EXPECT_NE(path.find("libblurcue_media.so"), std::string::npos) << path;
}

TEST_F(MediaTest, PngEncodesAndDecodesEveryPixel) {
  const cv::Mat image = Pattern(1, {37, 23});
  std::vector<uchar> bytes;
  ASSERT_TRUE(Imencode(".png", image, &bytes));
  // The PNG signature: the bytes are a PNG file, not some other encoding.
  ASSERT_GE(bytes.size(), 8u);
  EXPECT_EQ(bytes[0], 0x89);
  EXPECT_EQ(bytes[1], 'P');
  const cv::Mat back = Imdecode(bytes, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(back.size(), image.size());
  ASSERT_EQ(back.type(), CV_8UC3);
  EXPECT_EQ(cv::norm(back, image, cv::NORM_INF), 0);
  // And from a file, through imread.
  const std::filesystem::path file = dir_ / "p.png";
  std::ofstream(file, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  const cv::Mat read = Imread(file.string(), cv::IMREAD_COLOR);
  ASSERT_EQ(read.size(), image.size());
  EXPECT_EQ(cv::norm(read, image, cv::NORM_INF), 0);
}

TEST_F(MediaTest, UnreadableInputsAreEmptyNotErrors) {
  EXPECT_TRUE(Imread((dir_ / "missing.png").string(), cv::IMREAD_COLOR).empty());
  EXPECT_TRUE(Imdecode(std::vector<uchar>{1, 2, 3, 4}, cv::IMREAD_COLOR).empty());
  VideoReader reader;
  EXPECT_FALSE(reader.Open((dir_ / "missing.avi").string(), cv::CAP_FFMPEG));  // as track opens a video
  EXPECT_FALSE(reader.IsOpened());
  cv::Mat frame;
  EXPECT_FALSE(reader.Read(&frame));
}

TEST_F(MediaTest, LosslessVideoHoldsEveryFrameExactly) {
  const std::filesystem::path path = dir_ / "v.avi";
  const cv::Size size(64, 48);
  constexpr int kFrames = 5;
  {
    VideoWriter writer;
    ASSERT_TRUE(writer.Open(path.string(), Fourcc('F', 'F', 'V', '1'), 25, size)) << "no FFV1 writer";
    for (int f = 0; f < kFrames; ++f) writer.Write(Pattern(f, size));
    writer.Release();
    EXPECT_FALSE(writer.IsOpened());
  }
  ASSERT_GT(std::filesystem::file_size(path), 1000u);
  VideoReader reader;
  ASSERT_TRUE(reader.Open(path.string(), cv::CAP_FFMPEG));
  EXPECT_EQ(reader.Get(cv::CAP_PROP_FRAME_WIDTH), size.width);
  EXPECT_EQ(reader.Get(cv::CAP_PROP_FRAME_HEIGHT), size.height);
  EXPECT_NEAR(reader.Get(cv::CAP_PROP_FPS), 25, 1e-6);
  EXPECT_EQ(reader.Get(cv::CAP_PROP_FRAME_COUNT), kFrames);
  cv::Mat frame;
  for (int f = 0; f < kFrames; ++f) {
    ASSERT_TRUE(reader.Read(&frame)) << "frame " << f;
    ASSERT_EQ(frame.size(), size);
    EXPECT_EQ(cv::norm(frame, Pattern(f, size), cv::NORM_INF), 0) << "frame " << f << " differs";
  }
  EXPECT_FALSE(reader.Read(&frame)) << "a frame past the last";
}

}  // namespace
}  // namespace blurcue::media
