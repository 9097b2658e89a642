#pragma once
// Text screens (instructions, breaks, pause) drawn with OpenCV's Hershey font on the study's grey.
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace blurcue::session {

// 8-bit sRGB BGR of `size`: a title, a body wrapped to the width, a footer line; empty texts are left out.
cv::Mat TextScreen(cv::Size size, const std::string& title, const std::string& body, const std::string& footer);

// Splits `text` into lines no wider than width_px at `scale` of the plain Hershey font.
std::vector<std::string> WrapText(const std::string& text, int width_px, double scale);

}  // namespace blurcue::session
