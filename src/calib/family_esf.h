#pragma once
// A PSF family's edge profile (phase_check.cc): the optics (EsfModel: disc x Gaussian, the pixel's aperture included)
// then the family's filter on the sampled image. The filter is separable, the same 1-D taps t on rows and columns
// (synth/post_filter.cc: cv::sepFilter2D), so its 2-D kernel is t_i t_j at whole pixels (i, j). An edge of unit normal
// n = (n_x, n_y) at distance d is sampled as ESF(n.p - d), and the filter, linear on the samples, makes
// m(x) = sum_ij t_i t_j ESF(x - (n_x i + n_y j)): the two 1-D tap measures, spaced |n_x| and |n_y| across the edge,
// convolved (the taps are symmetric, so the signs of n_x, n_y do not matter). Its variance across the edge is
// V (n_x^2 + n_y^2) = V at any angle (V the taps' second moment), so a family reads sqrt(r1^2 + 4 V), r1 the optics
// alone. A level edge (n_y = 0) gets the 1-D taps themselves. Internal to calib.
#include <cstddef>
#include <memory>
#include <vector>

#include "calib/edge_esf.h"
#include "calib/phase_check.h"

namespace blurcue::calib::detail {

// The family's 1-D kernel at whole pixels (a Gaussian out to 4 sigma, at least one tap each side), normalised; {1}
// for the optics alone. The taps synth applies (PostFilterTaps), in double.
std::vector<double> FamilyTaps(const PhaseFamily& family);
// Their second moment about the centre (px^2; negative for an unsharp mask).
double TapsVariance(const std::vector<double>& taps);

// One tap of the 2-D kernel seen across an edge: the profile moved by `offset` px, weighed by `weight`.
struct ProjectedTap {
  double offset = 0, weight = 0;
};
// The taps t_i t_j at offsets w1 i + w2 j across an edge whose normal's components are w1 >= w2 >= 0 in magnitude,
// those whose |weight| is under 1e-7 left out. Where the second axis's spread across the edge is negligible,
// w2^2 |V| <= 1e-7 px^2 (a level edge: w2 under 0.02-0.05 deg), its taps sum into the first's: the 1-D taps
// themselves at w1 k, as the profile of a level edge is (the second-order term they leave, w2^2 V ESF'' / 2, is
// under 1e-6 of the step).
std::vector<ProjectedTap> ProjectTaps(const std::vector<double>& taps, double w1, double w2);

// EsfModel on a grid aligned to multiples of its step (0.01 px x a power of 2, at most r / 40), read by Catmull-Rom
// cubic interpolation; 0 and 1 beyond the model's reach, as the model is. Within 6e-6 of EsfModel for r 0.02-4 px,
// any shape and angle (family_esf_test.cc checks 1e-5).
class EsfTable {
 public:
  explicit EsfTable(const EsfModel& model);
  // The points it holds for `model` (its cost, in EsfModel evaluations).
  static size_t Points(const EsfModel& model);
  double operator()(double x) const;

 private:
  double step_ = 0.01, first_ = 0;  // grid node k lies at (first_ + k) x step_
  std::vector<double> v_;
};

// The family's profile m(x) = sum_k weight_k ESF(x - offset_k) (its two levels aside) for optics of radius r1 and
// shape phi: through an EsfTable where it is to be evaluated at more points x taps than the table holds (the last 64
// built on the thread are kept: a reading asks for the same optics again), otherwise the EsfModel at each.
class FamilyProfile {
 public:
  FamilyProfile(double r1, double phi, double w1, double w2, const std::vector<ProjectedTap>& taps, size_t points);
  double operator()(double x) const;

 private:
  EsfModel model_;
  const std::vector<ProjectedTap>& taps_;
  std::shared_ptr<const EsfTable> table_;  // none: the model directly
};

}  // namespace blurcue::calib::detail
