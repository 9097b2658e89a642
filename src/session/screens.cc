#include "session/screens.h"

#include <sstream>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace blurcue::session {
namespace {
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
const cv::Scalar kGrey(118, 118, 118);  // sRGB 118 = linear 0.18, the grey the depth-matching field uses
const cv::Scalar kInk(245, 245, 245);

// Splits `text` into lines no wider than width_px at `scale` of the plain Hershey font.
std::vector<std::string> WrapText(const std::string& text, int width_px, double scale) {
  std::vector<std::string> lines;
  std::istringstream words(text);
  std::string word, line;
  int baseline = 0;
  while (words >> word) {
    const std::string candidate = line.empty() ? word : line + " " + word;
    if (!line.empty() && cv::getTextSize(candidate, kFont, scale, 1, &baseline).width > width_px) {
      lines.push_back(line);
      line = word;
    } else {
      line = candidate;
    }
  }
  if (!line.empty()) lines.push_back(line);
  return lines;
}

}  // namespace

cv::Mat TextScreen(cv::Size size, const std::string& title, const std::string& body, const std::string& footer) {
  cv::Mat image(size, CV_8UC3, kGrey);
  const double unit = size.height / 720.0;  // scales with the display
  const int margin = size.width / 10, width = size.width - 2 * margin;
  int y = size.height / 4;
  int baseline = 0;
  if (!title.empty()) {
    const double scale = 1.4 * unit;
    const cv::Size t = cv::getTextSize(title, kFont, scale, 2, &baseline);
    cv::putText(image, title, {(size.width - t.width) / 2, y}, kFont, scale, kInk, std::max(1, int(2 * unit)),
                cv::LINE_AA);
    y += int(t.height * 2.5);
  }
  const double scale = 0.8 * unit;
  for (const std::string& line : WrapText(body, width, scale)) {
    cv::putText(image, line, {margin, y}, kFont, scale, kInk, std::max(1, int(unit + 0.5)), cv::LINE_AA);
    y += int(36 * unit);
  }
  if (!footer.empty()) {
    const cv::Size t = cv::getTextSize(footer, kFont, 0.7 * unit, 1, &baseline);
    cv::putText(image, footer, {(size.width - t.width) / 2, size.height - int(60 * unit)}, kFont, 0.7 * unit,
                cv::Scalar(200, 200, 200), std::max(1, int(unit + 0.5)), cv::LINE_AA);
  }
  return image;
}

cv::Mat FixationScreen(cv::Size size) {
  cv::Mat image(size, CV_8UC3, kGrey);
  const int arm = std::max(4, size.height / 54), thick = std::max(1, size.height / 360);
  const cv::Point c(size.width / 2, size.height / 2);
  cv::line(image, c - cv::Point(arm, 0), c + cv::Point(arm, 0), kInk, thick, cv::LINE_AA);
  cv::line(image, c - cv::Point(0, arm), c + cv::Point(0, arm), kInk, thick, cv::LINE_AA);
  return image;
}

cv::Mat PromptBand(int width_px, int height_px, const std::string& text) {
  cv::Mat image(height_px, width_px, CV_8UC3, kGrey);
  int baseline = 0;
  double scale = 0.8 * height_px / 60.0;
  cv::Size t = cv::getTextSize(text, kFont, scale, 1, &baseline);
  if (t.width > width_px * 0.95) {
    scale *= width_px * 0.95 / t.width;
    t = cv::getTextSize(text, kFont, scale, 1, &baseline);
  }
  cv::putText(image, text, {(width_px - t.width) / 2, (height_px + t.height) / 2}, kFont, scale, kInk,
              std::max(1, int(scale + 0.5)), cv::LINE_AA);
  return image;
}

}  // namespace blurcue::session
