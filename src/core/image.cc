#include "core/image.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/atomic_file.h"
#include "core/error.h"

namespace blurcue {

cv::Mat ReadImage(const std::filesystem::path& path, int flags) {
  if (!std::filesystem::exists(path)) throw InputError(path.string(), "no such file");
  cv::Mat image = cv::imread(path.string(), flags);
  if (image.empty()) throw InputError(path.string(), "not a readable image (PNG, JPEG, TIFF, ...)");
  return image;
}

void WriteImage(const std::filesystem::path& path, const cv::Mat& image) {
  // Encoded in memory (OpenCV picks the encoder from the target's extension), then one atomic write.
  std::vector<uchar> bytes;
  bool ok = false;
  try {
    ok = cv::imencode(path.extension().string(), image, bytes);
  } catch (const cv::Exception& e) {
    throw InputError(path.string(), std::string("cannot encode image: ") + e.what());
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

cv::Mat ToGrey8(const cv::Mat& image) {
  if (image.channels() == 1) return image;
  cv::Mat grey;
  cv::cvtColor(image, grey, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  return grey;
}

}  // namespace blurcue
