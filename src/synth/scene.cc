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
#include <opencv2/imgcodecs.hpp>  // its flags (the functions: core/media.h)
#include "core/media.h"
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/image.h"
#include "optics/thin_lens.h"
#include "core/distortion.h"
#include "synth/scene_blur.h"
#include "synth/scene_distort.h"
#include "synth/scene_view.h"

namespace blurcue::synth {
namespace {

using detail::BlurAndDownsample;
using detail::Hit;
using detail::ChooseLevels;
using detail::Intersect;
using detail::Level;
using detail::RadiusRow;
using detail::SubToNormX;
using detail::SubToNormY;
using detail::View;

constexpr double kPi = 3.14159265358979323846;

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
  // After the noise, as a camera's pipeline filters the sensor's samples (the noise too).
  ApplyPostFilter(linear, PostFilterTaps(o.post_filter));
  cv::Mat grey8 = EncodeSrgb8(linear), bgr;
  cv::cvtColor(grey8, bgr, cv::COLOR_GRAY2BGR);
  if (o.jpeg_quality > 0) {
    std::vector<uint8_t> bytes;
    media::Imencode(".jpg", bgr, &bytes, {cv::IMWRITE_JPEG_QUALITY, o.jpeg_quality});
    bgr = media::Imdecode(bytes, cv::IMREAD_COLOR);
  }
  return bgr;
}

void ValidateOptions(const SceneOptions& o) {
  o.camera.Validate("camera");
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
  if (!(o.floor_sigma_px >= 0 && o.floor_sigma_px <= 20))
    throw InputError("floor_sigma_px", "must be in [0, 20] px, got " + Num(o.floor_sigma_px));
  if (!(o.vignetting >= 0 && o.vignetting <= 0.9))
    throw InputError("vignetting", "must be in [0, 0.9] (fall-off at the image corner), got " + Num(o.vignetting));
  if (!(o.noise_std >= 0 && o.noise_std <= 1))
    throw InputError("noise_std", "must be in [0, 1] (linear units), got " + Num(o.noise_std));
  if (o.post_filter.kind != PostFilter::kNone && !(o.post_filter.sigma_px > 0 && o.post_filter.sigma_px <= 5))
    throw InputError("post_sigma_px", "must be in (0, 5] px with a post filter, got " + Num(o.post_filter.sigma_px));
  if (o.post_filter.kind == PostFilter::kSharpen && !(o.post_filter.amount > 0 && o.post_filter.amount <= 5))
    throw InputError("post_amount", "must be in (0, 5] to sharpen, got " + Num(o.post_filter.amount));
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
  if (o.noise_seed) j["noise_seed"] = *o.noise_seed;
  j["supersample"] = o.supersample;
  j["floor_sigma_px"] = o.floor_sigma_px;
  j["vignetting"] = o.vignetting;
  j["post_filter"] = Name(o.post_filter.kind);
  if (o.post_filter.kind != PostFilter::kNone) j["post_sigma_px"] = o.post_filter.sigma_px;
  if (o.post_filter.kind == PostFilter::kSharpen) j["post_amount"] = o.post_filter.amount;
  return j;
}

}  // namespace

namespace {

// What RenderScene checks before it renders: the options, the canvas behind a distorted photo, the whole board in view.
struct SceneGeometry {
  Pose pose;
  detail::IdealCanvas canvas;
};

SceneGeometry CheckedGeometry(const SceneOptions& o) {
  ValidateOptions(o);
  const Board& board = o.board;
  const Camera& cam = o.camera;
  const int W = cam.image_width_px, H = cam.image_height_px, ss = o.supersample;
  const std::array<double, 9> K = cam.Intrinsics();
  const Pose pose = PlaceBoard(o);
  // With dist_coeffs the ideal (pinhole) view is rendered and blurred on a canvas covering every ray the photo sees,
  // then warped onto the photo's pixels (scene_distort.h); without, the canvas is the photo.
  const LensDistortion distortion(cam);
  detail::IdealCanvas canvas{0, 0, W, H};
  if (!distortion.Identity()) {
    try {
      canvas = detail::CanvasFor(distortion, W, H);
    } catch (const Error& e) {
      throw InputError("camera/dist_coeffs", e.what());
    }
  }
  const int Wi = canvas.width, Hi = canvas.height;
  if (double(Wi) * Hi * ss * ss > 64e6)
    throw InputError("camera/dist_coeffs", "the undistorted view behind the photo is " + std::to_string(Wi) + " x " +
                                               std::to_string(Hi) + " px, more than a scene renders at " +
                                               std::to_string(ss) + " x " + std::to_string(ss) +
                                               " sub-pixels (lower --supersample or the size)");

  // The whole board must be in front of the lens and inside the image.
  {
    const double corners[4][2] = {{0, 0}, {board.WidthMm(), 0}, {0, board.LengthMm()},
                                  {board.WidthMm(), board.LengthMm()}};
    for (const auto& c : corners) {
      const cv::Vec3d P = pose.R * cv::Vec3d(c[0], c[1], 0) + pose.t;
      const Point2 image = distortion.Distort({K[0] * P[0] / P[2] + K[2], K[4] * P[1] / P[2] + K[5]});
      const double px = image[0], py = image[1];
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
  return {pose, canvas};
}

}  // namespace

void CheckSceneOptions(const SceneOptions& options) { CheckedGeometry(options); }

namespace {

// The camera, pose and lens as the shading and blur passes read them (scene_view.h).
View MakeView(const SceneOptions& o, const Pose& pose, const detail::IdealCanvas& canvas, double focus) {
  const Board& board = o.board;
  const std::array<double, 9> K = o.camera.Intrinsics();
  const optics::Lens lens = optics::Lens::FromCamera(o.camera);
  const int ss = o.supersample;
  View v;
  v.fx = K[0], v.fy = K[4], v.cx = K[2] + canvas.ox, v.cy = K[5] + canvas.oy;
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
  return v;
}

// Pass 1: the range of blur radii {min, max} over the hss x wss sub-pixels, row by row, to choose the levels and
// the margin; a view nearer than the focal length, or blur over a quarter of the image, refused.
std::pair<double, double> BlurRange(const View& v, const SceneOptions& o, int hss, int wss) {
  const int W = o.camera.image_width_px, H = o.camera.image_height_px;
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
  return {r_min, r_max};
}

// Flaws: dark spots on white squares, near an edge, in the middle half of a section; each with its padded sub-pixel
// bounding box (m sub-pixels of margin), the sections it touches marked in touched_sections, listed in truth.
std::vector<Flaw> PlaceFlaws(const SceneOptions& o, const Pose& pose, const View& v, int m,
                             std::vector<std::vector<bool>>* touched_sections, Json* truth) {
  const Board& board = o.board;
  const std::array<double, 9> K = o.camera.Intrinsics();
  const int ss = o.supersample;
  Rng flaw_rng(o.seed, kFlawStream);
  std::vector<Flaw> flaws;
  std::vector<std::vector<bool>>& flawed = *touched_sections;
  flawed.assign(board.EdgeCount(), std::vector<bool>(board.SectionCount(), false));
  Json& flaws_json = *truth;
  flaws_json = Json::array();
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
      const double px = (K[0] * P[0] / P[2] + v.cx + 0.5) * ss - 0.5 + m;
      const double py = (K[4] * P[1] / P[2] + v.cy + 0.5) * ss - 0.5 + m;
      x0 = std::min(x0, px), x1 = std::max(x1, px), y0 = std::min(y0, py), y1 = std::max(y1, py);
    }
    fl.col0 = static_cast<int>(std::floor(x0)) - 2, fl.col1 = static_cast<int>(std::ceil(x1)) + 2;
    fl.row0 = static_cast<int>(std::floor(y0)) - 2, fl.row1 = static_cast<int>(std::ceil(y1)) + 2;
    flaws.push_back(fl);
    flaws_json.push_back({{"x_mm", fl.x}, {"y_mm", fl.y}, {"radius_mm", fl.radius}, {"sections", touched}});
  }
  return flaws;
}

// The table and wall, shaded once per output pixel over the ideal canvas (Wi x Hi) plus mb pixels each side.
cv::Mat ShadeBackground(const View& v, const Wood& wood, double wall_phase, double wall_level, int Wi, int Hi,
                        int mb) {
  const double cyaw = std::cos(v.yaw), syaw = std::sin(v.yaw);
  // The table and wall are smooth, so they are shaded once per output pixel (footprint: the pixel) over the image
  // plus the margin; the board's edges, which carry the measurement, are shaded per sub-pixel.
  cv::Mat background(Hi + 2 * mb, Wi + 2 * mb, CV_32F);
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
  return background;
}

// Light fall-off on the sensor, from the photo's principal point: `amount` at the farthest corner.
void Vignette(double amount, const std::array<double, 9>& K, int W, int H, std::initializer_list<cv::Mat*> images) {
  const double cx = K[2], cy = K[5];
  const double rho2_corner = std::max({cx * cx + cy * cy, (W - 1 - cx) * (W - 1 - cx) + cy * cy,
                                       cx * cx + (H - 1 - cy) * (H - 1 - cy),
                                       (W - 1 - cx) * (W - 1 - cx) + (H - 1 - cy) * (H - 1 - cy)});
  for (cv::Mat* img : images)
    for (int y = 0; y < H; ++y) {
      float* p = img->ptr<float>(y);
      for (int x = 0; x < W; ++x) {
        const double rho2 = (x - cx) * (x - cx) + (y - cy) * (y - cy);
        p[x] = static_cast<float>(p[x] * (1 - amount * rho2 / rho2_corner));
      }
    }
}

// Every section's truth (what was applied: the mixed levels' and the floor's variances, the distortion's stretch,
// the post filter's taps) and truth.json's content, into scene.
void AddTruth(Scene* out, const SceneOptions& o, const Pose& pose, const View& v, const std::vector<Level>& levels,
              double floor_var_px2, std::pair<double, double> r_range,
              const std::vector<std::vector<bool>>& flawed, const Json& flaws_json) {
  Scene& scene = *out;
  const Board& board = o.board;
  const Camera& cam = o.camera;
  const std::array<double, 9> K = cam.Intrinsics();
  const int ss = o.supersample;
  const optics::Lens lens = optics::Lens::FromCamera(cam);
  const LensDistortion distortion(cam);
  const double focus = scene.focus_mm, r_min = r_range.first, r_max = r_range.second;
  const cv::Vec3d rvec = scene.rvec;
  // The post-sampling filter's taps as applied (float), and their second moment: every section's truth adds it.
  const std::vector<float> post_taps = PostFilterTaps(o.post_filter);
  const double post_var_px2 = PostFilterVariancePx2(post_taps);
  Json sections = Json::array();
  for (int e = 1; e <= board.EdgeCount(); ++e)
    for (int s = 1; s <= board.SectionCount(); ++s) {
      const auto mid = board.SectionMidpoint(e, s);
      const double u = (pose.R * cv::Vec3d(mid[0], mid[1], mid[2]) + pose.t)[2];
      SectionTruth t;
      t.edge = e;
      t.section = s;
      t.u_mm = u;
      t.defocus_r_px = o.fixed_r_px ? *o.fixed_r_px : optics::BlurRadiusPx(lens, focus, u) * o.blur_gain;
      // Truth is what was applied: the mixed defocus levels' and the floor taps' variances from their arrays (in
      // ideal px), times the distortion's stretch across the edge at the midpoint (1 without distortion).
      const double var_px2 = detail::AppliedVarianceSs(levels, t.defocus_r_px, ss) / (double(ss) * ss) + floor_var_px2;
      auto ideal_px = [&](const std::array<double, 3>& b) {
        const cv::Vec3d P = pose.R * cv::Vec3d(b[0], b[1], b[2]) + pose.t;
        return Point2{K[0] * P[0] / P[2] + K[2], K[4] * P[1] / P[2] + K[5]};
      };
      const Point2 a = ideal_px(board.SectionStart(e, s)), b = ideal_px(board.SectionEnd(e, s));
      t.stretch = distortion.StretchAcross(ideal_px(mid), {a[1] - b[1], b[0] - a[0]});
      t.r_ideal_px = 2 * std::sqrt(var_px2);
      t.r_optical_px = t.r_ideal_px * t.stretch;
      t.r_px = std::sqrt(std::max(0.0, t.r_optical_px * t.r_optical_px + 4 * post_var_px2));
      t.flawed = flawed[e - 1][s - 1];
      scene.sections.push_back(t);
      Json row = {{"edge", e}, {"section", s}, {"u_mm", u}, {"r_px", t.r_px}, {"defocus_r_px", t.defocus_r_px},
                  {"flawed", t.flawed}};
      if (!distortion.Identity()) row["r_ideal_px"] = t.r_ideal_px, row["stretch"] = t.stretch;
      if (post_taps.size() > 1) row["r_optical_px"] = t.r_optical_px;
      sections.push_back(row);
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
  j["r_unit"] = distortion.Identity()
                   ? "px, 2 x std of the line-spread function of the kernels applied (defocus and floor), optical only "
                     "(pixel area excluded)"
                   : "photo px, 2 x std of the line-spread function across the edge of the kernels applied (defocus "
                     "and floor, in ideal px: r_ideal_px) times the distortion's stretch across the edge at the "
                     "section's midpoint (stretch = 1 / |J^-T n|), optical only (pixel area excluded)";
  j["floor_sigma_applied_px"] = std::sqrt(floor_var_px2);
  // The whole view's blur with the floor (every point has it: nothing in the view is sharper than the floor), and the
  // defocus alone (the lens formula's range, before discretisation).
  if (post_taps.size() > 1) j["post_filter"] = PostFilterTruth(o.post_filter, post_taps);
  // (and the post-sampling filter's, where there is one).
  const double added_px2 = 4 * (floor_var_px2 + post_var_px2);
  j["r_range_px"] = {std::sqrt(std::max(0.0, r_min * r_min + added_px2)),
                     std::sqrt(std::max(0.0, r_max * r_max + added_px2))};
  j["defocus_r_range_px"] = {r_min, r_max};
  j["blur_levels_px"] = levels_json;
  j["sections"] = sections;
  j["flaws"] = flaws_json;
}

// Pass 2's board: each sub-pixel of the hp x wp sharp scene (m sub-pixels beyond the image) box-filtered over its
// footprint on the board, the flaws drawn over it, the background behind (mb pixels of margin); the same view
// without the board beside it.
std::pair<cv::Mat, cv::Mat> ShadeSharp(const View& v, const SceneOptions& o, const std::vector<Flaw>& flaws,
                                       const cv::Mat& background, int hp, int wp, int m, int mb) {
  const Board& board = o.board;
  const int ss = o.supersample;
  cv::Mat sharp(hp, wp, CV_32F), sharp_no_board(hp, wp, CV_32F);
  const double bw = board.WidthMm(), bl = board.LengthMm(), sq = board.square_mm;
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
  return {sharp, sharp_no_board};
}

}  // namespace

Scene RenderScene(const SceneOptions& o) {
  const SceneGeometry geometry = CheckedGeometry(o);
  const Board& board = o.board;
  const Camera& cam = o.camera;
  const int W = cam.image_width_px, H = cam.image_height_px, ss = o.supersample;
  const std::array<double, 9> K = cam.Intrinsics();
  const Pose& pose = geometry.pose;
  const LensDistortion distortion(cam);
  const detail::IdealCanvas& canvas = geometry.canvas;
  const int Wi = canvas.width, Hi = canvas.height;
  const double edge1_u = (pose.R * cv::Vec3d(board.WidthMm() / 2, 0, 0) + pose.t)[2];
  const double focus = std::isnan(o.focus_mm) ? edge1_u : o.focus_mm;
  const View v = MakeView(o, pose, canvas, focus);

  const int hss = Hi * ss, wss = Wi * ss;
  const std::pair<double, double> r_range = BlurRange(v, o, hss, wss);
  const std::vector<Level> levels = ChooseLevels(r_range.first, r_range.second, o.fixed_r_px, ss, o.psf);
  int reach = 0;
  for (const Level& l : levels) reach = std::max(reach, l.reach);
  // The floor is spatially invariant, so it is applied to the sharp scene first (convolution commutes); its
  // truth is its taps' variance, not the sigma asked for.
  const std::vector<double> floor_taps = detail::FloorTaps(o.floor_sigma_px, ss);
  const int floor_reach = static_cast<int>(floor_taps.size()) / 2;
  const double floor_var_px2 = detail::TapsVariance(floor_taps) / (double(ss) * ss);
  // The sharp scene is rendered this far beyond the image: blur brings light in from there.
  const int m = reach + floor_reach + 2;

  std::vector<std::vector<bool>> flawed;
  Json flaws_json;
  const std::vector<Flaw> flaws = PlaceFlaws(o, pose, v, m, &flawed, &flaws_json);

  // Pass 2: the sharp scene, box-filtered per sub-pixel, with and without the board, m sub-pixels beyond the image.
  Rng texture_rng(o.seed, kTextureStream);
  const Wood wood(texture_rng, o.table);
  const double wall_phase = texture_rng.Uniform(0, 2 * kPi);
  const double wall_level = std::clamp(0.5 * (o.table + o.white), 0.0, 1.0);
  const int hp = hss + 2 * m, wp = wss + 2 * m;
  // The table and wall are smooth, so they are shaded once per output pixel (footprint: the pixel) over the image
  // plus the margin; the board's edges, which carry the measurement, are shaded per sub-pixel.
  const int mb = (m + ss - 1) / ss;  // margin in whole pixels
  const cv::Mat background = ShadeBackground(v, wood, wall_phase, wall_level, Wi, Hi, mb);
  auto [sharp, sharp_no_board] = ShadeSharp(v, o, flaws, background, hp, wp, m, mb);

  // Pass 3: the floor, depth-varying blur, downsample, vignetting; then noise, sRGB, JPEG.
  if (floor_reach > 0) {
    const cv::Mat k(floor_taps, true);
    cv::Mat k32;
    k.convertTo(k32, CV_32F);
    for (cv::Mat* img : {&sharp, &sharp_no_board})
      cv::sepFilter2D(*img, *img, CV_32F, k32, k32, cv::Point(-1, -1), 0, cv::BORDER_REPLICATE);
  }
  cv::Mat linear, linear_no_board;
  if (distortion.Identity()) {
    linear = BlurAndDownsample(sharp, v, H, W, levels, ss, m);
    linear_no_board = BlurAndDownsample(sharp_no_board, v, H, W, levels, ss, m);
    sharp.release(), sharp_no_board.release();
  } else {
    std::vector<cv::Mat> ideal = {BlurAndDownsample(sharp, v, Hi, Wi, levels, ss, m, true)};
    sharp.release();
    ideal.push_back(BlurAndDownsample(sharp_no_board, v, Hi, Wi, levels, ss, m, true));
    sharp_no_board.release();
    std::vector<cv::Mat> photo = detail::DistortAndDownsample(ideal, distortion, canvas, ss, H, W);
    linear = photo[0], linear_no_board = photo[1];
  }
  if (o.vignetting > 0) Vignette(o.vignetting, K, W, H, {&linear, &linear_no_board});

  Scene scene;
  scene.image = Finish(linear, o, Rng(o.noise_seed.value_or(o.seed), kNoiseStream));
  scene.image_no_board = Finish(linear_no_board, o, Rng(o.noise_seed.value_or(o.seed), kNoiseNoBoardStream));
  scene.camera = cam;
  scene.board = board;
  cv::Vec3d rvec;
  cv::Rodrigues(pose.R, rvec);
  scene.rvec = rvec;
  scene.tvec = pose.t;
  scene.focus_mm = focus;

  AddTruth(&scene, o, pose, v, levels, floor_var_px2, r_range, flawed, flaws_json);
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
