#pragma once
// Text screens (instructions, breaks, pause) drawn with OpenCV's Hershey font on the study's grey.
#include <string>

#include <opencv2/core.hpp>

namespace blurcue::session {

// 8-bit sRGB BGR of `size`: a title, a body wrapped to the width, a footer line; empty texts are left out.
cv::Mat TextScreen(cv::Size size, const std::string& title, const std::string& body, const std::string& footer);
// The grey field with a fixation cross at its centre (about 0.5 deg on a 24-inch screen at 60 cm: 20 px a arm at
// 1080 px high, scaled with the display).
cv::Mat FixationScreen(cv::Size size);

// The response prompt's band (responses.prompt): `text` centred in light grey ink on the grey field, width_px x
// height_px (Presentation::prompt_band_px), shrunk to fit the width.
cv::Mat PromptBand(int width_px, int height_px, const std::string& text);

}  // namespace blurcue::session
