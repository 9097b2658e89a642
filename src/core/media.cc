#include "core/media.h"

#include <dlfcn.h>

#include <filesystem>
#include <mutex>

#include "core/data_dir.h"
#include "core/error.h"
#include "core/media_api.h"

namespace blurcue::media {
namespace {

constexpr const char* kPluginFile = "libblurcue_media.so";

struct Loaded {
  const Api* api = nullptr;
  std::string path;
};

// Beside an installed binary (PREFIX/bin/blurcue -> PREFIX/lib/blurcue/), else the build tree's copy.
Loaded Load() {
  std::vector<std::filesystem::path> places;
  if (const std::filesystem::path exe = ExecutableDir(); !exe.empty())
    places.push_back((exe.parent_path() / "lib" / "blurcue" / kPluginFile).lexically_normal());
  places.emplace_back(BLURCUE_MEDIA_BUILD_PATH);
  std::string looked, said;
  for (const std::filesystem::path& place : places) {
    looked += (looked.empty() ? "" : ", ") + place.string();
    std::error_code ec;
    if (!std::filesystem::is_regular_file(place, ec)) continue;
    void* handle = dlopen(place.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* why = dlerror();
      said = why ? why : "dlopen failed";
      continue;
    }
    auto function = reinterpret_cast<ApiFunction>(dlsym(handle, kApiSymbol));
    const Api* api = function ? function() : nullptr;
    if (api && api->version == kApiVersion) return Loaded{api, place.string()};
    said = place.string() + " is not this blurcue's image and video plugin";
  }
  throw Error(ErrorKind::kInternal, std::string("cannot load blurcue's image and video plugin ") + kPluginFile +
                                        " (looked in " + looked + (said.empty() ? "" : "; " + said) +
                                        "): reinstall blurcue");
}

const Loaded& Plugin() {
  static const Loaded loaded = Load();  // thread-safe; a failure throws and is retried on the next call
  return loaded;
}
const Api& A() { return *Plugin().api; }

}  // namespace

cv::Mat Imread(const std::string& path, int flags) { return A().imread(path, flags); }
bool Imencode(const std::string& ext, const cv::Mat& image, std::vector<uchar>* bytes, const std::vector<int>& params) {
  return A().imencode(ext, image, bytes, params);
}
cv::Mat Imdecode(const std::vector<uchar>& bytes, int flags) { return A().imdecode(bytes, flags); }
std::string PluginPath() { return Plugin().path; }

VideoReader::VideoReader() = default;
VideoReader::~VideoReader() {
  if (handle_) A().reader_close(handle_);
}
bool VideoReader::Open(const std::string& path, int api_preference) {
  if (handle_) A().reader_close(handle_), handle_ = nullptr;
  handle_ = A().reader_open(path, api_preference);
  return handle_ != nullptr;
}
bool VideoReader::IsOpened() const { return handle_ != nullptr; }
double VideoReader::Get(int property) const { return handle_ ? A().reader_get(handle_, property) : 0; }
bool VideoReader::Read(cv::Mat* frame) { return handle_ && A().reader_read(handle_, frame); }

VideoWriter::VideoWriter() = default;
VideoWriter::~VideoWriter() { Release(); }
bool VideoWriter::Open(const std::string& path, int fourcc, double fps, cv::Size size) {
  Release();
  handle_ = A().writer_open(path, fourcc, fps, size);
  return handle_ != nullptr;
}
void VideoWriter::Write(const cv::Mat& frame) {
  if (handle_) A().writer_write(handle_, frame);
}
void VideoWriter::Release() {
  if (handle_) A().writer_close(handle_), handle_ = nullptr;
}

}  // namespace blurcue::media
