#pragma once
// The edge model the blur fit spans (edge_blur.cc) and the phase check reads with (phase_check.cc): the edge spread
// function of a defocus disc convolved with a Gaussian floor, the pixel's own aperture included, in closed form or
// by quadrature. Internal to calib.
#include <algorithm>
#include <array>
#include <cmath>

#include "core/stats.h"

namespace blurcue::calib::detail {

inline constexpr double kEsfPi = 3.14159265358979323846;

// ---- Edge spread functions ---------------------------------------------------------------------------
// F2 is the second antiderivative of the optical ESF (zero far on the dark side): F2(x) = E[(x - X)_+^2] / 2
// with X distributed as the LSF. The pixel's own aperture, projected on the normal, is the convolution of two
// boxes of widths |n.x| and |n.y| (a trapezoid; variance 1/12 at any angle). Averaging the ESF over two boxes
// is a second divided difference of F2, so the whole model stays in closed form.


inline double F1Gauss(double x, double s) {
  const double z = x / s;
  return x * StdNormalCdf(z) + s * StdNormalPdf(z);
}
inline double F2Gauss(double x, double s) {
  const double z = x / s;
  return 0.5 * (x * x + s * s) * StdNormalCdf(z) + 0.5 * x * s * StdNormalPdf(z);
}

// Disc of radius R: the LSF is a semicircle on [-R, R], variance R^2 / 4.
inline double F1Disc(double x, double R) {
  if (x <= -R) return 0;
  if (x >= R) return x;
  const double u = x / R, q = std::sqrt(std::max(0.0, 1 - u * u));
  return R * (0.5 * u + (u * std::asin(u) + q - q * q * q / 3) / kEsfPi);
}
inline double F2Disc(double x, double R) {
  if (x <= -R) return 0;
  if (x >= R) return 0.5 * (x * x + 0.25 * R * R);
  const double u = x / R, q = std::sqrt(std::max(0.0, 1 - u * u)), as = std::asin(u);
  const double bracket = -(u * q * q * q / 4 + 0.375 * (u * q + as)) / 3 + 0.5 * u * u * as - 0.25 * (as - u * q) +
                         0.5 * (u * q + as);
  return R * R * (0.25 * u * u + bracket / kEsfPi + 1.0 / 16);
}

// The optical PSF family the fit spans: a defocus disc of radius R convolved with a Gaussian of std s (the lens
// floor: aberrations, diffraction, demosaicing). Parametrised by the DESIGN.md radius r = sqrt(R^2 + 4 s^2), which
// is what the measurement reports, and the shape angle phi: R = r cos(phi), 2 s = r sin(phi) (phi = 0: a pure
// disc, pi/2: a pure Gaussian). The LSF's variance is R^2/4 + s^2 = r^2/4 at every phi, so r is the second moment
// whatever share of it the shape puts in the disc or the floor, and a poorly determined phi leaves r well
// determined.
struct EsfModel {
  double r = 1, phi = 0;   // DESIGN.md radius and shape angle
  double R = 1, s = 0;     // disc radius, Gaussian std
  double w1 = 1, w2 = 0;   // pixel aperture boxes across the edge, w1 >= w2
  double reach = 0;        // beyond |x| > reach the model is exactly 0 or 1
  enum class Mode { kDisc, kGaussian, kOverDisc, kOverGaussian } mode = Mode::kDisc;
  // Quadrature of the mixed shape: nodes (shifts, px) and weights (sum 1).
  static constexpr int kMaxNodes = 49;
  int n = 0;
  std::array<double, kMaxNodes> node{}, weight{};

  EsfModel(double radius, double shape, double box1, double box2)
      : r(radius), phi(shape), R(radius * std::cos(shape)), s(0.5 * radius * std::sin(shape)), w1(box1), w2(box2) {
    // An exactly pure shape (or a share too small to matter) is the closed form itself.
    if (s <= 1e-4 * r) {
      mode = Mode::kDisc, R = r, s = 0;
    } else if (R <= 1e-4 * r) {
      mode = Mode::kGaussian, R = 0, s = 0.5 * r;
    } else {
      // Disc x Gaussian has no closed form; it is a weighted sum of shifted closed forms of one factor (pixel
      // aperture included), integrated over the other. Which factor to integrate over: the one that is narrow
      // against the other's smoothness, so a few nodes resolve it.
      const double smooth = std::sqrt(s * s + (w1 * w1 + w2 * w2) / 12);
      if (R <= 2 * smooth) {
        // Over the disc's semicircular LSF: Gauss-Chebyshev (second kind) nodes, exact for polynomials of degree
        // 2n - 1 against the semicircle; spaced at most half the Gaussian-and-box smoothness apart.
        mode = Mode::kOverDisc;
        n = std::clamp(static_cast<int>(std::ceil(2 * kEsfPi * R / smooth)) + 2, 4, kMaxNodes);
        for (int k = 1; k <= n; ++k) {
          const double th = k * kEsfPi / (n + 1);
          node[k - 1] = R * std::cos(th);
          weight[k - 1] = 2.0 / (n + 1) * std::sin(th) * std::sin(th);
        }
      } else {
        // Over the Gaussian: trapezoid nodes s/2 apart over +-6 s. The disc-and-box ESF it shifts has a continuous
        // derivative here (R > 0.5 px), so the rule's error is far below the noise.
        mode = Mode::kOverGaussian;
        n = 25;
        double sum = 0;
        for (int k = 0; k < n; ++k) {
          const double z = 0.5 * (k - 12);
          node[k] = z * s;
          sum += weight[k] = std::exp(-0.5 * z * z);
        }
        for (int k = 0; k < n; ++k) weight[k] /= sum;
      }
    }
    reach = R + 7 * s + 0.5 * (w1 + w2) + 1e-9;  // Gaussian: 7 s (tail 1e-12)
  }

  // ESF of a disc (Gaussian when gauss) pixel-averaged: a second divided difference of F2 (first of F1).
  double Boxed(bool gauss, double width, double x) const {
    auto F1 = [&](double t) { return gauss ? F1Gauss(t, width) : F1Disc(t, width); };
    auto F2 = [&](double t) { return gauss ? F2Gauss(t, width) : F2Disc(t, width); };
    const double h1 = 0.5 * w1, h2 = 0.5 * w2;
    if (w2 < 1e-3) return (F1(x + h1) - F1(x - h1)) / w1;
    return (F2(x + h1 + h2) - F2(x + h1 - h2) - F2(x - h1 + h2) + F2(x - h1 - h2)) / (w1 * w2);
  }

  // ESF in [0, 1] at signed distance x from the edge, pixel aperture included.
  double operator()(double x) const {
    if (x <= -reach) return 0;
    if (x >= reach) return 1;
    double v = 0;
    switch (mode) {
      case Mode::kDisc: v = Boxed(false, R, x); break;
      case Mode::kGaussian: v = Boxed(true, s, x); break;
      case Mode::kOverDisc:
        for (int k = 0; k < n; ++k) v += weight[k] * Boxed(true, s, x - node[k]);
        break;
      case Mode::kOverGaussian:
        for (int k = 0; k < n; ++k) v += weight[k] * Boxed(false, R, x - node[k]);
        break;
    }
    return std::clamp(v, 0.0, 1.0);
  }
};

}  // namespace blurcue::calib::detail
