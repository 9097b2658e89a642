// A section's profile across its edge for the phase check (phase_check.cc): the pixels' values binned by their
// distance from the pose's line, and the pixels' noise about them.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "calib/edge_blur.h"

namespace blurcue::calib::detail {

// One bin: its pixels' mean distance across the edge (px), their interquartile mean (linear light), their count.
struct Bin {
  double x = 0, v = 0, w = 0;
};

// The profile across the edge, from the pose's line (d = 0), over |d| <= half_px, in the central part along. A bin
// holds at least `min_samples` pixels (its interquartile mean: robust to a printing spot); the noise comes from the bins
// of 3 or more (those of 2 too, where they give fewer than 12 deviations).
std::vector<Bin> ProfileBins(const cv::Mat& linear, const EdgeSegment& segment, double along_fraction,
                             double half_px, size_t min_samples, double* noise);

}  // namespace blurcue::calib::detail
