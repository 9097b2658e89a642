#include "scene/frame.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace blurcue::scene {

FrameView FrameView::Identity(int photo_width_px, int photo_height_px) {
  return {photo_width_px, photo_height_px, photo_width_px, photo_height_px, 0, 0};
}

Camera FrameView::CameraOf(const Camera& c) const {
  return c.Viewed(double(photo_width_px) / c.image_width_px, double(photo_height_px) / c.image_height_px, x_px, y_px,
                  width_px, height_px);
}

double FitScale(int src_w, int src_h, int width_px, int height_px) {
  const double scale = std::min(double(width_px) / src_w, double(height_px) / src_h);
  return double(int(src_w * scale)) / src_w;
}

double ButterworthEquivalentSigma(double cutoff) { return std::sqrt(std::log(2.0) / 2) / (M_PI * cutoff); }

int ScaledWidthPx(cv::Size picture, int height_px) {
  return std::max(1, int(std::lround(double(picture.width) * height_px / picture.height)));
}

cv::Rect LayerOnField(cv::Size field, cv::Size layer) {
  return {(field.width - layer.width) / 2, (field.height - layer.height) / 2, layer.width, layer.height};
}

int GreyMarginPx(cv::Size scaled) { return std::max(scaled.width, scaled.height) / 4; }

namespace {

// Where PictureOnGrey puts a picture of `picture` size scaled to height_px on a `field`: its outline before the blur
// spreads it, with the drawing's own rounding.
cv::Rect PictureRectOnGrey(cv::Size picture, cv::Size field, int height_px) {
  const cv::Size scaled(ScaledWidthPx(picture, height_px), height_px);
  const int m = GreyMarginPx(scaled);
  const cv::Rect layer = LayerOnField(field, {scaled.width + 2 * m, scaled.height + 2 * m});
  return {layer.x + m, layer.y + m, scaled.width, scaled.height};
}

}  // namespace

DepthMatchingLayout DepthMatchingLayout::Of(int width_px, cv::Size picture) {
  DepthMatchingLayout l;
  const int h = width_px * 3 / 4, half = h / 2;
  l.frame = {width_px, h};
  l.upper = {0, 0, width_px, half};
  if (!picture.empty()) l.picture = PictureRectOnGrey(picture, l.upper.size(), half * 6 / 10);
  l.lower = {0, half, width_px, h - half};
  return l;
}

double DepthMatchingLayout::LowerScale(cv::Size photo) const {
  return std::max(double(lower.width) / photo.width, double(lower.height) / photo.height);
}

cv::Mat DepthMatchingLayout::LowerHalf(const cv::Mat& photo) const {
  const double scale = LowerScale(photo.size());
  cv::Mat scaled;
  cv::resize(photo, scaled, cv::Size(), scale, scale, cv::INTER_AREA);
  return scaled(cv::Rect((scaled.cols - lower.width) / 2, (scaled.rows - lower.height) / 2, lower.width,
                         lower.height)).clone();
}

}  // namespace blurcue::scene
