#include "render/real_picture.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"
#include "core/limits.h"
#include "optics/thin_lens.h"
#include "render/blur.h"

namespace blurcue::render {

cv::Mat RealPicturePhoto(const cv::Mat& picture, const Camera& camera, double focus_mm, double distance_mm,
                         double picture_height_mm, double grey) {
  const optics::Lens lens = optics::Lens::FromCamera(camera);
  const double r_px = optics::BlurRadiusPx(lens, focus_mm, distance_mm);  // throws kDomain for u or focus <= f
  const double magnification = lens.focal_length_mm / (distance_mm - lens.focal_length_mm);
  const double height = picture_height_mm * magnification / lens.pixel_pitch_mm;
  // Just beyond f the picture fills more than any image and its blur passes any kernel: refuse before the
  // numbers reach an int.
  auto mm = [](double v) { return std::to_string(int(std::lround(std::min(v, 1e9)))) + " mm"; };
  if (!(height <= kMaxImageSidePx))
    throw Error(ErrorKind::kDomain, "a " + mm(picture_height_mm) + " picture at " + mm(distance_mm) +
                                        " would be imaged " + std::to_string(std::lround(std::min(height, 1e15))) +
                                        " px tall, more than the largest image (" + std::to_string(kMaxImageSidePx) +
                                        " px); place it farther from the lens");
  if (!(r_px <= kMaxBlurRadiusPx))
    throw Error(ErrorKind::kDomain, "a picture at " + mm(distance_mm) + " with the focus at " + mm(focus_mm) +
                                        " would be blurred by " + std::to_string(std::lround(std::min(r_px, 1e15))) +
                                        " px, more than the largest blur (" +
                                        std::to_string(int(kMaxBlurRadiusPx)) + " px)");
  const int height_px = std::max(2, int(std::lround(height)));
  auto disc = [r_px](const cv::Mat& layer, int) { return r_px >= 0.5 ? DiscBlurCpu(layer, r_px) : layer; };
  return PictureOnField(picture, cv::Size(camera.image_width_px, camera.image_height_px), height_px,
                        int(std::ceil(r_px)) + 2, disc, grey);
}

}  // namespace blurcue::render
