#include "core/image.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

#include <opencv2/imgproc.hpp>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/image_integrity.h"
#include "core/limits.h"

namespace blurcue {

namespace {

// What a path is when it is not a regular file, for the message.
std::string KindOfNonRegular(std::filesystem::file_type type) {
  switch (type) {
    case std::filesystem::file_type::directory: return "a directory";
    case std::filesystem::file_type::character: return "a character device";
    case std::filesystem::file_type::block: return "a block device";
    case std::filesystem::file_type::fifo: return "a pipe";
    case std::filesystem::file_type::socket: return "a socket";
    case std::filesystem::file_type::none:
    case std::filesystem::file_type::not_found:
    case std::filesystem::file_type::regular:
    case std::filesystem::file_type::symlink:
    case std::filesystem::file_type::unknown: break;
  }
  return "not a regular file";
}

uint32_t BigEndian(const std::vector<uint8_t>& b, size_t at, int bytes) {
  uint32_t v = 0;
  for (int i = 0; i < bytes; ++i) v = (v << 8) | b[at + i];
  return v;
}

// Width and height from a PNG's IHDR or a JPEG's start-of-frame, without decoding; {0, 0} for other formats or
// a header too short to say (the decoder then has its say, and the size is checked after decoding).
std::pair<uint32_t, uint32_t> HeaderSizePx(const std::vector<uint8_t>& b) {
  static const uint8_t kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (b.size() >= 24 && std::equal(kPng, kPng + 8, b.begin()) && std::equal(b.begin() + 12, b.begin() + 16, "IHDR"))
    return {BigEndian(b, 16, 4), BigEndian(b, 20, 4)};
  if (b.size() < 4 || b[0] != 0xff || b[1] != 0xd8) return {0, 0};
  // JPEG: walk the marker segments up to the first start-of-frame (C0..CF but DHT C4, JPG C8, DAC CC).
  size_t i = 2;
  while (i + 4 <= b.size()) {
    if (b[i] != 0xff) return {0, 0};
    const uint8_t marker = b[i + 1];
    if (marker == 0xff) { ++i; continue; }  // fill byte
    if (marker == 0x01 || (marker >= 0xd0 && marker <= 0xd7)) { i += 2; continue; }  // no length
    if (marker == 0xda || marker == 0xd9) return {0, 0};  // scan data or end before any frame header
    const uint32_t length = BigEndian(b, i + 2, 2);
    const bool sof = marker >= 0xc0 && marker <= 0xcf && marker != 0xc4 && marker != 0xc8 && marker != 0xcc;
    if (sof && i + 9 <= b.size()) return {BigEndian(b, i + 7, 2), BigEndian(b, i + 5, 2)};
    i += 2 + length;
  }
  return {0, 0};
}

std::string SizeLimitText() {
  return "images are read up to " + std::to_string(kMaxImageSidePx) + " px a side and " +
         std::to_string(kMaxImagePixels / 1'000'000) + " Mpx";
}

void RequireSizeWithinLimits(const std::filesystem::path& path, uint64_t w, uint64_t h) {
  if (w > uint64_t(kMaxImageSidePx) || h > uint64_t(kMaxImageSidePx) || w * h > uint64_t(kMaxImagePixels))
    throw InputError(path.string(), "is " + std::to_string(w) + " x " + std::to_string(h) + " px; " + SizeLimitText());
}

// Redirects fd 2 into a temporary file while it lives. OpenCV's PNG decoder lets libpng print its warnings
// ("libpng warning: iCCP: known incorrect sRGB profile") straight to stderr, and the JPEG decoder does the same with
// libjpeg's; a command's output must stay its own lines and an error one line. Release() restores fd 2 and returns
// what was written meanwhile. Images are read on one thread at a time here (the mutex makes sure of it).
class CapturedStderr {
 public:
  CapturedStderr() : lock_(Mutex()) {
    std::fflush(stderr);
    file_ = std::tmpfile();
    saved_ = file_ ? dup(2) : -1;
    if (saved_ >= 0 && dup2(fileno(file_), 2) < 0) close(saved_), saved_ = -1;
  }
  ~CapturedStderr() { Release(); }
  CapturedStderr(const CapturedStderr&) = delete;
  CapturedStderr& operator=(const CapturedStderr&) = delete;

  std::string Release() {
    std::string text;
    if (saved_ >= 0) {
      std::fflush(stderr);
      dup2(saved_, 2);
      close(saved_);
      saved_ = -1;
      std::rewind(file_);
      char buffer[512];
      size_t n;
      while (text.size() < 4096 && (n = std::fread(buffer, 1, sizeof buffer, file_)) > 0) text.append(buffer, n);
    }
    if (file_) std::fclose(file_), file_ = nullptr;
    return text;
  }

 private:
  static std::mutex& Mutex() {
    static std::mutex m;
    return m;
  }
  std::lock_guard<std::mutex> lock_;
  std::FILE* file_ = nullptr;
  int saved_ = -1;
};

// The decoder's own words as one clause: lines joined by "; ", at most 300 characters.
std::string DecoderClause(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '\n' || c == '\r') {
      if (!out.empty() && out.back() != ' ') out += "; ";
    } else {
      out += c;
    }
  }
  while (!out.empty() && (out.back() == ' ' || out.back() == ';')) out.pop_back();
  return out.size() > 300 ? out.substr(0, 297) + "..." : out;
}

}  // namespace

void RequireImageFileWhole(const std::filesystem::path& path) {
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) throw InputError(path.string(), "no such file");
  // A directory, /dev/zero or a pipe is no image: refuse it before a decoder reads forever or says nothing useful.
  if (!std::filesystem::is_regular_file(status))
    throw InputError(path.string(), "is " + KindOfNonRegular(status.type()) + ", not an image file");
  const uintmax_t bytes = std::filesystem::file_size(path, ec);
  if (ec) throw InputError(path.string(), "cannot read file: " + ec.message());
  if (bytes > uintmax_t(kMaxImageFileBytes))
    throw InputError(path.string(), "is " + std::to_string(bytes) + " bytes; image files are read up to " +
                                        std::to_string(kMaxImageFileBytes) + " bytes");
  // The size from the header first, so a hostile 65535 x 65535 PNG is refused before it is decoded; then a JPEG or
  // PNG is checked whole for damage (core/image_integrity.h): a cut one decodes with grey fill and no error. Other
  // formats' bytes past the header are left to their decoder. The decoder reads the file again from the page cache
  // (~1 ms per 4 MB; imdecode from these bytes would skip imread's EXIF orientation handling on some OpenCV versions).
  std::ifstream in(path, std::ios::binary);
  std::vector<uint8_t> head(std::min<uintmax_t>(bytes, 1 << 20));
  if (!in.read(reinterpret_cast<char*>(head.data()), std::streamsize(head.size())))
    throw InputError(path.string(), "cannot read file");
  const auto [w, h] = HeaderSizePx(head);
  RequireSizeWithinLimits(path, w, h);
  const bool checked = head.size() >= 3 && ((head[0] == 0x89 && head[1] == 'P' && head[2] == 'N') ||
                                            (head[0] == 0xff && head[1] == 0xd8 && head[2] == 0xff));
  if (checked && bytes > head.size()) {
    head.resize(bytes);
    if (!in.read(reinterpret_cast<char*>(head.data()) + (1 << 20), std::streamsize(bytes - (1 << 20))))
      throw InputError(path.string(), "cannot read file");
  }
  if (checked) RequireIntactImage(path, std::string_view(reinterpret_cast<const char*>(head.data()), head.size()));
}

cv::Mat ReadImage(const std::filesystem::path& path, int flags) {
  RequireImageFileWhole(path);
  cv::Mat image;
  std::string decoder_said;
  {
    CapturedStderr captured;
    try {
      image = media::Imread(path.string(), flags);
    } catch (const cv::Exception& e) {
      decoder_said = e.err;
    }
    decoder_said = DecoderClause(captured.Release() + decoder_said);
  }
  if (image.empty())
    throw InputError(path.string(), "not a readable image (PNG, JPEG, TIFF, ...)" +
                                        (decoder_said.empty() ? "" : ": " + decoder_said));
  if (DecoderSaysDamaged(decoder_said))
    throw InputError(path.string(), "damaged image: its decoder filled in pixels it could not read (" + decoder_said +
                                        ")");
  RequireSizeWithinLimits(path, image.cols, image.rows);
  // Everything downstream is 8-bit sRGB: a 16-bit PNG or TIFF (read unchanged) is scaled to 8 bits (65535 -> 255), and
  // a float or other depth is refused here rather than by an OpenCV assertion in the renderer (exit 10).
  if (image.depth() == CV_16U) {
    image.convertTo(image, CV_8U, 1.0 / 257.0);
  } else if (image.depth() != CV_8U) {
    throw InputError(path.string(), "has " + std::to_string(8 * int(image.elemSize1())) +
                                        "-bit samples that are not integers of 8 or 16 bits; save it as an 8- or "
                                        "16-bit PNG or JPEG");
  }
  return image;
}

void RequireImageName(const std::string& option, const std::filesystem::path& path) {
  std::vector<uchar> bytes;
  bool ok = false;
  try {
    ok = media::Imencode(path.extension().string(), cv::Mat(1, 1, CV_8UC3, cv::Scalar::all(0)), &bytes);
  } catch (const cv::Exception&) {
  }
  if (!ok)
    throw Error(ErrorKind::kUsage, option + " " + path.string() + ": no image can be written as '" +
                                       path.extension().string() + "': " + kImageNameHint);
}

void WriteImage(const std::filesystem::path& path, const cv::Mat& image) {
  // Encoded in memory (OpenCV picks the encoder from the target's extension), then one atomic write.
  std::vector<uchar> bytes;
  bool ok = false;
  try {
    ok = media::Imencode(path.extension().string(), image, &bytes);
  } catch (const cv::Exception&) {
    // OpenCV's own text runs over several lines and names its source file: say what the user can change instead.
    throw InputError(path.string(), "cannot encode an image as '" + path.extension().string() +
                                        "': " + kImageNameHint);
  }
  if (!ok) throw InputError(path.string(), "cannot encode image");
  WriteFileAtomically(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

double SrgbToLinear(double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); }
double LinearToSrgb(double v) {
  v = std::clamp(v, 0.0, 1.0);
  return v <= 0.0031308 ? v * 12.92 : 1.055 * std::pow(v, 1 / 2.4) - 0.055;
}

const std::array<float, 256>& SrgbDecodeTable() {
  static const std::array<float, 256> lut = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) t[i] = static_cast<float>(SrgbToLinear(i / 255.0));
    return t;
  }();
  return lut;
}

cv::Mat DecodeSrgb8(const cv::Mat& srgb8) {
  CV_Assert(srgb8.depth() == CV_8U);
  const std::array<float, 256>& lut = SrgbDecodeTable();
  cv::Mat out(srgb8.size(), CV_MAKETYPE(CV_32F, srgb8.channels()));
  const int n = srgb8.cols * srgb8.channels();
  for (int y = 0; y < srgb8.rows; ++y) {
    const uint8_t* s = srgb8.ptr<uint8_t>(y);
    float* d = out.ptr<float>(y);
    for (int i = 0; i < n; ++i) d[i] = lut[s[i]];
  }
  return out;
}

cv::Mat EncodeSrgb8(const cv::Mat& linear) {
  CV_Assert(linear.depth() == CV_32F);
  // 65536-step table over [0, 1]: finer than 8-bit output needs near black, where sRGB is steepest.
  constexpr int kSteps = 65536;
  static const std::array<uint8_t, kSteps + 1> lut = [] {
    std::array<uint8_t, kSteps + 1> t{};
    for (int i = 0; i <= kSteps; ++i) t[i] = static_cast<uint8_t>(std::lround(255.0 * LinearToSrgb(double(i) / kSteps)));
    return t;
  }();
  cv::Mat out(linear.size(), CV_MAKETYPE(CV_8U, linear.channels()));
  const int n = linear.cols * linear.channels();
  for (int y = 0; y < linear.rows; ++y) {
    const float* s = linear.ptr<float>(y);
    uint8_t* d = out.ptr<uint8_t>(y);
    for (int i = 0; i < n; ++i) {
      const float v = s[i] <= 0.f ? 0.f : (s[i] >= 1.f ? 1.f : s[i]);
      // Near black the table is too coarse for exact rounding; compute directly there.
      d[i] = v < 0.002f ? static_cast<uint8_t>(std::lround(255.0 * LinearToSrgb(v))) : lut[std::lround(v * kSteps)];
    }
  }
  return out;
}

cv::Mat ResampleSrgb8(const cv::Mat& srgb8, cv::Size size) {
  CV_Assert(srgb8.depth() == CV_8U && srgb8.channels() != 4 && size.width > 0 && size.height > 0);  // no alpha
  if (srgb8.size() == size) return srgb8.clone();
  cv::Mat resampled;
  cv::resize(DecodeSrgb8(srgb8), resampled, size, 0, 0, cv::INTER_AREA);
  return EncodeSrgb8(resampled);
}

cv::Mat ToGrey8(const cv::Mat& image) {
  cv::Mat grey;
  ToGrey8(image, grey);
  return grey;
}

void ToGrey8(const cv::Mat& image, cv::Mat& grey) {
  if (image.channels() == 1) {
    grey = image;
    return;
  }
  cv::cvtColor(image, grey, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
}

const char* OpenLosslessVideo(media::VideoWriter& video, const std::filesystem::path& path, double fps, cv::Size size) {
  for (const char* codec : {"FFV1", "MJPG"}) {
    if (video.Open(path.string(), media::Fourcc(codec[0], codec[1], codec[2], codec[3]), fps, size)) return codec;
  }
  return nullptr;
}

}  // namespace blurcue
