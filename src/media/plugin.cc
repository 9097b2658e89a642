// libblurcue_media.so: OpenCV's imgcodecs and videoio behind core/media_api.h's table (see core/media.h for why).
#include <memory>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "core/media_api.h"

namespace blurcue::media {
namespace {

cv::Mat Imread(const std::string& path, int flags) { return cv::imread(path, flags); }
bool Imencode(const std::string& ext, const cv::Mat& image, std::vector<uchar>* bytes, const std::vector<int>& params) {
  return cv::imencode(ext, image, *bytes, params);
}
cv::Mat Imdecode(const std::vector<uchar>& bytes, int flags) { return cv::imdecode(bytes, flags); }

void* ReaderOpen(const std::string& path, int api_preference) {
  auto reader = std::make_unique<cv::VideoCapture>(path, api_preference);
  return reader->isOpened() ? reader.release() : nullptr;
}
double ReaderGet(void* reader, int property) { return static_cast<cv::VideoCapture*>(reader)->get(property); }
bool ReaderRead(void* reader, cv::Mat* frame) { return static_cast<cv::VideoCapture*>(reader)->read(*frame); }
void ReaderClose(void* reader) { delete static_cast<cv::VideoCapture*>(reader); }

void* WriterOpen(const std::string& path, int fourcc, double fps, cv::Size size) {
  auto writer = std::make_unique<cv::VideoWriter>(path, fourcc, fps, size);
  return writer->isOpened() ? writer.release() : nullptr;
}
void WriterWrite(void* writer, const cv::Mat& frame) { static_cast<cv::VideoWriter*>(writer)->write(frame); }
void WriterClose(void* writer) { delete static_cast<cv::VideoWriter*>(writer); }  // releases: the file is whole

const Api kApi = {kApiVersion, Imread,    Imencode,  Imdecode,   ReaderOpen,
                  ReaderGet,   ReaderRead, ReaderClose, WriterOpen, WriterWrite, WriterClose};

}  // namespace
}  // namespace blurcue::media

extern "C" __attribute__((visibility("default"))) const blurcue::media::Api* blurcue_media_api() {
  return &blurcue::media::kApi;
}
