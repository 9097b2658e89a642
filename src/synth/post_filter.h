#pragma once
// A filter applied to the sampled image, after the pixel aperture and the sensor noise, as a camera's demosaicing and
// sharpening do: one separable kernel on the pixel grid. Unlike the lens floor (scene.h: a Gaussian convolved with
// every PSF before sampling) it acts on the samples, so an edge's profile depends on where the edge falls between
// pixel rows (issue 42). The truth is the kernel's own second moment, from the taps applied.
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/json_io.h"

namespace blurcue::synth {

// What is applied to the sampled image.
enum class PostFilter {
  kNone,
  kGaussian,  // taps of a Gaussian of std sigma_px sampled at whole pixels, normalised
  kSharpen,   // unsharp mask: (1 + amount) x identity - amount x the Gaussian above (a negative second moment)
};
// "none", "gaussian", "sharpen".
const char* Name(PostFilter filter);
// Throws Error(kUsage) naming the words it takes.
PostFilter ParsePostFilter(const std::string& text);

struct PostFilterOptions {
  PostFilter kind = PostFilter::kNone;
  double sigma_px = 0;  // the Gaussian's std, px of the image
  double amount = 0;    // sharpening only: how much of the blurred copy is taken away
};

// The separable taps (1-D, centred, odd length, in the float precision applied); {1} for kNone.
std::vector<float> PostFilterTaps(const PostFilterOptions& options);
// Second moment (px^2) of the taps about their centre, divided by their sum, from the array: what the filter adds to
// the variance of a line-spread function across an edge of any direction (the kernel is the same on both axes).
double PostFilterVariancePx2(const std::vector<float>& taps);
// truth.json's post_filter block: kind, sigma_px, amount, the taps and their second moment (variance_px2).
Json PostFilterTruth(const PostFilterOptions& options, const std::vector<float>& taps);
// Applies the taps along rows and columns of a CV_32F image in place (edges replicated).
void ApplyPostFilter(cv::Mat& linear, const std::vector<float>& taps);

}  // namespace blurcue::synth
