#include "synth/scene.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <memory>
#include <random>
#include <sstream>
#include <thread>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/image.h"
#include "optics/thin_lens.h"

namespace blurcue::synth {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string Num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// ---------------------------------------------------------------------------------------------------------------
// Random numbers: std::mt19937_64's output is fixed by the standard, but the std:: distributions are not, so the
// uniform and normal draws are written out here; that keeps "same options + seed -> identical bytes" across
// standard libraries. Each purpose (flaws, texture phases, noise) gets its own stream so that, e.g., turning noise
// on does not move the flaws.

uint64_t SplitMix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

class Rng {
 public:
  Rng(uint64_t seed, uint64_t stream) : gen_(SplitMix64(seed * 0x100000001b3ULL + stream)) {}
  // [0, 1) with 53 random bits.
  double Uniform() { return static_cast<double>(gen_() >> 11) * 0x1.0p-53; }
  double Uniform(double a, double b) { return a + (b - a) * Uniform(); }
  int Int(int n) { return static_cast<int>(Uniform() * n); }
  // Box-Muller, both values used.
  double Normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double u1 = 1.0 - Uniform(), u2 = Uniform();  // u1 in (0, 1]
    const double m = std::sqrt(-2.0 * std::log(u1));
    spare_ = m * std::sin(2 * kPi * u2);
    has_spare_ = true;
    return m * std::cos(2 * kPi * u2);
  }

 private:
  std::mt19937_64 gen_;
  bool has_spare_ = false;
  double spare_ = 0;
};

enum Stream : uint64_t { kFlawStream = 1, kTextureStream = 2, kNoiseStream = 3, kNoiseNoBoardStream = 4 };

// ---------------------------------------------------------------------------------------------------------------
// Geometry.

struct Pose {
  cv::Matx33d R;  // board -> camera
  cv::Vec3d t;
};

// Board placement (see scene.h): camera pitched down by tilt, no roll; board turned by yaw about the table normal;
// edge 1's midpoint at depth edge1_u; board centre at camera x = lateral; near and far edge midpoints placed
// symmetrically about the principal point's row, so the board is centred in view.
Pose PlaceBoard(const SceneOptions& o) {
  const double th = o.tilt_deg * kPi / 180, ps = o.yaw_deg * kPi / 180;
  // World axes (right, forward on the table, up) in camera coordinates (x right, y down, z forward).
  const cv::Vec3d right(1, 0, 0), forward(0, -std::sin(th), std::cos(th)), up(0, -std::cos(th), -std::sin(th));
  const cv::Vec3d bx = std::cos(ps) * right + std::sin(ps) * forward;
  const cv::Vec3d by = -std::sin(ps) * right + std::cos(ps) * forward;
  Pose p;
  for (int i = 0; i < 3; ++i) {
    p.R(i, 0) = bx[i];
    p.R(i, 1) = by[i];
    p.R(i, 2) = up[i];
  }
  const Board& b = o.board;
  const cv::Vec3d m1 = p.R * cv::Vec3d(b.WidthMm() / 2, 0, 0);
  const cv::Vec3d mn = p.R * cv::Vec3d(b.WidthMm() / 2, b.LengthMm(), 0);
  const cv::Vec3d centre = p.R * cv::Vec3d(b.WidthMm() / 2, b.LengthMm() / 2, 0);
  p.t[2] = o.edge1_u_mm - m1[2];
  p.t[0] = o.lateral_mm - centre[0];
  const double z1 = m1[2] + p.t[2], zn = mn[2] + p.t[2];
  // (m1_y + ty) / z1 + (mn_y + ty) / zn = 0.
  p.t[1] = -(m1[1] / z1 + mn[1] / zn) / (1 / z1 + 1 / zn);
  return p;
}

// Everything a ray needs: intrinsics, the table and wall planes in camera coordinates, the lens.
struct View {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  int ss = 1;          // sub-pixels per pixel side
  cv::Matx33d Rt;      // camera -> board rotation
  cv::Vec3d t;         // board origin in camera coordinates
  cv::Vec3d n_table;   // table normal (board z) in camera coordinates; table: n_table . P = c_table
  double c_table = 0;
  cv::Vec3d n_wall;    // wall normal (world forward); wall: n_wall . P = c_wall
  double c_wall = 0;
  cv::Vec3d up;        // world up, for the wall's texture
  double yaw = 0;      // radians, board -> table texture frame
  // Thin lens, r_signed = k (a (1 - f/u) - 1), the form of optics::SignedBlurRadiusPx.
  double f = 0, k = 0, a = 1, gain = 1;
  std::optional<double> fixed_r;

  // Blur radius (px) at inverse depth w = 1/u.
  double RadiusPx(double w) const { return fixed_r ? *fixed_r : std::abs(k * (a * (1 - f * w) - 1)) * gain; }
};

// Where a ray through normalized image point (xn, yn) lands. surface: 0 table, 1 wall, -1 nothing.
struct Hit {
  int surface = -1;
  double s = 0;  // ray parameter = depth u (camera z), the ray being (xn, yn, 1)
};

inline Hit Intersect(const View& v, double xn, double yn) {
  const double qt = v.n_table[0] * xn + v.n_table[1] * yn + v.n_table[2];
  const double qw = v.n_wall[0] * xn + v.n_wall[1] * yn + v.n_wall[2];
  const double st = qt != 0 ? v.c_table / qt : -1;
  const double sw = qw != 0 ? v.c_wall / qw : -1;
  Hit h;
  if (st > 0 && (sw <= 0 || st <= sw)) {
    h.surface = 0;
    h.s = st;
  } else if (sw > 0) {
    h.surface = 1;
    h.s = sw;
  }
  return h;
}

// Image sub-pixel index -> normalized coordinates (OpenCV pixel centres at integers).
inline double SubToNormX(const View& v, double i) { return ((i + 0.5) / v.ss - 0.5 - v.cx) / v.fx; }
inline double SubToNormY(const View& v, double j) { return ((j + 0.5) / v.ss - 0.5 - v.cy) / v.fy; }

// Blur radius (px) of every sub-pixel of image sub-pixel row j. The inverse depth of a ray's hit on a plane is
// linear in the image coordinates, and the nearer surface is the larger positive one, so a row costs no divisions.
// Returns false if some ray meets nothing, or meets it no farther than the focal length.
bool RadiusRow(const View& v, int j, int wss, float* r) {
  const double yn = SubToNormY(v, j), x0 = SubToNormX(v, 0), dx = 1.0 / (v.fx * v.ss);
  const double it = 1 / v.c_table, iw = 1 / v.c_wall, w_max = 1 / v.f;
  const double t0 = (v.n_table[0] * x0 + v.n_table[1] * yn + v.n_table[2]) * it, t1 = v.n_table[0] * dx * it;
  const double w0 = (v.n_wall[0] * x0 + v.n_wall[1] * yn + v.n_wall[2]) * iw, w1 = v.n_wall[0] * dx * iw;
  bool ok = true;
  for (int i = 0; i < wss; ++i) {
    const double w = std::max(t0 + i * t1, w0 + i * w1);  // 1 / u
    if (!(w > 0 && w < w_max)) {
      ok = false;
      r[i] = 0;
      continue;
    }
    r[i] = static_cast<float>(v.RadiusPx(w));
  }
  return ok;
}

// ---------------------------------------------------------------------------------------------------------------
// Appearance (linear light).

// Integral from 0 to x (x >= 0) of the +1/-1 square wave that is +1 on even squares.
inline double Tri(double x, double square) {
  const double m = x - 2 * square * std::floor(x / (2 * square));
  return m < square ? m : 2 * square - m;
}

// Box-filtered board over a footprint of widths (wx, wy) mm centred at (x, y): board coverage and white coverage.
// The checker is a product of square waves and the box is separable, so the box average is exact (the footprint
// is the sub-pixel's parallelogram replaced by the box with the same second moments).
inline void BoardCoverage(double x, double y, double wx, double wy, double width, double length, double square,
                          double* cover, double* white_cover) {
  const double x0 = std::clamp(x - wx / 2, 0.0, width), x1 = std::clamp(x + wx / 2, 0.0, width);
  const double y0 = std::clamp(y - wy / 2, 0.0, length), y1 = std::clamp(y + wy / 2, 0.0, length);
  const double ax = (x1 - x0) / wx, ay = (y1 - y0) / wy;
  if (ax == 0 || ay == 0) {
    *cover = *white_cover = 0;
    return;
  }
  const double bx = (Tri(x1, square) - Tri(x0, square)) / wx, by = (Tri(y1, square) - Tri(y0, square)) / wy;
  *cover = ax * ay;
  *white_cover = 0.5 * (ax * ay - bx * by);  // white where the two square waves differ in sign
}

// sin for textures: a fixed polynomial instead of libm (three times faster here, and the same on every platform).
inline double FastSin(double x) {
  x -= 2 * kPi * std::floor(x / (2 * kPi) + 0.5);  // [-pi, pi]
  if (x > kPi / 2) x = kPi - x;
  if (x < -kPi / 2) x = -kPi - x;  // [-pi/2, pi/2]
  const double x2 = x * x;
  return x * (1 + x2 * (-1.0 / 6 + x2 * (1.0 / 120 + x2 * (-1.0 / 5040 + x2 * (1.0 / 362880)))));
}

// Attenuation of a sinusoid of period p by a box of width w (second-order match of the sinc, never negative).
inline double BoxAtten(double w, double p) {
  const double x = kPi * w / p;
  return std::exp(-x * x / 6);
}

// A smooth, low-contrast wood-like grain: wavy lines running away from the camera, plus slow blotches.
struct Wood {
  std::array<double, 8> phase{};
  double mean = 0.3;
  explicit Wood(Rng& rng, double mean_) : mean(mean_) {
    for (double& p : phase) p = rng.Uniform(0, 2 * kPi);
  }
  // (x, y): table frame, mm; (wx, wy): footprint widths.
  double operator()(double x, double y, double wx, double wy) const {
    const double warp = 3.0 * FastSin(2 * kPi * y / 190 + phase[0]) + 1.2 * FastSin(2 * kPi * y / 71 + phase[1]);
    // Ring spacing drifts across the board (x), as growth rings do.
    const double drift = 1.6 * FastSin(2 * kPi * x / 53 + phase[6]) + 0.8 * FastSin(2 * kPi * x / 17 + phase[7]);
    double g = 0.5 * FastSin(2 * kPi * (x + warp) / 9.0 + drift + phase[2]) * BoxAtten(wx, 6.0);
    g += 0.3 * FastSin(2 * kPi * (x + 0.7 * warp) / 23.0 + phase[3]) * BoxAtten(wx, 23.0);
    g += 0.35 * FastSin(2 * kPi * x / 260 + phase[4]) * FastSin(2 * kPi * y / 410 + phase[5]) * BoxAtten(wy, 410);
    return mean * (1 + 0.07 * g);
  }
};

struct Flaw {
  double x = 0, y = 0, radius = 0;  // board frame, mm
  double value = 0;                 // reflectance of the spot
  int row0 = 0, row1 = -1, col0 = 0, col1 = -1;  // padded sub-pixel bounding box
};

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

// Area of a disc of radius R between y = a and y = b.
double DiscStripArea(double R, double a, double b) {
  a = std::clamp(a, -R, R), b = std::clamp(b, -R, R);
  auto F = [R](double y) { return y * std::sqrt(std::max(0.0, R * R - y * y)) + R * R * std::asin(y / R); };
  return F(b) - F(a);
}

void BuildDisc(double R, Level* l) {
  const int n = R <= 0.5 ? 0 : static_cast<int>(std::ceil(R - 0.5));
  l->reach = n;
  l->row_weight.assign(2 * n + 1, 0);
  l->row_half.assign(2 * n + 1, 0);
  double total = 0;
  for (int dy = -n; dy <= n; ++dy) {
    const double area = R > 0 ? DiscStripArea(R, dy - 0.5, dy + 0.5) : 1;
    l->row_weight[dy + n] = area;
    l->row_half[dy + n] = R > 0 ? area / 2 : 0.5;  // segment of length = area at unit density
    total += area;
  }
  for (double& w : l->row_weight) w /= total;
  l->reach = std::max(n, static_cast<int>(std::ceil(l->row_half[n] + 0.5)));
}

// Variance across columns of a disc level: each row's segment [-h, h] integrated over unit cells.
double ColumnVariance(const Level& l) {
  double v = 0;
  for (size_t k = 0; k < l.row_weight.size(); ++k) {
    const double h = l.row_half[k];
    double s = 0;
    for (int i = -static_cast<int>(h) - 1; i <= static_cast<int>(h) + 1; ++i)
      s += i * i * std::max(0.0, std::min(i + 0.5, h) - std::max(i - 0.5, -h));
    v += l.row_weight[k] * s / (2 * h);
  }
  return v;
}

double RowVariance(const std::vector<double>& w) {
  const int n = static_cast<int>(w.size()) / 2;
  double v = 0;
  for (int i = 0; i < static_cast<int>(w.size()); ++i) v += (i - n) * (i - n) * w[i];
  return v;
}

void BuildGaussian(double sigma, int n, Level* l) {
  l->taps.assign(2 * n + 1, 0);
  double total = 0;
  for (int i = -n; i <= n; ++i) total += l->taps[i + n] = std::exp(-0.5 * i * i / (sigma * sigma));
  for (double& w : l->taps) w /= total;
  l->reach = n;
}

// A kernel of the family whose discrete variance is var_ss exactly (bisection on the continuous parameter).
Level MakeLevel(double r_px, int ss, Psf psf) {
  Level l;
  l.r_px = r_px;
  l.psf = psf;
  l.var_ss = (r_px * ss) * (r_px * ss) / 4;
  if (l.var_ss <= 0) {
    l.var_ss = 0;
    l.reach = 0;
    return l;
  }
  const double target = l.var_ss;
  if (psf == Psf::kDisc) {
    double lo = 0.5, hi = 2 * std::sqrt(target) + 2;
    for (int it = 0; it < 80; ++it) {
      const double mid = 0.5 * (lo + hi);
      Level t;
      BuildDisc(mid, &t);
      (RowVariance(t.row_weight) < target ? lo : hi) = mid;
    }
    BuildDisc(0.5 * (lo + hi), &l);
    // Rows of a small disc cut into cells are not round: widen (or narrow) every row's segment by one factor so
    // the spread across columns matches the spread across rows, i.e. the kernel is isotropic in second moment.
    const std::vector<double> halves = l.row_half;
    double klo = 0.05, khi = 4;
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (klo + khi);
      for (size_t k = 0; k < halves.size(); ++k) l.row_half[k] = halves[k] * mid;
      (ColumnVariance(l) < target ? klo : khi) = mid;
    }
    for (size_t k = 0; k < halves.size(); ++k) l.row_half[k] = halves[k] * 0.5 * (klo + khi);
    const int rows = static_cast<int>(l.row_weight.size()) / 2;
    l.reach = std::max(rows, static_cast<int>(std::ceil(*std::max_element(l.row_half.begin(), l.row_half.end()) + 0.5)));
  } else {
    // Width fixed first (3 sigma, at least one tap) so the variance is continuous in sigma.
    const int n = std::max(1, static_cast<int>(std::ceil(3 * std::sqrt(target))));
    double lo = 1e-3, hi = 4 * std::sqrt(target) + 4;
    for (int it = 0; it < 80; ++it) {
      const double mid = 0.5 * (lo + hi);
      Level t;
      BuildGaussian(mid, n, &t);
      (RowVariance(t.taps) < target ? lo : hi) = mid;
    }
    BuildGaussian(0.5 * (lo + hi), n, &l);
  }
  return l;
}

// Radius ladder: fine steps where the blur is about a pixel (shape matters most there), then 10 % steps.
std::vector<double> Ladder(double r_max) {
  std::vector<double> r;
  for (int i = 0; i <= 8; ++i) r.push_back(0.125 * i);
  while (r.back() < r_max) r.push_back(r.back() * 1.1);
  return r;
}

std::vector<Level> ChooseLevels(double r_min, double r_max, std::optional<double> fixed, int ss, Psf psf) {
  std::vector<Level> levels;
  if (fixed) {
    levels.push_back(MakeLevel(*fixed, ss, psf));
    return levels;
  }
  const std::vector<double> ladder = Ladder(r_max);
  size_t first = 0;
  while (first + 1 < ladder.size() && ladder[first + 1] <= r_min) ++first;
  for (size_t i = first; i < ladder.size(); ++i) {
    levels.push_back(MakeLevel(ladder[i], ss, psf));
    if (ladder[i] >= r_max) break;
  }
  return levels;
}

// A ring of processed rows, computed on demand. Rows are requested in a window that slides down the image, so a
// ring of twice the reach plus one never evicts a row that will be asked for again.
class RowRing {
 public:
  RowRing(int size, int width) : size_(size), width_(width), data_(size_t(size) * width), tag_(size, INT32_MIN) {}
  template <class Fill>
  const double* Get(int row, Fill&& fill) {
    const int slot = ((row % size_) + size_) % size_;
    double* p = &data_[size_t(slot) * width_];
    if (tag_[slot] != row) {
      fill(row, p);
      tag_[slot] = row;
    }
    return p;
  }

 private:
  int size_, width_;
  std::vector<double> data_;
  std::vector<int> tag_;
};

// Blurs the padded sharp image `sharp` (margin m on every side) with the radius each image sub-pixel's ray calls
// for (RadiusRow, r in output pixels), mixing levels, and area-downsamples by ss. Output: CV_32F, H x W.
cv::Mat BlurAndDownsample(const cv::Mat& sharp, const View& view, int H, int W, const std::vector<Level>& levels,
                          int ss, int m) {
  const int wss = W * ss, wp = sharp.cols;
  cv::Mat out(H, W, CV_32F, cv::Scalar(0));
  std::vector<double> var(levels.size());
  int max_reach = 0;
  for (size_t k = 0; k < levels.size(); ++k) var[k] = levels[k].var_ss, max_reach = std::max(max_reach, levels[k].reach);
  const double ss2 = double(ss) * ss;

  auto body = [&](const cv::Range& range) {
    // Exclusive prefix sums of sharp rows (disc); horizontally filtered rows per Gaussian level.
    RowRing prefix(2 * max_reach + 2, wp + 1);
    std::vector<std::unique_ptr<RowRing>> hrows(levels.size());
    for (size_t k = 0; k < levels.size(); ++k)
      if (levels[k].psf == Psf::kGaussian && !levels[k].identity())
        hrows[k] = std::make_unique<RowRing>(2 * levels[k].reach + 2, wp);
    std::vector<int> lo(wss);
    std::vector<double> wlo(wss), acc(wss), row_out(wss), blurred(wss);
    std::vector<float> rr(wss);

    auto fill_prefix = [&](int row, double* p) {
      const float* s = sharp.ptr<float>(row);
      double sum = 0;
      p[0] = 0;
      for (int x = 0; x < wp; ++x) p[x + 1] = sum += s[x];
    };

    for (int Y = range.start; Y < range.end; ++Y) {
      float* o = out.ptr<float>(Y);
      for (int y = Y * ss; y < (Y + 1) * ss; ++y) {
        const int py = y + m;  // padded row
        // Per sub-pixel: the level just below the wanted variance and its weight.
        RadiusRow(view, y, wss, rr.data());
        int lo_min = INT32_MAX, lo_max = -1;
        for (int x = 0; x < wss; ++x) {
          const double v = 0.25 * double(rr[x]) * ss * double(rr[x]) * ss;
          int k = static_cast<int>(std::upper_bound(var.begin(), var.end(), v) - var.begin()) - 1;
          k = std::clamp(k, 0, static_cast<int>(var.size()) - 1);
          double w = 1;
          if (k + 1 < static_cast<int>(var.size())) w = (var[k + 1] - v) / (var[k + 1] - var[k]);
          lo[x] = k;
          wlo[x] = std::clamp(w, 0.0, 1.0);
          lo_min = std::min(lo_min, k);
          lo_max = std::max(lo_max, k);
        }
        std::fill(row_out.begin(), row_out.end(), 0.0);
        const int k_end = std::min(lo_max + 1, static_cast<int>(levels.size()) - 1);
        for (int k = lo_min; k <= k_end; ++k) {
          // Columns that use level k with a non-zero weight.
          int x0 = wss, x1 = -1;
          for (int x = 0; x < wss; ++x) {
            const double w = lo[x] == k ? wlo[x] : (lo[x] + 1 == k ? 1 - wlo[x] : 0);
            if (w > 0) x0 = std::min(x0, x), x1 = x;
          }
          if (x1 < x0) continue;
          const Level& L = levels[k];
          if (L.identity()) {
            const float* s = sharp.ptr<float>(py) + m;
            for (int x = x0; x <= x1; ++x) blurred[x] = s[x];
          } else if (L.psf == Psf::kDisc) {
            std::fill(acc.begin() + x0, acc.begin() + x1 + 1, 0.0);
            for (int dy = -L.reach; dy <= L.reach; ++dy) {
              const int idx = dy + (static_cast<int>(L.row_weight.size()) / 2);
              if (idx < 0 || idx >= static_cast<int>(L.row_weight.size()) || L.row_weight[idx] == 0) continue;
              const double* p = prefix.Get(py + dy, fill_prefix);
              const double h = L.row_half[idx];
              // Integral of the piecewise-constant row over [X - h, X + h]: the prefix sum read with linear
              // interpolation at t + 1/2 (cells are centred on integers).
              const double th = h + 0.5, tl = -h + 0.5;
              const int oh = static_cast<int>(std::floor(th)), ol = static_cast<int>(std::floor(tl));
              const double fh = th - oh, fl = tl - ol;
              const double scale = L.row_weight[idx] / (2 * h);
              for (int x = x0; x <= x1; ++x) {
                const int X = x + m;
                const double hi_v = p[X + oh] + fh * (p[X + oh + 1] - p[X + oh]);
                const double lo_v = p[X + ol] + fl * (p[X + ol + 1] - p[X + ol]);
                acc[x] += scale * (hi_v - lo_v);
              }
            }
            for (int x = x0; x <= x1; ++x) blurred[x] = acc[x];
          } else {
            const int n = L.reach;
            auto fill_h = [&](int row, double* p) {
              const float* s = sharp.ptr<float>(row);
              for (int X = m; X < m + wss; ++X) {  // only the image's columns are read back
                double sum = 0;
                for (int i = -n; i <= n; ++i) sum += L.taps[i + n] * s[X + i];
                p[X] = sum;
              }
            };
            std::fill(acc.begin() + x0, acc.begin() + x1 + 1, 0.0);
            for (int dy = -n; dy <= n; ++dy) {
              const double* p = hrows[k]->Get(py + dy, fill_h);
              const double w = L.taps[dy + n];
              for (int x = x0; x <= x1; ++x) acc[x] += w * p[x + m];
            }
            for (int x = x0; x <= x1; ++x) blurred[x] = acc[x];
          }
          for (int x = x0; x <= x1; ++x) {
            const double w = lo[x] == k ? wlo[x] : (lo[x] + 1 == k ? 1 - wlo[x] : 0);
            row_out[x] += w * blurred[x];
          }
        }
        for (int x = 0; x < wss; ++x) o[x / ss] += static_cast<float>(row_out[x] / ss2);
      }
    }
  };
  const int threads = std::max(1u, std::thread::hardware_concurrency());
  cv::parallel_for_(cv::Range(0, H), body, std::min(H, 4 * threads));
  return out;
}

// Sensor noise: Gaussian read noise of std `noise` plus shot noise whose variance grows with the signal and equals
// the read noise's at `white`.
void AddNoise(cv::Mat& linear, double noise, double white, Rng rng) {
  if (noise <= 0) return;
  const double shot = noise * noise / std::max(white, 1e-3);
  for (int y = 0; y < linear.rows; ++y) {
    float* p = linear.ptr<float>(y);
    for (int x = 0; x < linear.cols; ++x) {
      const double v = p[x];
      p[x] = static_cast<float>(v + std::sqrt(noise * noise + shot * std::max(v, 0.0)) * rng.Normal());
    }
  }
}

cv::Mat Finish(cv::Mat linear, const SceneOptions& o, Rng rng) {
  AddNoise(linear, o.noise_std, o.white, rng);
  cv::Mat grey8 = EncodeSrgb8(linear), bgr;
  cv::cvtColor(grey8, bgr, cv::COLOR_GRAY2BGR);
  if (o.jpeg_quality > 0) {
    std::vector<uint8_t> bytes;
    cv::imencode(".jpg", bgr, bytes, {cv::IMWRITE_JPEG_QUALITY, o.jpeg_quality});
    bgr = cv::imdecode(bytes, cv::IMREAD_COLOR);
  }
  return bgr;
}

void ValidateOptions(const SceneOptions& o) {
  o.camera.Validate("camera");
  if (!o.camera.dist_coeffs.empty() &&
      std::any_of(o.camera.dist_coeffs.begin(), o.camera.dist_coeffs.end(), [](double d) { return d != 0; }))
    throw InputError("camera/dist_coeffs", "synthetic scenes are rendered through an ideal (undistorted) lens; "
                                           "remove the distortion coefficients");
  o.board.Validate("board");
  auto finite = [](double v) { return std::isfinite(v); };
  if (!(o.tilt_deg > 0 && o.tilt_deg <= 90))
    throw InputError("tilt_deg", "must be in (0, 90] degrees down from the horizontal, got " + Num(o.tilt_deg));
  const double f = o.camera.focal_length_mm;
  if (!(o.edge1_u_mm > f) || !finite(o.edge1_u_mm))
    throw InputError("edge1_u_mm", "must be a finite depth beyond the focal length (" + Num(f) + " mm), got " +
                                       Num(o.edge1_u_mm));
  if (!finite(o.lateral_mm)) throw InputError("lateral_mm", "must be finite, got " + Num(o.lateral_mm));
  if (!(std::abs(o.yaw_deg) < 90)) throw InputError("yaw_deg", "must be in (-90, 90) degrees, got " + Num(o.yaw_deg));
  if (!std::isnan(o.focus_mm) && !(o.focus_mm > f))
    throw InputError("focus_mm", "must be beyond the focal length (" + Num(f) + " mm) or infinity, got " +
                                     Num(o.focus_mm));
  if (o.fixed_r_px && !(*o.fixed_r_px >= 0 && finite(*o.fixed_r_px)))
    throw InputError("fixed_r_px", "must be a radius >= 0 px, got " + Num(*o.fixed_r_px));
  if (!(o.blur_gain >= 0 && finite(o.blur_gain)))
    throw InputError("blur_gain", "must be >= 0, got " + Num(o.blur_gain));
  for (auto [name, v] : {std::pair{"white", o.white}, {"black", o.black}, {"table", o.table}})
    if (!(v >= 0 && v <= 1)) throw InputError(name, "must be a linear reflectance in [0, 1], got " + Num(v));
  if (!(o.noise_std >= 0 && o.noise_std <= 1))
    throw InputError("noise_std", "must be in [0, 1] (linear units), got " + Num(o.noise_std));
  if (o.jpeg_quality < 0 || o.jpeg_quality > 100)
    throw InputError("jpeg_quality", "must be 0 (no JPEG) or 1..100, got " + std::to_string(o.jpeg_quality));
  if (o.flaws < 0 || o.flaws > 10000) throw InputError("flaws", "must be in [0, 10000], got " + std::to_string(o.flaws));
  if (o.supersample < 1 || o.supersample > 16)
    throw InputError("supersample", "must be in [1, 16] sub-pixels per side, got " + std::to_string(o.supersample));
  // The scene is shaded and blurred at sub-pixel resolution in a few float buffers of that size: cap it where the
  // thesis preset (4592 x 3056 px at 2 x 2, 56 M) still fits and a hostile size cannot exhaust memory.
  constexpr double kMaxSubPixels = 64e6;
  const double sub_pixels = double(o.camera.image_width_px) * o.camera.image_height_px * o.supersample * o.supersample;
  if (sub_pixels > kMaxSubPixels)
    throw InputError("supersample", std::to_string(o.camera.image_width_px) + " x " +
                                        std::to_string(o.camera.image_height_px) + " px at " +
                                        std::to_string(o.supersample) + " x " + std::to_string(o.supersample) +
                                        " sub-pixels is " + Num(sub_pixels / 1e6) +
                                        " M sub-pixels; the most a scene renders is " + Num(kMaxSubPixels / 1e6) +
                                        " M (lower --supersample or the size)");
}

Json OptionsToJson(const SceneOptions& o) {
  Json j;
  j["tilt_deg"] = o.tilt_deg;
  j["edge1_u_mm"] = o.edge1_u_mm;
  j["lateral_mm"] = o.lateral_mm;
  j["yaw_deg"] = o.yaw_deg;
  j["focus_mm"] = std::isfinite(o.focus_mm) ? Json(o.focus_mm) : Json(nullptr);
  j["focus"] = std::isnan(o.focus_mm) ? "edge 1" : (std::isinf(o.focus_mm) ? "infinity" : "focus_mm");
  j["fixed_r_px"] = o.fixed_r_px ? Json(*o.fixed_r_px) : Json(nullptr);
  j["blur_gain"] = o.blur_gain;
  j["psf"] = o.psf == Psf::kDisc ? "disc" : "gaussian";
  j["white"] = o.white;
  j["black"] = o.black;
  j["table"] = o.table;
  j["noise_std"] = o.noise_std;
  j["jpeg_quality"] = o.jpeg_quality;
  j["flaws"] = o.flaws;
  j["seed"] = o.seed;
  j["supersample"] = o.supersample;
  return j;
}

}  // namespace

Scene RenderScene(const SceneOptions& o) {
  ValidateOptions(o);
  const Board& board = o.board;
  const Camera& cam = o.camera;
  const int W = cam.image_width_px, H = cam.image_height_px, ss = o.supersample;
  const std::array<double, 9> K = cam.Intrinsics();
  const Pose pose = PlaceBoard(o);
  const optics::Lens lens = optics::Lens::FromCamera(cam);

  // The whole board must be in front of the lens and inside the image.
  {
    const double corners[4][2] = {{0, 0}, {board.WidthMm(), 0}, {0, board.LengthMm()},
                                  {board.WidthMm(), board.LengthMm()}};
    for (const auto& c : corners) {
      const cv::Vec3d P = pose.R * cv::Vec3d(c[0], c[1], 0) + pose.t;
      const double px = K[0] * P[0] / P[2] + K[2], py = K[4] * P[1] / P[2] + K[5];
      if (!(P[2] > cam.focal_length_mm) || px < 0 || py < 0 || px > W - 1 || py > H - 1) {
        std::ostringstream s;
        s << "board not fully in view: its corner (" << c[0] << ", " << c[1] << ") mm lands at pixel (" << px
          << ", " << py << ") of a " << W << " x " << H << " image (edge1_u_mm = " << o.edge1_u_mm
          << ", tilt_deg = " << o.tilt_deg << ", yaw_deg = " << o.yaw_deg << ", lateral_mm = " << o.lateral_mm
          << "); move the board farther or turn it less";
        throw InputError("edge1_u_mm", s.str());
      }
    }
  }
  const double edge1_u = (pose.R * cv::Vec3d(board.WidthMm() / 2, 0, 0) + pose.t)[2];
  const double focus = std::isnan(o.focus_mm) ? edge1_u : o.focus_mm;

  View v;
  v.fx = K[0], v.fy = K[4], v.cx = K[2], v.cy = K[5];
  v.ss = ss;
  v.Rt = pose.R.t();
  v.t = pose.t;
  v.n_table = cv::Vec3d(pose.R(0, 2), pose.R(1, 2), pose.R(2, 2));
  v.c_table = v.n_table.dot(pose.t);
  const double th = o.tilt_deg * kPi / 180;
  v.n_wall = cv::Vec3d(0, -std::sin(th), std::cos(th));
  v.up = cv::Vec3d(0, -std::cos(th), -std::sin(th));
  // The back wall stands 1.5 m beyond the board's farthest point; it only shows when the view reaches the horizon.
  double far = 0;
  for (double x : {0.0, board.WidthMm()})
    far = std::max(far, v.n_wall.dot(pose.R * cv::Vec3d(x, board.LengthMm(), 0) + pose.t));
  v.c_wall = far + 1500;
  v.yaw = o.yaw_deg * kPi / 180;
  v.f = lens.focal_length_mm;
  v.k = lens.aperture_mm / (2 * lens.pixel_pitch_mm);
  v.a = std::isinf(focus) ? 1 : 1 / (1 - v.f / focus);
  v.gain = o.blur_gain;
  v.fixed_r = o.fixed_r_px;

  // Pass 1: the range of blur radii, row by row, to choose the levels and the margin.
  const int hss = H * ss, wss = W * ss;
  std::vector<float> row_min(hss), row_max(hss);
  std::atomic<bool> too_near{false};
  cv::parallel_for_(cv::Range(0, hss), [&](const cv::Range& range) {
    std::vector<float> r(wss);
    for (int j = range.start; j < range.end; ++j) {
      if (!RadiusRow(v, j, wss, r.data())) too_near = true;
      const auto [lo, hi] = std::minmax_element(r.begin(), r.end());
      row_min[j] = *lo, row_max[j] = *hi;
    }
  });
  if (too_near)
    throw InputError("tilt_deg", "some of the view is nearer than the focal length or sees no surface (tilt_deg = " +
                                     Num(o.tilt_deg) + ", edge1_u_mm = " + Num(o.edge1_u_mm) + ")");
  const double r_min = *std::min_element(row_min.begin(), row_min.end());
  const double r_max = *std::max_element(row_max.begin(), row_max.end());
  if (r_max > 0.25 * std::min(W, H))
    throw InputError(o.fixed_r_px ? "fixed_r_px" : "focus_mm",
                     "blur up to " + Num(r_max) + " px is more than a quarter of the image; nothing would be left to see");
  const std::vector<Level> levels = ChooseLevels(r_min, r_max, o.fixed_r_px, ss, o.psf);
  int reach = 0;
  for (const Level& l : levels) reach = std::max(reach, l.reach);
  const int m = reach + 2;  // the sharp scene is rendered this far beyond the image: blur brings light in from there

  // Flaws: dark spots on white squares, near an edge, in the middle half of a section.
  Rng flaw_rng(o.seed, kFlawStream);
  std::vector<Flaw> flaws;
  std::vector<std::vector<bool>> flawed(board.EdgeCount(), std::vector<bool>(board.SectionCount(), false));
  Json flaws_json = Json::array();
  const double sq = board.square_mm;
  for (int n = 0; n < o.flaws; ++n) {
    Flaw fl;
    int edge = 0, section = 0, row = -1;
    for (int attempt = 0; attempt < 1000 && row < 0; ++attempt) {
      edge = 1 + flaw_rng.Int(board.EdgeCount());
      section = 1 + flaw_rng.Int(board.SectionCount());
      const int near_row = edge - 2, far_row = edge - 1, col = section - 1;
      const bool near_white = near_row >= 0 && !board.IsBlack(col, near_row);
      const bool far_white = far_row < board.rows && !board.IsBlack(col, far_row);
      if (near_white) row = near_row;
      if (far_white) row = far_row;
    }
    if (row < 0) break;  // no white square next to any edge (cannot happen on a checkerboard)
    fl.radius = flaw_rng.Uniform(0.8, 2.0);
    const double d = fl.radius + flaw_rng.Uniform(0.3, 3.0);  // distance of the centre from the edge line
    const double edge_y = (edge - 1) * sq;
    fl.y = row == edge - 1 ? edge_y + d : edge_y - d;
    fl.x = (section - 0.5) * sq + flaw_rng.Uniform(-0.25, 0.25) * sq;
    fl.value = o.black + 0.1 * (o.white - o.black);
    // Sections whose measurement band (half-way to the neighbouring edges) the spot touches.
    Json touched = Json::array();
    for (int e = 1; e <= board.EdgeCount(); ++e)
      for (int s = 1; s <= board.SectionCount(); ++s) {
        const double ey = (e - 1) * sq;
        const double dx = std::max({0.0, (s - 1) * sq - fl.x, fl.x - s * sq});
        const double dy = std::max(0.0, std::abs(fl.y - ey) - sq / 2);
        if (dx * dx + dy * dy < fl.radius * fl.radius) {
          flawed[e - 1][s - 1] = true;
          touched.push_back({{"edge", e}, {"section", s}});
        }
      }
    // Padded sub-pixel bounding box of the spot.
    double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
    for (int c = 0; c < 16; ++c) {
      const double a = 2 * kPi * c / 16, rr = fl.radius * 1.1 + 0.2;
      const cv::Vec3d P = pose.R * cv::Vec3d(fl.x + rr * std::cos(a), fl.y + rr * std::sin(a), 0) + pose.t;
      const double px = (K[0] * P[0] / P[2] + K[2] + 0.5) * ss - 0.5 + m;
      const double py = (K[4] * P[1] / P[2] + K[5] + 0.5) * ss - 0.5 + m;
      x0 = std::min(x0, px), x1 = std::max(x1, px), y0 = std::min(y0, py), y1 = std::max(y1, py);
    }
    fl.col0 = static_cast<int>(std::floor(x0)) - 2, fl.col1 = static_cast<int>(std::ceil(x1)) + 2;
    fl.row0 = static_cast<int>(std::floor(y0)) - 2, fl.row1 = static_cast<int>(std::ceil(y1)) + 2;
    flaws.push_back(fl);
    flaws_json.push_back({{"x_mm", fl.x}, {"y_mm", fl.y}, {"radius_mm", fl.radius}, {"sections", touched}});
  }

  // Pass 2: the sharp scene, box-filtered per sub-pixel, with and without the board, m sub-pixels beyond the image.
  Rng texture_rng(o.seed, kTextureStream);
  const Wood wood(texture_rng, o.table);
  const double wall_phase = texture_rng.Uniform(0, 2 * kPi);
  const double wall_level = std::clamp(0.5 * (o.table + o.white), 0.0, 1.0);
  const int hp = hss + 2 * m, wp = wss + 2 * m;
  const double cyaw = std::cos(v.yaw), syaw = std::sin(v.yaw);
  // The table and wall are smooth, so they are shaded once per output pixel (footprint: the pixel) over the image
  // plus the margin; the board's edges, which carry the measurement, are shaded per sub-pixel.
  const int mb = (m + ss - 1) / ss;  // margin in whole pixels
  cv::Mat background(H + 2 * mb, W + 2 * mb, CV_32F);
  cv::parallel_for_(cv::Range(0, background.rows), [&](const cv::Range& range) {
    for (int by = range.start; by < range.end; ++by) {
      float* bg = background.ptr<float>(by);
      const double yn = (by - mb - v.cy) / v.fy;
      for (int bx = 0; bx < background.cols; ++bx) {
        const double xn = (bx - mb - v.cx) / v.fx;
        const Hit h = Intersect(v, xn, yn);
        const cv::Vec3d d(xn, yn, 1);
        const cv::Vec3d P = h.s * d;
        if (h.surface == 0) {
          const cv::Vec3d B = v.Rt * (P - v.t);
          const double q = v.n_table.dot(d);
          const cv::Vec3d a = v.Rt * (h.s * (cv::Vec3d(1, 0, 0) - d * (v.n_table[0] / q))) / v.fx;
          const cv::Vec3d b = v.Rt * (h.s * (cv::Vec3d(0, 1, 0) - d * (v.n_table[1] / q))) / v.fy;
          // Table frame: the board frame turned back by yaw (the grain stays put when the board turns).
          const double tx = cyaw * B[0] - syaw * B[1], ty = syaw * B[0] + cyaw * B[1];
          const double tax = cyaw * a[0] - syaw * a[1], tay = syaw * a[0] + cyaw * a[1];
          const double tbx = cyaw * b[0] - syaw * b[1], tby = syaw * b[0] + cyaw * b[1];
          bg[bx] = static_cast<float>(wood(tx, ty, std::sqrt(tax * tax + tbx * tbx), std::sqrt(tay * tay + tby * tby)));
        } else {
          const double height = v.up.dot(P), across = P[0];
          bg[bx] = static_cast<float>(wall_level * (1 + 0.04 * FastSin(2 * kPi * across / 700 + wall_phase) *
                                                            FastSin(2 * kPi * height / 500 + 2 * wall_phase)));
        }
      }
    }
  });
  cv::Mat sharp(hp, wp, CV_32F), sharp_no_board(hp, wp, CV_32F);
  const double bw = board.WidthMm(), bl = board.LengthMm();
  const double dn = 1.0 / (v.fx * ss), dm = 1.0 / (v.fy * ss);  // normalized step per sub-pixel
  const double rt0[3] = {v.Rt(0, 0), v.Rt(0, 1), v.Rt(0, 2)}, rt1[3] = {v.Rt(1, 0), v.Rt(1, 1), v.Rt(1, 2)};
  const cv::Vec3d tb = v.Rt * v.t;  // B = Rt (s d - t) = s (Rt d) - Rt t
  cv::parallel_for_(cv::Range(0, hp), [&](const cv::Range& range) {
    std::vector<double> bx(wp), by(wp), bwx(wp), bwy(wp);
    for (int J = range.start; J < range.end; ++J) {
      float* s = sharp.ptr<float>(J);
      float* s0 = sharp_no_board.ptr<float>(J);
      const float* bg = background.ptr<float>((J - m + mb * ss) / ss);
      const double yn = SubToNormY(v, J - m);
      for (int I = 0; I < wp; ++I) {
        const double xn = SubToNormX(v, I - m);
        const Hit h = Intersect(v, xn, yn);
        const float back = bg[(I - m + mb * ss) / ss];
        s0[I] = back;
        bx[I] = -1e9;
        if (h.surface != 0) {
          s[I] = back;
          continue;
        }
        // Board coordinates of the hit, and the sub-pixel's footprint on the table (d P / d column, d row) in the
        // board frame. Only x and y matter: Rt rows 0 and 1 applied to the ray (rd) and to the camera axes.
        const double rdx = rt0[0] * xn + rt0[1] * yn + rt0[2], rdy = rt1[0] * xn + rt1[1] * yn + rt1[2];
        const double X = h.s * rdx - tb[0], Y = h.s * rdy - tb[1];
        const double q = v.n_table[0] * xn + v.n_table[1] * yn + v.n_table[2];
        const double kx = v.n_table[0] / q, ky = v.n_table[1] / q, sa = h.s * dn, sb = h.s * dm;
        const double ax = sa * (rt0[0] - rdx * kx), ay = sa * (rt1[0] - rdy * kx);
        const double bxx = sb * (rt0[1] - rdx * ky), byy = sb * (rt1[1] - rdy * ky);
        const double wx = std::sqrt(ax * ax + bxx * bxx), wy = std::sqrt(ay * ay + byy * byy);
        bx[I] = X, by[I] = Y, bwx[I] = wx, bwy[I] = wy;
        if (X + wx / 2 <= 0 || X - wx / 2 >= bw || Y + wy / 2 <= 0 || Y - wy / 2 >= bl) {
          s[I] = back;  // off the board
          continue;
        }
        double cover, white_cover;
        BoardCoverage(X, Y, wx, wy, bw, bl, sq, &cover, &white_cover);
        s[I] = static_cast<float>(o.black * (cover - white_cover) + o.white * white_cover + (1 - cover) * back);
      }
      for (const Flaw& fl : flaws) {
        if (J < fl.row0 || J > fl.row1) continue;
        for (int I = std::max(0, fl.col0); I <= std::min(wp - 1, fl.col1); ++I) {
          if (bx[I] < -1e8) continue;
          const double dist = std::hypot(bx[I] - fl.x, by[I] - fl.y);
          const double w = std::sqrt(bwx[I] * bwy[I]);
          const double cov = std::clamp(0.5 + (fl.radius - dist) / w, 0.0, 1.0);
          s[I] = static_cast<float>(s[I] * (1 - cov) + fl.value * cov);
        }
      }
    }
  });

  // Pass 3: depth-varying blur, downsample; then noise, sRGB, JPEG.
  cv::Mat linear = BlurAndDownsample(sharp, v, H, W, levels, ss, m);
  cv::Mat linear_no_board = BlurAndDownsample(sharp_no_board, v, H, W, levels, ss, m);
  sharp.release(), sharp_no_board.release();

  Scene scene;
  scene.image = Finish(linear, o, Rng(o.seed, kNoiseStream));
  scene.image_no_board = Finish(linear_no_board, o, Rng(o.seed, kNoiseNoBoardStream));
  scene.camera = cam;
  scene.board = board;
  cv::Vec3d rvec;
  cv::Rodrigues(pose.R, rvec);
  scene.rvec = rvec;
  scene.tvec = pose.t;
  scene.focus_mm = focus;

  Json sections = Json::array();
  for (int e = 1; e <= board.EdgeCount(); ++e)
    for (int s = 1; s <= board.SectionCount(); ++s) {
      const auto mid = board.SectionMidpoint(e, s);
      const double u = (pose.R * cv::Vec3d(mid[0], mid[1], mid[2]) + pose.t)[2];
      SectionTruth t;
      t.edge = e;
      t.section = s;
      t.u_mm = u;
      t.r_px = o.fixed_r_px ? *o.fixed_r_px : optics::BlurRadiusPx(lens, focus, u) * o.blur_gain;
      t.flawed = flawed[e - 1][s - 1];
      scene.sections.push_back(t);
      sections.push_back({{"edge", e}, {"section", s}, {"u_mm", u}, {"r_px", t.r_px}, {"flawed", t.flawed}});
    }

  Json rotation = Json::array();
  for (int i = 0; i < 3; ++i) rotation.push_back({pose.R(i, 0), pose.R(i, 1), pose.R(i, 2)});
  Json levels_json = Json::array();
  for (const Level& l : levels) levels_json.push_back(l.r_px);
  Json& j = scene.truth;
  j["generator"] = "blurcue synth-scene";
  j["options"] = OptionsToJson(o);
  j["camera"] = CameraToJson(cam);
  j["board"] = {{"cols", board.cols}, {"rows", board.rows}, {"square_mm", board.square_mm}};
  j["pose"] = {{"rvec", {rvec[0], rvec[1], rvec[2]}},
               {"tvec", {pose.t[0], pose.t[1], pose.t[2]}},
               {"rotation", rotation},
               {"convention", "board frame (mm) -> camera (x right, y down, z forward), OpenCV"},
               {"camera_height_mm", -v.c_table}};
  j["focus_mm"] = std::isfinite(focus) ? Json(focus) : Json(nullptr);
  j["focus_at_infinity"] = std::isinf(focus);
  j["aperture_mm"] = lens.aperture_mm;
  j["pixel_pitch_mm"] = lens.pixel_pitch_mm;
  j["psf"] = o.psf == Psf::kDisc ? "disc" : "gaussian";
  j["r_unit"] = "px, 2 x std of the line-spread function, optical only (pixel area excluded)";
  j["r_range_px"] = {r_min, r_max};
  j["blur_levels_px"] = levels_json;
  j["sections"] = sections;
  j["flaws"] = flaws_json;
  return scene;
}

void WriteScene(const Scene& scene, const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  WriteImage(dir / "scene.png", scene.image);
  WriteImage(dir / "scene-no-board.png", scene.image_no_board);
  WriteJsonFile(dir / "camera.json", CameraToJson(scene.camera));
  WriteJsonFile(dir / "truth.json", scene.truth);
}

}  // namespace blurcue::synth
