#pragma once
// Blur measurement on one straight black/white edge section of a photo (thesis section 4.3), two ways:
//  - the thesis's own method (the anchor every better method is compared against), and
//  - a robust model fit in linear light.
// Both return r in the DESIGN.md unit: 2 x the standard deviation of the optical line-spread function.
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace blurcue::calib {

// Under this radius (px) a section whose profile does not tell the PSF's shape (ModelFit::shape_ambiguous) is read
// with the Gaussian shape, by the blur fit and by the phase check's families alike: a shape the profile cannot tell
// still moves the size there where the edge lies near a pixel centre (edge_blur.cc says what was measured).
constexpr double kOneShapeBelowPx = 0.7;
// ... and from this one: under it the profile is little more than the pixel's own box and the size is not determined
// (on the tests' scene focused on edge 1, a true 0 read 0.02-0.48 px section by section, the free shape and the
// Gaussian alike), so the blur fit's free reading stands there as before. The floor-0.2 scenes' sections read 0.4 px
// and up. (The tests' scenes rest on edge 1's median, 0.30 px: eq. 3.7 as published from a reference of 0.02 px
// refuses every point nearer than that edge, where test 2's balls start.)
constexpr double kOneShapeFromPx = 0.35;

// A board edge parallel to a section and next to it: the same section of the edge before or after it, in image px,
// its ends listed in the same order as the section's (a at the same column line as the section's a).
struct NeighbourEdge {
  cv::Point2d a, b;
  double beyond_px = 0;  // how far past it the image holds no other edge (half the gap to the edge after it)
  double r_px = 0;       // its blur where measured (its depth differs from the section's); 0: taken as the section's
};

// One edge section in image pixels.
struct EdgeSegment {
  cv::Point2d a, b;          // end points (the square corners bounding the section)
  double half_window_px = 0; // how far across the edge samples may reach on each side
                             // (about half the image distance to the neighbouring parallel edge)
  // How far the edge's midpoint lies off the chord a-b along its normal (px; a lens distortion bows straight edges):
  // distances across the edge are taken from the parabola through a, b and that point. 0: a straight edge.
  double bow_px = 0;
  // Directions in the image of the board's other lines, the ones that cross this edge at a and at b (any length,
  // either sense; zero: perpendicular to the edge). Where the squares are parallelograms in the image (a board
  // turned about the table normal, seen obliquely) those lines lean across the window; the samples keep their
  // distance from them along the edge at every offset across it, so the crossing edges never enter.
  cv::Point2d cross_a{0, 0}, cross_b{0, 0};
  // The parallel board edges on either side, where the board has them (calibrate.cc gives them from the pose). When
  // the blur reaches past half_window_px, the window reaches across them and the profile model includes their steps
  // (edge_window.h) instead of refusing the section as "crowded".
  std::vector<NeighbourEdge> neighbours = {};
};

struct ModelFitOptions {
  double along_fraction = 0.5;   // use the central part of the section (avoids the X-junctions at its ends)
  double min_contrast = 0.03;    // |step| in linear light below this: "low_contrast"
  double max_rms_rel = 0.08;     // fit residual rms / |step| above this: "poor_fit"
  double saturation_level = 0.99;// linear value at or above which a sample counts as clipped
  double max_saturated_fraction = 0.05;
};

struct ModelFit {
  bool ok = false;                 // usable: none of the disqualifying flags below
  std::vector<std::string> flags;  // "low_contrast", "saturated", "crowded", "poor_fit", "too_few_pixels",
                                   // "phase_limited" (phase_check.h)
                                   // disqualify; "flaw" (robustly rejected outliers), "neighbours" (measured
                                   // across the neighbouring edges, their steps in the model), "short" (a
                                   // shorter central part than along_fraction, to keep the X-junctions out of a
                                   // large blur) and "junctions" (the X-junctions within the blur's reach of even
                                   // the shortest part: the crossing lines in the model, edge_junction.h) are
                                   // informational
  std::string crowded_why;         // with "crowded": why the blur cannot be measured here, in words
  // With "phase_limited" (set by the calibration, phase_check.h: an edge along the pixel rows with blur near or
  // below a pixel, whose reading depends on a PSF family the photo does not pin): why, in words.
  std::string phase_why;
  double r_px = 0;                 // optical blur radius: 2 x the std of the optical LSF, pixel aperture removed
                                   // (the fitted disc x Gaussian's second moment, whatever its shape)
  // The shape within r_px^2 = disc_r_px^2 + 4 floor_sigma_px^2 (DESIGN.md): a defocus disc and a Gaussian floor.
  double disc_r_px = 0, floor_sigma_px = 0;
  double shape_se_rad = 0;         // standard error of the shape angle atan(2 floor_sigma / disc_r)
  // Under kOneShapeBelowPx, where the shape is ambiguous: the standard error of r_px with the shape held (the Gaussian
  // from kOneShapeFromPx, the free fit's under it; 0 where not read so, infinite where the profile does not bound the
  // reading). Near a pixel centre it grows (phase_flags.cc: a section too unsure there is flagged).
  double r_se_px = 0;
  bool shape_ambiguous = true;     // the profile does not pin the split (under kOneShapeBelowPx, read as a Gaussian)
  std::string psf;                 // "disc", "gaussian" or "disc x gaussian": the fitted shape
  double offset_px = 0;            // fitted edge position along the normal, relative to the segment line
  double step = 0;                 // signed step in linear light (dark->bright along the normal is > 0)
  double rms_rel = 0;              // residual rms / |step|
  int samples = 0;                 // pixels used
};

// `linear` is a one-channel CV_32F image in linear light [0, 1].
ModelFit MeasureEdgeModel(const cv::Mat& linear, const EdgeSegment& segment, const ModelFitOptions& options = {});

struct ThesisOptions {
  int sma_n = 5;             // simple-moving-average length, eq. 4.1
  double threshold = 1.0;    // grey levels per pixel
  int max_profile_px = 200;  // "around 200 pixels" per profile
};

struct ThesisMeasure {
  bool ok = false;  // false when no gradient sample exceeds the threshold
  double r_px = 0;  // half the count of contiguous above-threshold gradient samples around the peak
  int count = 0;
};

// The thesis's method on the 8-bit grey image as stored (gamma-encoded, as the thesis did): one profile
// perpendicular to the edge through the section midpoint, SMA-smoothed, gradient, count of contiguous pixels
// whose |gradient| exceeds the threshold around the peak, halved.
ThesisMeasure MeasureEdgeThesis(const cv::Mat& grey8, const EdgeSegment& segment, const ThesisOptions& options = {});

}  // namespace blurcue::calib
