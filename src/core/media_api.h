#pragma once
// The table of functions libblurcue_media.so gives core/media.cc (both built from this tree by one compiler, so C++
// types cross; OpenCV's exceptions cross as they are). Internal: use core/media.h.
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace blurcue::media {

struct Api {
  int version;  // kApiVersion
  cv::Mat (*imread)(const std::string& path, int flags);
  bool (*imencode)(const std::string& ext, const cv::Mat& image, std::vector<uchar>* bytes, const std::vector<int>& params);
  cv::Mat (*imdecode)(const std::vector<uchar>& bytes, int flags);
  void* (*reader_open)(const std::string& path, int api_preference);  // nullptr when it cannot open
  double (*reader_get)(void* reader, int property);
  bool (*reader_read)(void* reader, cv::Mat* frame);
  void (*reader_close)(void* reader);
  void* (*writer_open)(const std::string& path, int fourcc, double fps, cv::Size size);  // nullptr when it cannot
  void (*writer_write)(void* writer, const cv::Mat& frame);
  void (*writer_close)(void* writer);
};
constexpr int kApiVersion = 1;
// The plugin's one symbol.
constexpr const char* kApiSymbol = "blurcue_media_api";
using ApiFunction = const Api* (*)();

}  // namespace blurcue::media
