#pragma once
// Image files and videos through OpenCV's imgcodecs and videoio, which blurcue loads only when it first reads or
// writes one: the two modules pull ~210 shared libraries (GDAL, GDCM, FFmpeg, GStreamer, ...) into a process, and
// loading them is ~0.2-0.3 s of every start - most of a short command. They live in a plugin beside the binary
// (libblurcue_media.so: lib/blurcue/ of an installed blurcue, the build folder otherwise), opened on first use.
// The classes mirror OpenCV's; flags and properties are OpenCV's (cv::IMREAD_*, cv::IMWRITE_*, cv::CAP_PROP_*).
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace blurcue::media {

// cv::imread; empty when it cannot decode. Throws cv::Exception as OpenCV does; Error(kInternal) naming the plugin and
// where it was looked for when the plugin cannot be loaded.
cv::Mat Imread(const std::string& path, int flags);
// cv::imencode: `ext` such as ".png"; false when it cannot.
bool Imencode(const std::string& ext, const cv::Mat& image, std::vector<uchar>* bytes,
              const std::vector<int>& params = {});
// cv::imdecode; empty when it cannot.
cv::Mat Imdecode(const std::vector<uchar>& bytes, int flags);

// cv::VideoCapture of a file.
class VideoReader {
 public:
  VideoReader();
  ~VideoReader();
  VideoReader(const VideoReader&) = delete;
  VideoReader& operator=(const VideoReader&) = delete;
  // `api_preference`: cv::CAP_ANY (0), cv::CAP_FFMPEG, ...
  bool Open(const std::string& path, int api_preference = 0);
  bool IsOpened() const;
  double Get(int property) const;
  bool Read(cv::Mat* frame);

 private:
  void* handle_ = nullptr;
};

// cv::VideoWriter of a file.
class VideoWriter {
 public:
  VideoWriter();
  ~VideoWriter();
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;
  bool Open(const std::string& path, int fourcc, double fps, cv::Size size);
  bool IsOpened() const { return handle_ != nullptr; }
  void Write(const cv::Mat& frame);
  void Release();  // closes the file; the frames written so far make a whole video

 private:
  void* handle_ = nullptr;
};

// cv::VideoWriter::fourcc.
constexpr int Fourcc(char a, char b, char c, char d) {
  return (a & 255) | ((b & 255) << 8) | ((c & 255) << 16) | ((d & 255) << 24);
}

// Where the plugin was loaded from (loads it): for `blurcue info`.
std::string PluginPath();

}  // namespace blurcue::media
