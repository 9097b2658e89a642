#include "calib/edge_blur.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

#include "calib/edge_esf.h"
#include "calib/edge_junction.h"
#include "calib/edge_window.h"
#include "core/image.h"
#include "core/stats.h"

namespace blurcue::calib {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kMinRadiusPx = 0.02;    // fits never go below this (a Gaussian of s = 0 has no derivative)
constexpr double kMaxRadiusPx = 200.0;   // ... nor above this
constexpr double kBlackClip = 1e-4;      // linear value at or below which a sample counts as clipped black
constexpr double kFineBinPx = 0.25;      // finest bin across the edge (ISO 12233 uses 1/4 pixel)
constexpr int kMinSamples = 100;
// Standard error of the shape angle (radians) above which the disc/floor split is "shape_ambiguous".
constexpr double kShapeSeLimitRad = 0.15;
constexpr int kMaxNeighbours = 2;  // one each side of the edge
// The shortest central part of a section measured (MeasureEdgeModel): a fifth of it still holds thousands of samples
// of a section tens of px long, and its X-junctions out of reach of a blur up to about 40 % of its length.
constexpr double kMinAlongFraction = 0.2;

// Geometry shared by both methods and the window: EdgeFrame (edge_window.h). Pixel centres sit at integer
// coordinates (OpenCV).
using Frame = EdgeFrame;

// The edge spread function (disc x Gaussian, pixel aperture included): edge_esf.h.
using detail::EsfModel;

// ---- Sampling and binning ----------------------------------------------------------------------------

struct Sample {
  float d, v;
};

struct Bin {
  int index = 0;  // position in the bin grid
  double x = 0;   // mean signed distance of its samples
  double v = 0;   // robust value: the median, then (RefineBins) the mean of the samples near it
  double w = 0;   // weight (sample count)
  double median = 0;
};

// The upper median (for even counts): robust statistics need no averaging of the middle pair.
double MedianInPlace(float* first, float* last) {
  float* mid = first + (last - first) / 2;
  std::nth_element(first, mid, last);
  return *mid;
}

// Bins samples of |d| <= half_window at `width`; per bin the median value (rejects printing spots).
// `start` (per bin, where its values begin) and `values` (grouped by bin) are kept for RefineBins.
// `spread_px2` (when given): the mean over the samples of their distance's variance within their bin. A bin's value
// averages the profile over where its samples lie: across an edge that no pixel axis follows they fill the bin
// evenly, and the binned profile is the true one convolved with a box of the bin's width (w^2 / 12 of variance,
// +0.3-1 % on r at 45 degrees); along a pixel axis each bin holds one row's distance and adds nothing.
std::vector<Bin> MakeBins(const std::vector<Sample>& samples, double half_window, double width,
                          std::vector<int>& start, std::vector<float>& values, double* spread_px2 = nullptr) {
  const int nb = std::max(1, static_cast<int>(std::ceil(2 * half_window / width)));
  auto index = [&](double d) { return std::clamp(static_cast<int>((d + half_window) / width), 0, nb - 1); };
  start.assign(nb + 1, 0);
  std::vector<double> sum_d(nb, 0.0), in_n(nb, 0.0), in_d(nb, 0.0), in_d2(nb, 0.0);
  for (const Sample& s : samples) {
    const int i = index(s.d);
    ++start[i + 1];
    sum_d[i] += s.d;
    // The end bins also take the samples beyond the window (a bowed edge's, moved across by the bow): on the plateau,
    // where the spread does not matter, and not the spread of the bin's width.
    if (std::abs(s.d) < half_window) in_n[i] += 1, in_d[i] += s.d, in_d2[i] += double(s.d) * s.d;
  }
  if (spread_px2) {
    double within = 0, n = 0;
    for (int i = 0; i < nb; ++i)
      if (in_n[i] > 0) within += std::max(0.0, in_d2[i] - in_d[i] * in_d[i] / in_n[i]), n += in_n[i];
    *spread_px2 = n > 0 ? within / n : 0;
  }
  for (int i = 0; i < nb; ++i) start[i + 1] += start[i];
  values.resize(samples.size());
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (const Sample& s : samples) values[fill[index(s.d)]++] = s.v;
  std::vector<Bin> bins;
  bins.reserve(nb);
  for (int i = 0; i < nb; ++i) {
    const int n = start[i + 1] - start[i];
    if (n == 0) continue;
    const double median = MedianInPlace(values.data() + start[i], values.data() + start[i + 1]);
    bins.push_back({i, sum_d[i] / n, median, static_cast<double>(n), median});
  }
  return bins;
}

struct BinStats {
  double sigma = 0;    // noise std, from the median absolute deviation from the bin medians
  long outliers = 0;   // samples farther than `flaw_limit` from their bin's median
  long clipped = 0;    // samples in bins whose median is clipped black or white
};

// The median rejects printing spots but wastes a third of the information in Gaussian noise, and on 8-bit data
// it snaps to code values; the mean of the samples that are not flaws (within max(6 sigma, flaw_rel x step) of
// the median) recovers both. A narrower window would cut quantised noise asymmetrically in the transition bins
// and widen the edge. Near a clip level (black at 0) the median is kept: there clipped noise would bias a mean.
BinStats RefineBins(std::vector<Bin>& bins, const std::vector<int>& start, std::vector<float>& values,
                    double flaw_rel, double step, double white_clip, double black_clip) {
  BinStats st;
  // A few thousand deviations pin the noise level as well as all of them.
  const int stride = std::max<int>(1, static_cast<int>(values.size() / 4096));
  std::vector<float> dev;
  dev.reserve(values.size() / stride + bins.size());
  for (const Bin& b : bins)
    for (int k = start[b.index]; k < start[b.index + 1]; k += stride) dev.push_back(std::abs(values[k] - float(b.median)));
  if (dev.empty()) return st;
  st.sigma = 1.4826 * MedianInPlace(dev.data(), dev.data() + dev.size());
  const double flaw = std::max(6 * st.sigma, flaw_rel * std::abs(step));
  for (Bin& b : bins) {
    const float* first = values.data() + start[b.index];
    const float* last = values.data() + start[b.index + 1];
    double sum = 0;
    int n = 0;
    for (const float* v = first; v != last; ++v) {
      const double d = std::abs(*v - b.median);
      if (d <= flaw) sum += *v, ++n;
      else ++st.outliers;
    }
    if (b.median >= white_clip || b.median <= black_clip) st.clipped += last - first;
    const bool near_clip = b.median <= black_clip + 2 * st.sigma || b.median >= 1 - 2 * st.sigma;
    if (n > 0 && !near_clip) b.v = sum / n;
  }
  return st;
}

// ---- Fit ---------------------------------------------------------------------------------------------

// Solves the K x K system a x = b; false when singular.
template <int K>
bool Solve(const std::array<std::array<double, K>, K>& a, const std::array<double, K>& b, std::array<double, K>* x) {
  cv::Matx<double, K, K> m;
  cv::Vec<double, K> v, out;
  for (int i = 0; i < K; ++i) {
    v[i] = b[i];
    for (int j = 0; j < K; ++j) m(i, j) = a[i][j];
  }
  if (!cv::solve(m, v, out, cv::DECOMP_LU)) return false;
  for (int i = 0; i < K; ++i) (*x)[i] = out[i];
  return std::all_of(x->begin(), x->end(), [](double d) { return std::isfinite(d); });
}

struct FitState {
  double d0 = 0, r = 1, phi = 0;
  // Levels: v = a + b E + (a' + b' E) x / L across the window (x: bin position, L: half window). The slope terms
  // take up slowly varying illumination (vignetting, shading) that would otherwise tilt the plateaus into the edge.
  // With neighbouring edges (FitSetup::steps) their steps follow: v += c_k E(x - d0 - g_k), after the four above.
  std::array<double, 4 + kMaxNeighbours> lin{};
  double sse = std::numeric_limits<double>::infinity();
  double Step() const { return lin[1]; }  // at x = 0, the segment line
};

struct FitSetup {
  const std::vector<Bin>* bins = nullptr;
  double w1 = 1, w2 = 0, half_window = 1;
  bool slopes = false;
  // Neighbouring parallel edges in the window (edge_window.h): their distances from this edge (px). Each step has
  // its own free size (the board's neighbour beyond its outer edges is the table, not the opposite square) and its
  // own blur where known (its depth differs by a square's: a few % of r), else this edge's, with this edge's shape.
  std::vector<EdgeWindow::Step> steps;
  // The X-junctions at the section's ends in the model (edge_junction.h): every step is E - 2 C; null: out of reach.
  const detail::JunctionGeometry* junction = nullptr;
};

FitState EvaluateWithNeighbours(const FitSetup& fs, double d0, double r, double phi, std::vector<double>* residuals);

// For fixed (d0, r, phi) the levels follow by weighted linear least squares (variable projection).
// Fills `residuals` (weighted) when given.
FitState Evaluate(const FitSetup& fs, double d0, double r, double phi, std::vector<double>* residuals = nullptr) {
  if (!fs.steps.empty()) return EvaluateWithNeighbours(fs, d0, r, phi, residuals);
  const std::vector<Bin>& bins = *fs.bins;
  FitState st;
  st.d0 = d0, st.r = r, st.phi = phi;
  const EsfModel model(r, phi, fs.w1, fs.w2);
  std::optional<detail::JunctionShare> junction;
  if (fs.junction) junction.emplace(*fs.junction, r, phi);
  const int k = fs.slopes ? 4 : 2;
  thread_local std::vector<std::array<double, 4>> basis;
  basis.resize(bins.size());
  std::array<std::array<double, 4>, 4> a{};
  std::array<double, 4> rhs{};
  for (size_t i = 0; i < bins.size(); ++i) {
    const double x = bins[i].x - d0, e = model(x) - (junction ? 2 * (*junction)(x) : 0), t = bins[i].x / fs.half_window;
    basis[i] = {1, e, t, t * e};
    for (int p = 0; p < k; ++p) {
      rhs[p] += bins[i].w * basis[i][p] * bins[i].v;
      for (int q = 0; q < k; ++q) a[p][q] += bins[i].w * basis[i][p] * basis[i][q];
    }
  }
  bool solved;
  std::array<double, 4> x{};
  if (fs.slopes) {
    solved = Solve<4>(a, rhs, &x) && std::abs(a[1][1] * a[0][0] - a[0][1] * a[0][1]) > 1e-12 * a[0][0] * a[0][0];
  } else {
    std::array<std::array<double, 2>, 2> a2{{{a[0][0], a[0][1]}, {a[1][0], a[1][1]}}};
    std::array<double, 2> r2{rhs[0], rhs[1]}, x2{};
    solved = std::abs(a2[0][0] * a2[1][1] - a2[0][1] * a2[0][1]) > 1e-12 * a2[0][0] * a2[0][0] && Solve<2>(a2, r2, &x2);
    x = {x2[0], x2[1], 0, 0};
  }
  if (!solved) x = {rhs[0] / std::max(a[0][0], 1e-12), 0, 0, 0};  // the model is flat over the bins: no step
  std::copy(x.begin(), x.end(), st.lin.begin());
  double sse = 0;
  if (residuals) residuals->resize(bins.size());
  for (size_t i = 0; i < bins.size(); ++i) {
    double m = 0;
    for (int p = 0; p < 4; ++p) m += x[p] * basis[i][p];
    const double res = bins[i].v - m;
    sse += bins[i].w * res * res;
    if (residuals) (*residuals)[i] = std::sqrt(bins[i].w) * res;
  }
  st.sse = sse;
  return st;
}

// Evaluate with the steps of neighbouring edges in the profile: columns 1, E, t, t E (as above; the slopes only
// with FitSetup::slopes) and E(x - d0 - g_k) per neighbour; unused columns are padded out of the system.
FitState EvaluateWithNeighbours(const FitSetup& fs, double d0, double r, double phi, std::vector<double>* residuals) {
  constexpr int K = 4 + kMaxNeighbours;
  const std::vector<Bin>& bins = *fs.bins;
  FitState st;
  st.d0 = d0, st.r = r, st.phi = phi;
  const EsfModel model(r, phi, fs.w1, fs.w2);
  const int m = std::min<int>(fs.steps.size(), kMaxNeighbours);
  std::optional<detail::JunctionShare> junction;
  if (fs.junction) junction.emplace(*fs.junction, r, phi);
  auto lost = [&](double at) { return junction ? 2 * (*junction)(at) : 0.0; };
  std::array<bool, K> used{};
  used[0] = used[1] = true;
  used[2] = used[3] = fs.slopes;
  std::array<std::optional<EsfModel>, kMaxNeighbours> other;
  for (int k = 0; k < m; ++k) {
    used[4 + k] = true;
    if (fs.steps[k].r_px > 0) other[k].emplace(fs.steps[k].r_px, phi, fs.w1, fs.w2);
  }
  thread_local std::vector<std::array<double, K>> basis;
  basis.resize(bins.size());
  std::array<std::array<double, K>, K> a{};
  std::array<double, K> rhs{};
  for (size_t i = 0; i < bins.size(); ++i) {
    const double x = bins[i].x - d0, e = model(x) - lost(x), t = bins[i].x / fs.half_window;
    std::array<double, K>& b = basis[i];
    b = {};
    b[0] = 1, b[1] = e;
    if (fs.slopes) b[2] = t, b[3] = t * e;
    for (int k = 0; k < m; ++k) {
      const double at = x - fs.steps[k].at_px;
      b[4 + k] = (other[k] ? (*other[k])(at) : model(at)) - lost(at);
    }
    for (int p = 0; p < K; ++p) {
      rhs[p] += bins[i].w * b[p] * bins[i].v;
      for (int q = 0; q < K; ++q) a[p][q] += bins[i].w * b[p] * b[q];
    }
  }
  for (int p = 0; p < K; ++p)
    if (!used[p]) a[p][p] = 1;
  std::array<double, K> x{};
  if (!Solve<K>(a, rhs, &x)) x = {};
  st.lin = x;
  double sse = 0;
  if (residuals) residuals->resize(bins.size());
  for (size_t i = 0; i < bins.size(); ++i) {
    double v = 0;
    for (int p = 0; p < K; ++p) v += x[p] * basis[i][p];
    const double res = bins[i].v - v;
    sse += bins[i].w * res * res;
    if (residuals) (*residuals)[i] = std::sqrt(bins[i].w) * res;
  }
  st.sse = sse;
  return st;
}

// Levenberg-Marquardt on (d0, r[, phi]) of the reduced (levels eliminated) problem, numeric Jacobian. With
// `jtj_out` the Gauss-Newton matrix at the optimum is returned (for the shape's uncertainty).
FitState FitShape(const FitSetup& fs, FitState start, bool free_phi, double d0_limit,
                  std::array<std::array<double, 3>, 3>* jtj_out = nullptr) {
  const double phi_max = kPi / 2;
  start.r = std::clamp(start.r, kMinRadiusPx, kMaxRadiusPx);
  start.phi = std::clamp(start.phi, 0.0, phi_max);
  std::vector<double> res0, trial_res;
  std::array<std::vector<double>, 3> jac;
  FitState best = Evaluate(fs, start.d0, start.r, start.phi, &res0);
  const size_t n = res0.size();
  double lambda = 1e-3;
  std::array<std::array<double, 3>, 3> A{};
  for (int iter = 0; iter < 40; ++iter) {
    const double h = 1e-3 * (1 + best.r);
    // Forward differences, backwards at the upper bound of phi.
    const double hp = best.phi + 1e-3 > phi_max ? -1e-3 : 1e-3;
    Evaluate(fs, best.d0 + h, best.r, best.phi, &jac[0]);
    Evaluate(fs, best.d0, best.r + h, best.phi, &jac[1]);
    if (free_phi) Evaluate(fs, best.d0, best.r, best.phi + hp, &jac[2]);
    const std::array<double, 3> step_h = {h, h, hp};
    A = {};
    std::array<double, 3> g{};
    const int np = free_phi ? 3 : 2;
    for (size_t i = 0; i < n; ++i) {
      double j[3] = {0, 0, 0};
      for (int p = 0; p < np; ++p) j[p] = (jac[p][i] - res0[i]) / step_h[p];
      for (int p = 0; p < np; ++p) {
        g[p] += j[p] * res0[i];
        for (int q = 0; q < np; ++q) A[p][q] += j[p] * j[q];
      }
    }
    if (!free_phi) A[2][2] = 1;
    bool improved = false;
    for (int tries = 0; tries < 10 && !improved; ++tries) {
      auto B = A;
      for (int p = 0; p < 3; ++p) B[p][p] = A[p][p] * (1 + lambda) + 1e-15;
      std::array<double, 3> neg_g = {-g[0], -g[1], -g[2]}, step{};
      if (!Solve<3>(B, neg_g, &step)) break;
      const double nd0 = std::clamp(best.d0 + step[0], -d0_limit, d0_limit);
      const double nr = std::clamp(best.r + step[1], kMinRadiusPx, kMaxRadiusPx);
      const double nphi = free_phi ? std::clamp(best.phi + step[2], 0.0, phi_max) : best.phi;
      const FitState trial = Evaluate(fs, nd0, nr, nphi, &trial_res);
      if (trial.sse < best.sse) {
        res0.swap(trial_res);
        const double gain = best.sse - trial.sse;
        const bool tiny_step = std::abs(nd0 - best.d0) < 1e-5 && std::abs(nr - best.r) < 1e-5 * (1 + best.r) &&
                               std::abs(nphi - best.phi) < 1e-5;
        best = trial;
        lambda = std::max(lambda * 0.3, 1e-9);
        improved = true;
        if (tiny_step || gain < 1e-12 * (1 + best.sse)) {
          iter = 1000;  // converged
        }
      } else {
        lambda *= 10;
      }
    }
    if (!improved) break;
  }
  if (jtj_out) *jtj_out = A;
  return best;
}

// Plateau levels from the outer halves of the window (bin medians): the signed step, for the flaw limit.
double PlateauStep(const std::vector<Bin>& bins, double half_window, double* low) {
  std::vector<float> lo, hi;
  for (const Bin& b : bins) {
    if (b.x < -0.5 * half_window) lo.push_back(static_cast<float>(b.median));
    if (b.x > 0.5 * half_window) hi.push_back(static_cast<float>(b.median));
  }
  *low = 0;
  if (lo.empty() || hi.empty()) return 0;
  *low = MedianInPlace(lo.data(), lo.data() + lo.size());
  return MedianInPlace(hi.data(), hi.data() + hi.size()) - *low;
}

// Start for the fit: edge position from the area under the normalised profile, radius from the width of its
// 10-90 % zone around that position (Gaussian: 1.28 r, disc: about 1.16 r; the pixel box alone gives 0.8 px).
void StartEstimate(const std::vector<Bin>& bins, double half_window, double low, double step, double* d0,
                   double* r) {
  *d0 = 0;
  *r = 1;
  if (std::abs(step) < 1e-9 || bins.size() < 4) return;
  auto p = [&](const Bin& b) { return (b.v - low) / step; };
  double area = 0;
  for (size_t i = 0; i + 1 < bins.size(); ++i) area += 0.5 * (bins[i + 1].x - bins[i].x) * (p(bins[i]) + p(bins[i + 1]));
  *d0 = std::clamp(bins.back().x - area, -half_window, half_window);
  double x10 = bins.front().x, x90 = bins.back().x;
  for (const Bin& b : bins) {
    if (b.x < *d0 && p(b) <= 0.1) x10 = b.x;
    if (b.x > *d0 && p(b) >= 0.9) {
      x90 = b.x;
      break;
    }
  }
  const double width = x90 - x10;
  *r = std::max(0.3, std::sqrt(std::max(0.0, width * width - 0.64)) / 1.25);
}

// The fit in one window (edge_window.h). `prior`: a fit of the same edge in a narrower window, whose position, size
// and step start this one (the wide window's outer parts hold other edges, so the plateau-based start would be
// wrong there). Disqualifying flags but "crowded" are set; `along_span` is the extent of the samples along the edge.
// The pixels in `window` (their distance across the edge and value) and their extent along the edge.
std::vector<Sample> WindowSamples(const cv::Mat& linear, const EdgeSegment& segment, const ModelFitOptions& options,
                                  const EdgeWindow& window, double* along_span) {
  const Frame f = MakeEdgeFrame(segment);
  *along_span = 0;
  // Pixels in the window: across it from lo to hi, along it the central `along_fraction` of the strip between the
  // column lines through the section's ends (perpendicular to the edge in the plain window: an oriented rectangle).
  const double frac = std::clamp(options.along_fraction, 0.0, 1.0);
  auto along_range = [&](double d, double* lo, double* hi) {
    const double sa = window.ka * d, sb = f.length + window.kb * d, margin = 0.5 * (1 - frac) * (sb - sa);
    *lo = sa + margin, *hi = sb - margin;
  };
  double xmin = 1e18, xmax = -1e18, ymin = 1e18, ymax = -1e18;
  for (double d : {window.lo(), window.hi()}) {
    double s_lo, s_hi;
    along_range(d, &s_lo, &s_hi);
    for (double s : {s_lo, s_hi}) {
      const cv::Point2d p = f.a + s * f.t + d * f.n;
      xmin = std::min(xmin, p.x), xmax = std::max(xmax, p.x), ymin = std::min(ymin, p.y), ymax = std::max(ymax, p.y);
    }
  }
  const int x0 = std::max(0, static_cast<int>(std::ceil(xmin))), x1 = std::min(linear.cols - 1, int(std::floor(xmax)));
  const int y0 = std::max(0, static_cast<int>(std::ceil(ymin))), y1 = std::min(linear.rows - 1, int(std::floor(ymax)));
  const double bow = std::isfinite(segment.bow_px) ? segment.bow_px : 0;
  std::vector<Sample> samples;
  if (x0 <= x1 && y0 <= y1) samples.reserve(static_cast<size_t>((x1 - x0 + 1)) * (y1 - y0 + 1) / 2 + 16);
  double s_min = 1e18, s_max = -1e18;
  for (int y = y0; y <= y1; ++y) {
    const float* row = linear.ptr<float>(y);
    const double ry = y - f.a.y;
    double s = (x0 - f.a.x) * f.t.x + ry * f.t.y;
    double d = (x0 - f.a.x) * f.n.x + ry * f.n.y;
    for (int x = x0; x <= x1; ++x, s += f.t.x, d += f.n.x) {
      if (d < window.lo() || d > window.hi()) continue;
      double s_lo, s_hi;
      along_range(d, &s_lo, &s_hi);
      if (s < s_lo || s > s_hi) continue;
      const float v = row[x];
      if (!std::isfinite(v)) continue;
      // Across the bowed edge: the parabola's offset at s taken off (exact to first order in the bow).
      const double u = 2 * s / f.length - 1;
      samples.push_back({static_cast<float>(d - bow * (1 - u * u)), v});
      s_min = std::min(s_min, s), s_max = std::max(s_max, s);
    }
  }
  *along_span = std::max(0.0, s_max - s_min);
  return samples;
}

// The pixel aperture across the edge (boxes of |n.x| and |n.y|, edge_esf.h) with the bins' own spread folded in
// (MakeBins): as a second box where the edge follows a pixel axis (exact: the aperture is one box there), else added
// to the narrower box's variance (exact in second moment, which is what r is).
void ApertureWithBins(const Frame& f, double bin_spread_px2, double* w1, double* w2) {
  const double a = std::max(std::abs(f.n.x), std::abs(f.n.y)), b = std::min(std::abs(f.n.x), std::abs(f.n.y));
  const double c = std::sqrt(b * b + 12 * std::max(0.0, bin_spread_px2));
  *w1 = std::max(a, c), *w2 = std::min(a, c);
}

// The fitted state as a ModelFit: the size, its split into disc and floor and how well the profile pins that split,
// the edge's position and step, the residual.
void DescribeFit(const FitState& best, const std::array<std::array<double, 3>, 3>& jtj, const FitSetup& setup,
                 const std::vector<Bin>& bins, ModelFit* out) {
  ModelFit& fit = *out;
  double sw = 0;
  for (const Bin& b : bins) sw += b.w;
  fit.r_px = std::isfinite(best.r) ? best.r : 0;
  fit.disc_r_px = fit.r_px * std::cos(best.phi);
  fit.floor_sigma_px = 0.5 * fit.r_px * std::sin(best.phi);
  fit.offset_px = std::isfinite(best.d0) ? best.d0 : 0;
  fit.step = std::isfinite(best.Step()) ? best.Step() : 0;
  const double rms = std::sqrt(std::max(0.0, best.sse) / std::max(sw, 1.0));
  fit.rms_rel = std::abs(fit.step) > 1e-12 && std::isfinite(rms) ? rms / std::abs(fit.step) : 1e9;
  // The shape's standard error from the Gauss-Newton curvature, with the residual variance per bin (model error
  // included, so it errs on the side of "ambiguous"). Near r = 0 every shape looks alike: ambiguous by nature.
  {
    const int params = 3 + (setup.slopes ? 4 : 2) + static_cast<int>(setup.steps.size());
    const double dof = std::max(1.0, double(bins.size()) - params);
    std::array<std::array<double, 3>, 3> cov_in = jtj;
    std::array<double, 3> e2 = {0, 0, 1}, col{};
    double var_phi = std::numeric_limits<double>::infinity();
    if (Solve<3>(cov_in, e2, &col) && col[2] > 0) var_phi = best.sse / dof * col[2];
    fit.shape_se_rad = std::sqrt(var_phi);
    fit.shape_ambiguous = !(fit.shape_se_rad <= kShapeSeLimitRad) || fit.r_px < 0.5;
  }
  // The name says which factor holds the variance: a pure shape when the other holds under 15 % of r^2 (the
  // split's tails are what 8-bit quantisation and JPEG distort first), or when the fit is within two standard
  // errors of it.
  const double near = std::max(std::asin(std::sqrt(0.15)), 2 * std::min(fit.shape_se_rad, 1.0));
  fit.psf = best.phi <= near && best.phi <= kPi / 2 - best.phi ? "disc"
            : best.phi >= kPi / 2 - near                       ? "gaussian"
                                                               : "disc x gaussian";

}

// Under a pixel of blur the profile seldom tells the PSF's shape (shape_ambiguous), and a shape it cannot tell still
// moves the size where the edge lies near a pixel centre: the pixel holding the edge takes it whole, and the next
// ones see only the tails, whose extent is the shape's. A disc fitted best by noise read such sections 8-20 % high
// (disc x 0.2 px floor, noise 0.002; an independent erf fit of the same pixels read them within 1 %). Under
// kOneShapeBelowPx the size is read with the one shape that needs no second parameter, the Gaussian (model no more
// than the profile says); the shape stays reported ambiguous. (At 1 px, disc-like sections of 0.8 px read 4-6 %
// high with it: the limit is where the disc's own shape starts to show.)
void ReadOneShapeUnderAPixel(const FitSetup& setup, const FitState& best,
                             const std::array<std::array<double, 3>, 3>& jtj, const std::vector<Bin>& bins,
                             double d0_limit, ModelFit* fit) {
  const int params = 2 + (setup.slopes ? 4 : 2) + static_cast<int>(setup.steps.size());
  const double dof = std::max(1.0, double(bins.size()) - params);
  // The size's standard error with the shape held: the Gauss-Newton curvature of the reduced problem over (d0, r),
  // the residual variance per bin from the fit (model error included); infinite where the curvature in r vanishes
  // (a reading near 0, where the profile's slope in r does).
  auto size_se = [&](const std::array<std::array<double, 3>, 3>& a, double sse) {
    const double det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    return det > 0 && std::isfinite(sse) ? std::sqrt(sse / dof * a[0][0] / det)
                                         : std::numeric_limits<double>::infinity();
  };
  // Under kOneShapeFromPx the reading stands as the free fit read it; its standard error says whether the profile
  // pinned it (a Gaussian x 0.2 px floor scene under JPEG 95 read a section of 0.41 px as 0.02 px, its neighbours
  // 0.37-0.49 px, with nothing to flag it).
  if (fit->r_px < kOneShapeFromPx) {
    fit->r_se_px = size_se(jtj, best.sse);
    return;
  }
  if (!(fit->shape_ambiguous && fit->r_px < kOneShapeBelowPx)) return;
  FitState start_state = best;
  start_state.phi = kPi / 2;
  std::array<std::array<double, 3>, 3> a{};
  const FitState gauss = FitShape(setup, start_state, /*free_phi=*/false, d0_limit, &a);
  if (!std::isfinite(gauss.sse)) return;
  // A fit already at the Gaussian shape keeps its reading (only its standard error is taken from the re-fit).
  if (best.phi < kPi / 2) {
    DescribeFit(gauss, jtj, setup, bins, fit);
    fit->shape_ambiguous = true;
  }
  // Where the Gaussian re-fit collapsed to its least radius (JPEG 95 had taken a 0.41 px section's tails: 0.02 px,
  // its neighbours 0.37-0.49 px) the curvature in r vanishes and the standard error is infinite: not determined.
  fit->r_se_px = size_se(a, gauss.sse);
}

ModelFit FitInWindow(const cv::Mat& linear, const EdgeSegment& segment, const ModelFitOptions& options,
                     const EdgeWindow& window, const ModelFit* prior, double* along_span, bool junctions = false) {
  ModelFit fit;
  fit.psf = "disc";
  const Frame f = MakeEdgeFrame(segment);
  const double hw = window.HalfWidth();
  const std::vector<Sample> samples = WindowSamples(linear, segment, options, window, along_span);
  fit.samples = static_cast<int>(samples.size());
  if (fit.samples < kMinSamples || *along_span < 4) {
    fit.flags = {"too_few_pixels"};
    return fit;
  }

  // Super-resolved edge spread function: fine bins of a subsample first, for a start, then bins of r/8 of all
  // samples for the fit.
  std::vector<int> start;
  std::vector<float> values;
  std::vector<Bin> bins;
  {
    const size_t stride = std::max<size_t>(1, samples.size() / 8000);
    std::vector<Sample> sub;
    sub.reserve(samples.size() / stride + 1);
    for (size_t i = 0; i < samples.size(); i += stride) sub.push_back(samples[i]);
    bins = MakeBins(sub, hw, kFineBinPx, start, values);
  }
  double low = 0;
  const double step0 = prior ? prior->step : PlateauStep(bins, hw, &low);
  // Samples more than a quarter step (and 6 sigma) from their bin's median are printing flaws (or worse); bins
  // of r/8 hold at most ~1/16 step of slope either side of the median, so the edge itself is never cut.
  BinStats stats = RefineBins(bins, start, values, 0.25, step0, options.saturation_level, kBlackClip);
  double d0 = 0, r0 = 1;
  if (prior)
    d0 = prior->offset_px, r0 = prior->r_px;
  else
    StartEstimate(bins, hw, low, step0, &d0, &r0);

  FitSetup setup;
  setup.half_window = hw;
  setup.steps = window.Steps();
  // The samples' distances from the crossing lines (WindowSamples: the central part of the strip between them).
  const double frac = std::clamp(options.along_fraction, 0.0, 1.0);
  const detail::JunctionGeometry junction{f.length, window.ka, window.kb, 0.5 * (1 - frac) * f.length,
                                          0.5 * (1 + frac) * f.length};
  if (junctions) setup.junction = &junction;
  const double d0_limit = segment.half_window_px;
  FitState best;
  double bin_width = 0;  // the start bins hold a subsample: always rebin
  // Bins wider than r/6 would smear the edge they sample; refit on finer bins when the fit says so. These passes
  // fit the two pure shapes (a disc, a Gaussian) for the size; the mixed shape is fitted once on the final bins.
  for (int pass = 0; pass < 3; ++pass) {
    const double want = std::max(kFineBinPx, r0 / 8);
    if (std::abs(want - bin_width) > 1e-9) {
      bin_width = want;
      double spread_px2 = 0;
      bins = MakeBins(samples, hw, bin_width, start, values, &spread_px2);
      ApertureWithBins(f, spread_px2, &setup.w1, &setup.w2);
      stats = RefineBins(bins, start, values, 0.25, step0, options.saturation_level, kBlackClip);
    }
    if (bins.size() < 6) {
      fit.flags = {"too_few_pixels"};
      return fit;
    }
    setup.bins = &bins;
    // Slope terms need bins enough to tell them from the edge.
    setup.slopes = bins.size() >= 16;
    best = FitState{};
    for (double phi : {0.0, kPi / 2}) {
      // Two starts guard against a start far on the wrong side of the minimum.
      for (double scale : {1.0, 0.5}) {
        FitState start_state;
        start_state.d0 = d0, start_state.r = r0 * scale, start_state.phi = phi;
        const FitState st = FitShape(setup, start_state, /*free_phi=*/false, d0_limit);
        if (st.sse < best.sse) best = st;
        if (r0 < 1) break;
      }
    }
    if (!(bin_width > std::max(kFineBinPx, best.r / 6))) break;
    d0 = best.d0;
    r0 = best.r;
  }
  // The mixed shape (disc x Gaussian), from the better pure shape moved a little inwards and from the middle.
  std::array<std::array<double, 3>, 3> jtj{};
  {
    FitState mixed;
    for (double phi : {best.phi == 0 ? 0.15 : kPi / 2 - 0.15}) {
      FitState start_state = best;
      start_state.phi = phi;
      std::array<std::array<double, 3>, 3> a{};
      const FitState st = FitShape(setup, start_state, /*free_phi=*/true, d0_limit, &a);
      if (st.sse < mixed.sse) mixed = st, jtj = a;
    }
    // A pure shape that stays better keeps the curvature of the mixed fit that came back towards it.
    if (mixed.sse < best.sse) best = mixed;
  }

  DescribeFit(best, jtj, setup, bins, &fit);
  ReadOneShapeUnderAPixel(setup, best, jtj, bins, d0_limit, &fit);
  // Printing flaws: samples far from their bin's median (rejected above, reported here).
  if (std::abs(step0) > 0 && stats.outliers > std::max<long>(10, static_cast<long>(samples.size()) / 1000))
    fit.flags.push_back("flaw");

  bool bad = false;
  auto flag = [&](const char* name) { fit.flags.push_back(name), bad = true; };
  if (std::abs(fit.step) < options.min_contrast) flag("low_contrast");
  // Clipped noise tails do not bias the bin medians; clipped signal (a bin whose median is clipped) does.
  if (stats.clipped > options.max_saturated_fraction * fit.samples) flag("saturated");
  if (fit.rms_rel > options.max_rms_rel) flag("poor_fit");
  fit.ok = !bad;
  return fit;
}

}  // namespace

ModelFit MeasureEdgeModel(const cv::Mat& linear, const EdgeSegment& segment, const ModelFitOptions& options) {
  CV_Assert(linear.type() == CV_32FC1);
  const Frame f = MakeEdgeFrame(segment);
  const double hw = segment.half_window_px;
  if (!(f.length > 1) || !(hw > 1) || linear.empty() || !std::isfinite(hw)) {
    ModelFit fit;
    fit.psf = "disc";
    fit.flags = {"too_few_pixels"};
    return fit;
  }
  // The plain window first: half way to the next edge each side. The blur must fit in it with plateau to spare on
  // both sides of the edge, the X-junctions at the section ends must not reach into the central part used (a disc
  // reaches r), and the image border must leave enough of that part.
  const EdgeWindow plain = PlainWindow(segment);
  double span = 0;
  ModelFit fit = FitInWindow(linear, segment, options, plain, nullptr, &span);
  if (fit.samples < kMinSamples || fit.flags == std::vector<std::string>{"too_few_pixels"}) return fit;
  std::string why = CrowdedReason(segment, plain, fit, options.along_fraction, span, /*plain=*/true);
  EdgeWindow used = plain;
  double used_span = span;
  // Blur reaching the neighbouring edges: the window reaches across them and their steps join the profile model,
  // started from the plain fit (whose size is already close: the plain window holds most of the edge's spread).
  if (!why.empty() && !segment.neighbours.empty() && fit.r_px > 0) {
    EdgeWindow wide = NeighbourWindow(segment, BlurReachPx(fit));
    // Past the board's outer edge the board says nothing: the photo says whether the blur has room there (widened
    // again once if the fit across the neighbours finds a wider blur than the plain one).
    WidenFreeSides(linear, segment, BlurReachPx(fit), fit.offset_px, fit.step, &wide);
    const ModelFit plain_fit = fit;
    for (int round = 0; round < 2 && !wide.Steps().empty(); ++round) {
      double wide_span = 0;
      ModelFit across = FitInWindow(linear, segment, options, wide, &plain_fit, &wide_span);
      if (!(across.samples >= kMinSamples && across.r_px > 0)) break;
      fit = std::move(across);
      fit.flags.push_back("neighbours");
      used = wide, used_span = wide_span;
      why = CrowdedReason(segment, wide, fit, options.along_fraction, wide_span, /*plain=*/false);
      if (why.empty() || !WidenFreeSides(linear, segment, BlurReachPx(fit), fit.offset_px, fit.step, &wide)) break;
    }
  }
  // The X-junctions at the section's ends within reach of the part used (a large blur on a short section: a turned
  // board's far squares): a shorter central part, down to a fifth of the section, keeps them out of the blur's whole
  // reach (BlurReachPx: a Gaussian's 3 std, a disc's radius + 3 floor std), not only of r + 1 as CrowdedReason asks:
  // at r + 1 the short parts read up to 6 % high on turned scenes, at the whole reach within 4 % (mostly the
  // neighbours' steps misplaced, since fixed in NeighbourWindow: docs/independent-truth.md). Only where that is the
  // one reason left; the size and position start from the fit so far.
  const double shorter = AlongFractionClearOfJunctions(segment, used, BlurReachPx(fit) - 1);
  if (!why.empty() && fit.r_px > 0 && shorter < options.along_fraction && shorter >= kMinAlongFraction) {
    ModelFitOptions narrower = options;
    narrower.along_fraction = shorter;
    double short_span = 0;
    ModelFit part = FitInWindow(linear, segment, narrower, used, &fit, &short_span);
    const bool plain_used = used.Steps().empty();
    if (part.samples >= kMinSamples && part.r_px > 0 &&
        CrowdedReason(segment, used, part, shorter, short_span, plain_used).empty()) {
      if (!plain_used) part.flags.push_back("neighbours");
      part.flags.push_back("short");
      fit = std::move(part);
      why.clear();
    }
  }
  // Still crowded by the X-junctions alone (a section too short even at a fifth of it: a turned board's far squares
  // with r up to 8 px): the crossing lines join the model (edge_junction.h) and the usual central part is measured.
  if (!why.empty() && fit.r_px > 0 &&
      CrowdedReason(segment, used, fit, options.along_fraction, used_span, used.Steps().empty(), true).empty()) {
    double junction_span = 0;
    ModelFit part = FitInWindow(linear, segment, options, used, &fit, &junction_span, /*junctions=*/true);
    const bool plain_used = used.Steps().empty();
    if (part.samples >= kMinSamples && part.r_px > 0 &&
        CrowdedReason(segment, used, part, options.along_fraction, junction_span, plain_used, true).empty()) {
      if (!plain_used) part.flags.push_back("neighbours");
      part.flags.push_back("junctions");
      fit = std::move(part);
      why.clear();
    }
  }
  if (!why.empty()) {
    fit.flags.push_back("crowded");
    fit.crowded_why = why;
    fit.ok = false;
  }
  return fit;
}

ThesisMeasure MeasureEdgeThesis(const cv::Mat& grey8, const EdgeSegment& segment, const ThesisOptions& options) {
  ThesisMeasure out;
  if (grey8.empty()) return out;
  const cv::Mat grey = grey8.type() == CV_8UC1 ? grey8 : ToGrey8(grey8);
  const Frame f = MakeEdgeFrame(segment);
  if (!(f.length > 0) || !(segment.half_window_px >= 1)) return out;
  const cv::Point2d m = 0.5 * (segment.a + segment.b);

  // Profile across the edge through the midpoint, bilinear at 1 px steps; stops at the image border.
  const int K = static_cast<int>(std::floor(std::min(0.5 * options.max_profile_px, segment.half_window_px)));
  if (grey.cols < 2 || grey.rows < 2) return out;
  auto sample = [&](int k, double* v) {
    const double x = m.x + k * f.n.x, y = m.y + k * f.n.y;
    if (!(x >= 0 && y >= 0 && x <= grey.cols - 1 && y <= grey.rows - 1)) return false;
    const int xi = std::min(static_cast<int>(x), grey.cols - 2), yi = std::min(static_cast<int>(y), grey.rows - 2);
    const double fx = x - xi, fy = y - yi;
    const uint8_t* r0 = grey.ptr<uint8_t>(yi);
    const uint8_t* r1 = grey.ptr<uint8_t>(yi + 1);
    *v = (1 - fy) * ((1 - fx) * r0[xi] + fx * r0[xi + 1]) + fy * ((1 - fx) * r1[xi] + fx * r1[xi + 1]);
    return true;
  };
  std::vector<double> before, after;
  double v;
  for (int k = 0; k >= -K && sample(k, &v); --k) before.push_back(v);
  for (int k = 1; k <= K && sample(k, &v); ++k) after.push_back(v);
  std::vector<double> profile(before.rbegin(), before.rend());
  profile.insert(profile.end(), after.begin(), after.end());

  // Eq. 4.1: trailing simple moving average of n samples, then the forward-difference gradient.
  const int n = std::max(1, options.sma_n);
  if (static_cast<int>(profile.size()) < n + 1) return out;
  std::vector<double> sma;
  double acc = 0;
  for (size_t i = 0; i < profile.size(); ++i) {
    acc += profile[i];
    if (i >= static_cast<size_t>(n)) acc -= profile[i - n];
    if (i + 1 >= static_cast<size_t>(n)) sma.push_back(acc / n);
  }
  std::vector<double> grad(sma.size() - 1);
  for (size_t i = 0; i + 1 < sma.size(); ++i) grad[i] = std::abs(sma[i + 1] - sma[i]);
  if (grad.empty()) return out;
  const size_t peak = std::max_element(grad.begin(), grad.end()) - grad.begin();
  if (!(grad[peak] > options.threshold)) return out;
  size_t lo = peak, hi = peak;
  while (lo > 0 && grad[lo - 1] > options.threshold) --lo;
  while (hi + 1 < grad.size() && grad[hi + 1] > options.threshold) ++hi;
  out.count = static_cast<int>(hi - lo + 1);
  out.r_px = 0.5 * out.count;
  out.ok = true;
  return out;
}

}  // namespace blurcue::calib
