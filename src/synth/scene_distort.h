#pragma once
// The synthetic scene through a distorting lens (synth/scene.cc): the ideal (pinhole) view is rendered and blurred
// on a canvas that covers every ray the photo sees, then warped onto the photo's pixels through camera.json's
// dist_coeffs exactly and area-downsampled there, as a sensor behind the lens would sample it. Internal to synth.
#include <vector>

#include <opencv2/core.hpp>

#include "core/distortion.h"

namespace blurcue::synth::detail {

// The ideal image's canvas: ideal px x in [-ox, width - ox) (and y likewise), with a margin for the interpolation.
struct IdealCanvas {
  int ox = 0, oy = 0, width = 0, height = 0;
};

// The canvas covering the ideal points of every pixel of a W x H photo (from its border: the maps a lens makes are
// monotone along rays), and at least the photo's own rectangle. Throws Error(kDomain) where the map cannot be undone.
IdealCanvas CanvasFor(const LensDistortion& distortion, int W, int H);

// Warps blurred sub-pixel images of the canvas ((canvas.height ss) x (canvas.width ss), CV_32F) onto the photo's
// sub-pixel grid (each photo sub-pixel centre undone to its ideal point, read with Keys' cubic, which reproduces
// quadratics and so adds no second moment to the blur) and area-downsamples by ss: H x W each.
std::vector<cv::Mat> DistortAndDownsample(const std::vector<cv::Mat>& ideal_ss, const LensDistortion& distortion,
                                          const IdealCanvas& canvas, int ss, int H, int W);

}  // namespace blurcue::synth::detail
