#pragma once
// The synthetic scene's depth blur (synth/scene.cc): kernels of exact line-spread variance per radius level, and the
// blur of a supersampled image by the radius each sub-pixel's ray calls for, area-downsampled. Internal to synth.
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "synth/scene.h"
#include "synth/scene_view.h"

namespace blurcue::synth::detail {

// ---------------------------------------------------------------------------------------------------------------
// Blur levels. Each level is a kernel at the supersampled resolution whose discrete line-spread variance is exactly
// var_ss (sub-pixels^2); per pixel the two levels around the wanted variance are mixed so that the mixture's variance
// is exactly r^2/4 (mixing is linear in variance). Kernels are solved for that exact variance, so discretization
// does not add blur: the only extra spread left in the image is the pixel's own area (1/12 px^2), as in a camera.

struct Level {
  double r_px = 0;
  double var_ss = 0;
  Psf psf = Psf::kDisc;
  int reach = 0;  // rows (and columns, +1) the kernel reaches on each side
  // Disc: per row dy in [-reach, reach], weight and half-width of the row segment (density 1/area).
  std::vector<double> row_weight, row_half;
  // Gaussian: separable taps [-reach, reach].
  std::vector<double> taps;
  bool identity() const { return var_ss == 0; }
};

// The levels spanning radii r_min .. r_max (px) on a ladder (one level when `fixed`), for ss sub-pixels per pixel.
std::vector<Level> ChooseLevels(double r_min, double r_max, std::optional<double> fixed, int ss, Psf psf);

// Variance (sub-pixels^2) across an edge of the kernel BlurAndDownsample applies for radius r_px: the two levels
// around it mixed with its weights, each level's variance computed from its kernel arrays.
double AppliedVarianceSs(const std::vector<Level>& levels, double r_px, int ss);

// The lens floor at sub-pixel resolution: separable taps of a Gaussian of std sigma_px * ss, 4 sigma wide.
std::vector<double> FloorTaps(double sigma_px, int ss);
// Variance (sub-pixels^2) of those taps, from the array.
double TapsVariance(const std::vector<double>& taps);

// Blurs the padded sharp image `sharp` (margin m on every side) with the radius each image sub-pixel's ray calls
// for (RadiusRow, r in output pixels), mixing levels, and area-downsamples by ss. Output: CV_32F, H x W; with
// `keep_subpixels` the blurred sub-pixels themselves, (H ss) x (W ss), for a lens distortion to warp first.
cv::Mat BlurAndDownsample(const cv::Mat& sharp, const View& view, int H, int W, const std::vector<Level>& levels,
                          int ss, int m, bool keep_subpixels = false);

}  // namespace blurcue::synth::detail
