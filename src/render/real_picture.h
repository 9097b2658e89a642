#pragma once
// The depth-matching study's real picture, photographed through the thin lens (no photos needed to try the study).
#include <opencv2/core.hpp>

#include "core/camera.h"

namespace blurcue::render {

// A photo of the real picture in the depth-matching study, made with the thin lens (no photos needed to try the
// study): `picture` (8-bit sRGB, alpha = its shape) picture_height_mm high, facing `camera` at distance_mm on the
// optical axis, imaged at magnification f / (u - f) and blurred by the disc of the thin-lens radius for a lens
// focused at focus_mm, over a uniform wall of linear grey `grey`, in linear light. 8-bit BGR sRGB at the camera's
// resolution. Throws Error(kDomain) for a distance or focus not beyond the focal length.
cv::Mat RealPicturePhoto(const cv::Mat& picture, const Camera& camera, double focus_mm, double distance_mm,
                         double picture_height_mm = 120, double grey = 0.18);

}  // namespace blurcue::render
