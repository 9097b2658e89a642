#include "scene/stimuli.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <opencv2/core/utility.hpp>

#include "core/data_dir.h"
#include "core/error.h"
#include "core/image.h"
#include "core/names.h"

namespace blurcue::scene {

std::filesystem::path ResolveStimulus(const std::string& name) {
  if (std::filesystem::exists(name)) return name;
  const auto shipped = DataDir().path / "stimuli" / (name + ".png");
  if (std::filesystem::exists(shipped)) return shipped;
  // The shipped ones by name, so a misspelt or guessed one is answered with what there is.
  std::vector<std::string> names;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(DataDir().path / "stimuli", error))
    if (entry.path().extension() == ".png") names.push_back(entry.path().stem().string());
  std::sort(names.begin(), names.end());
  std::string listed;
  for (const std::string& n : names) listed += (listed.empty() ? "" : ", ") + n;
  throw InputError(name, "no such image, and no shipped stimulus " + shipped.string() +
                             (listed.empty() ? std::string() : " (shipped: " + listed + ")") + DidYouMean(name, names));
}

namespace {

// Colours are linear-light BGR; the thesis's soccer pattern was "colour balanced", so neither panel colour clips.
const cv::Vec3d kWarmWhite{0.80, 0.85, 0.87};
const cv::Vec3d kNearBlack{0.06, 0.06, 0.06};
const cv::Vec3d kSeamGrey{0.03, 0.03, 0.03};
const cv::Vec3d kCardWhite{0.85, 0.85, 0.85};
const cv::Vec3d kInkBlack{0.02, 0.02, 0.02};

void CheckWidth(const char* where, int width_px, int min_px, bool even) {
  if (width_px < min_px || (even && width_px % 2 != 0))
    throw Error(ErrorKind::kUsage, std::string(where) + ": width must be " + (even ? "even and " : "") + ">= " +
                                       std::to_string(min_px) + " px, got " + std::to_string(width_px));
}

double Clamp01(double v) { return std::clamp(v, 0.0, 1.0); }
double Smoothstep(double a, double b, double x) {
  const double t = Clamp01((x - a) / (b - a));
  return t * t * (3 - 2 * t);
}
cv::Vec3d Mix(const cv::Vec3d& a, const cv::Vec3d& b, double t) { return a * (1 - t) + b * t; }

// Linear BGR (CV_64FC3) -> 8-bit sRGB BGR; optional linear alpha (CV_64FC1) appended as a fourth channel.
cv::Mat Encode(const cv::Mat& linear_bgr, const cv::Mat& alpha = cv::Mat()) {
  cv::Mat f32;
  linear_bgr.convertTo(f32, CV_32F);
  cv::Mat bgr8 = EncodeSrgb8(f32);
  if (alpha.empty()) return bgr8;
  cv::Mat a8;
  alpha.convertTo(a8, CV_8U, 255.0);  // alpha is coverage, stored linearly (PNG convention)
  cv::Mat bgra8;
  std::vector<cv::Mat> planes;
  cv::split(bgr8, planes);
  planes.push_back(a8);
  cv::merge(planes, bgra8);
  return bgra8;
}

// ---- Soccer ball ------------------------------------------------------------------------------------------------

// The truncated icosahedron's 32 faces: unit normal and plane distance from the centre. A direction d lies on the
// face whose plane the ray t d hits first, t = h / (n . d): the face with the largest (n / h) . d.
struct Polyhedron {
  std::array<cv::Vec3d, 32> scaled_normal;  // n / h
  std::array<bool, 32> pentagon;
  // Angular distance from d to the great circle bounding faces i and j is asin(((n_i/h_i - n_j/h_j) . d) / norm).
  std::array<std::array<double, 32>, 32> inv_bisector_norm;
};

Polyhedron MakeTruncatedIcosahedron() {
  // Icosahedron with a vertex at each pole; the upper ring at phi = 0, 72, ..., the lower ring offset by 36 deg.
  std::vector<cv::Vec3d> v{{0, 0, 1}};
  const double z = 1 / std::sqrt(5.0), r = 2 / std::sqrt(5.0);
  for (int k = 0; k < 5; ++k) v.emplace_back(r * std::cos(2 * M_PI * k / 5), r * std::sin(2 * M_PI * k / 5), z);
  for (int k = 0; k < 5; ++k)
    v.emplace_back(r * std::cos(2 * M_PI * (k + 0.5) / 5), r * std::sin(2 * M_PI * (k + 0.5) / 5), -z);
  v.emplace_back(0, 0, -1);
  // Neighbours on the unit icosahedron have v_i . v_j = 1 / sqrt(5); others -1/sqrt(5) or -1.
  auto adjacent = [&](int i, int j) { return i != j && v[i].dot(v[j]) > 0.3; };
  Polyhedron p{};
  int f = 0;
  for (int i = 0; i < 12; ++i) {
    // Pentagon at vertex i: cut through the points one third along each edge from it.
    int j = 0;
    while (!adjacent(i, j)) ++j;
    const cv::Vec3d cut = v[i] + (v[j] - v[i]) / 3.0;
    p.scaled_normal[f] = v[i] / cut.dot(v[i]);
    p.pentagon[f++] = true;
  }
  for (int i = 0; i < 12; ++i)
    for (int j = i + 1; j < 12; ++j)
      for (int k = j + 1; k < 12; ++k)
        if (adjacent(i, j) && adjacent(j, k) && adjacent(i, k)) {
          // Hexagon on an icosahedron face: the face's own plane survives the truncation.
          const cv::Vec3d c = (v[i] + v[j] + v[k]) / 3.0;
          p.scaled_normal[f] = c / c.dot(c);
          p.pentagon[f++] = false;
        }
  CV_Assert(f == 32);
  for (int i = 0; i < 32; ++i)
    for (int j = 0; j < 32; ++j)
      p.inv_bisector_norm[i][j] = i == j ? 0 : 1 / cv::norm(p.scaled_normal[i] - p.scaled_normal[j]);
  return p;
}

// The face a direction falls on, and its angular distance (rad) to the face's border.
int PanelAt(const Polyhedron& p, const cv::Vec3d& d, double* border_rad) {
  std::array<double, 32> score;
  int best = 0;
  for (int i = 0; i < 32; ++i) {
    score[i] = p.scaled_normal[i].dot(d);
    if (score[i] > score[best]) best = i;
  }
  // The panel is a convex spherical polygon, so the distance to its border is the least distance to any of the
  // great circles that bound it against another face (circles of non-neighbours lie farther away).
  double sin_min = 1;
  for (int j = 0; j < 32; ++j)
    if (j != best) sin_min = std::min(sin_min, (score[best] - score[j]) * p.inv_bisector_norm[best][j]);
  *border_rad = std::asin(std::clamp(sin_min, 0.0, 1.0));
  return best;
}

cv::Vec3d PanelColour(const Polyhedron& p, int face, double border_rad, double seam_half_rad) {
  if (border_rad < seam_half_rad) return kSeamGrey;
  return p.pentagon[face] ? kNearBlack : kWarmWhite;
}

// ---- Smooth noise for wood --------------------------------------------------------------------------------------

// Value noise on a hashed integer lattice; tables drawn from std::mt19937_64 with our own mapping and Fisher–Yates,
// so the image is the same with every standard library.
class ValueNoise {
 public:
  explicit ValueNoise(uint64_t seed) {
    std::mt19937_64 rng(seed);
    for (int i = 0; i < 256; ++i) perm_[i] = static_cast<uint8_t>(i);
    for (int i = 255; i > 0; --i) std::swap(perm_[i], perm_[rng() % static_cast<uint64_t>(i + 1)]);
    for (double& value : values_) value = static_cast<double>(rng() >> 11) * 0x1.0p-53;
  }
  // In [0, 1], smooth (C2) in p.
  double operator()(const cv::Vec3d& p) const {
    const double fx = std::floor(p[0]), fy = std::floor(p[1]), fz = std::floor(p[2]);
    const int x = static_cast<int>(fx), y = static_cast<int>(fy), z = static_cast<int>(fz);
    auto fade = [](double t) { return t * t * t * (t * (t * 6 - 15) + 10); };
    const double u = fade(p[0] - fx), v = fade(p[1] - fy), w = fade(p[2] - fz);
    auto at = [&](int i, int j, int k) { return values_[perm_[(perm_[(perm_[i & 255] + j) & 255] + k) & 255]]; };
    auto lerp = [](double a, double b, double t) { return a + (b - a) * t; };
    return lerp(lerp(lerp(at(x, y, z), at(x + 1, y, z), u), lerp(at(x, y + 1, z), at(x + 1, y + 1, z), u), v),
                lerp(lerp(at(x, y, z + 1), at(x + 1, y, z + 1), u),
                     lerp(at(x, y + 1, z + 1), at(x + 1, y + 1, z + 1), u), v),
                w);
  }
  // Fractal sum of octaves, in [0, 1].
  double Fbm(cv::Vec3d p, int octaves) const {
    double sum = 0, amplitude = 0.5, total = 0;
    for (int o = 0; o < octaves; ++o) {
      sum += amplitude * (*this)(p);
      total += amplitude;
      p = p * 2.03 + cv::Vec3d(17.1, 31.7, 5.3);
      amplitude *= 0.5;
    }
    return sum / total;
  }

 private:
  std::array<uint8_t, 256> perm_;
  std::array<double, 256> values_;
};

double Uniform(std::mt19937_64& rng, double lo, double hi) {
  return lo + (hi - lo) * static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

// ---- Face drawing -----------------------------------------------------------------------------------------------

// Approximate signed distance to an ellipse (negative inside), good near the edge where anti-aliasing needs it.
double EllipseSdf(double x, double y, double a, double b) {
  const double k0 = std::hypot(x / a, y / b), k1 = std::hypot(x / (a * a), y / (b * b));
  return k1 > 0 ? k0 * (k0 - 1) / k1 : -std::min(a, b);
}
double CircleSdf(double x, double y, double r) { return std::hypot(x, y) - r; }
double Gauss(double x, double y, double sx, double sy) { return std::exp(-0.5 * (x * x / (sx * sx) + y * y / (sy * sy))); }

struct FaceGeometry {
  double px;  // one pixel in drawing units (the picture spans u in [-1, 1], v in [-1.5, 1.5], v down)

  double Coverage(double sdf) const { return Clamp01(0.5 - sdf / px); }

  // Egg-shaped face: narrower towards the chin.
  double FaceSdf(double u, double v) const {
    const double s = Smoothstep(0.0, 1.3, v), k = 1 - 0.14 * s;
    return EllipseSdf(u / k, v - 0.12, 0.76, 1.1) * k;
  }
  // Hair behind the head, cut at shoulder-length.
  double HairBackSdf(double u, double v) const {
    return std::max(EllipseSdf(u, v + 0.28, 0.93, 1.08), v - 0.55 - 0.06 * u * u);
  }
  // Fringe over the forehead, swept to one side.
  double FringeSdf(double u, double v) const {
    const double hairline = -0.6 + 0.25 * u * u + 0.1 * u + 0.03 * std::sin(9 * u);
    return std::max(EllipseSdf(u, v + 0.28, 0.93, 1.08), v - hairline);
  }
};

cv::Vec3d FaceColour(const FaceGeometry& g, double u, double v, double* alpha) {
  const cv::Vec3d skin{0.35, 0.50, 0.80}, hair{0.012, 0.028, 0.065}, lips{0.12, 0.12, 0.50},
      iris{0.10, 0.20, 0.28}, eye_white{0.80, 0.82, 0.84}, dark{0.015, 0.015, 0.02}, cheek{0.40, 0.35, 0.85};
  const cv::Vec3d light = cv::normalize(cv::Vec3d(-0.45, -0.55, 0.7));

  // Hair: shaded as a sphere lit from the upper left, with fine strands running down from the crown.
  auto hair_colour = [&](double hu, double hv) {
    const double nx = std::clamp(hu / 0.93, -1.0, 1.0), ny = std::clamp((hv + 0.28) / 1.08, -1.0, 1.0);
    const double nz = std::sqrt(std::max(0.0, 1 - nx * nx - ny * ny));
    const double diffuse = std::max(0.0, cv::Vec3d(nx, ny, nz).dot(light));
    const double strands = 0.9 + 0.1 * std::sin(90 * std::atan2(hu - 0.3, hv + 2.4));
    return hair * (0.5 + 1.3 * diffuse) * strands;
  };

  const double a_hair = g.Coverage(g.HairBackSdf(u, v));
  const double a_face = g.Coverage(g.FaceSdf(u, v));
  // Premultiplied "over": hair behind, face in front.
  cv::Vec3d premult = hair_colour(u, v) * a_hair;
  double a = a_hair;

  // Skin, shaded as an ellipsoid lit from the upper left.
  const double nx = std::clamp(u / 0.8, -1.0, 1.0), ny = std::clamp((v - 0.12) / 1.15, -1.0, 1.0);
  const double nz = std::sqrt(std::max(0.0, 1 - nx * nx - ny * ny));
  const double diffuse = std::max(0.0, cv::Vec3d(nx, ny, nz).dot(light));
  cv::Vec3d c = skin * (0.45 + 0.6 * diffuse);
  // Cheeks.
  c = Mix(c, cheek * (0.45 + 0.6 * diffuse), 0.35 * (Gauss(u - 0.42, v - 0.33, 0.12, 0.09) +
                                                     Gauss(u + 0.42, v - 0.33, 0.12, 0.09)));
  // Nose: shadow down its shaded side and under the tip, a highlight on the tip, two nostrils.
  c *= 1 - 0.35 * Gauss(u - 0.09, v - 0.12, 0.035, 0.2) - 0.3 * Gauss(u, v - 0.38, 0.1, 0.03);
  c = Mix(c, skin, 0.3 * Gauss(u + 0.01, v - 0.26, 0.04, 0.04));
  c *= 1 - 0.6 * (Gauss(u - 0.065, v - 0.33, 0.025, 0.015) + Gauss(u + 0.065, v - 0.33, 0.025, 0.015));
  // Mouth: lips between two curves, corners turned up; a dark line between them.
  {
    const double t = std::clamp(u / 0.24, -1.0, 1.0), mid = 0.64 - 0.05 * t * t, bulge = std::sqrt(1 - t * t);
    const double lip_sdf = std::max({std::abs(u) - 0.24, mid - 0.06 * bulge - v, v - mid - 0.07 * bulge});
    c = Mix(c, lips * (0.5 + 0.6 * diffuse) * (v < mid ? 0.8 : 1.0), g.Coverage(lip_sdf));
    c = Mix(c, dark, g.Coverage(std::max(std::abs(v - mid) - 0.007 * (0.3 + 0.7 * bulge), std::abs(u) - 0.25)));
    c *= 1 - 0.25 * Gauss(u, v - 0.8, 0.12, 0.035);  // shadow under the lower lip
  }
  // Eyes: shadowed sockets, white almond, iris, pupil, highlight, lid line; brows above.
  for (double side : {-1.0, 1.0}) {
    const double ex = u - side * 0.3, ey = v + 0.12;
    c *= 1 - 0.2 * Gauss(ex, ey + 0.02, 0.17, 0.1);
    const double eye_sdf = EllipseSdf(ex, ey, 0.165, 0.075);
    c = Mix(c, eye_white, g.Coverage(eye_sdf));
    c = Mix(c, iris, g.Coverage(std::max(CircleSdf(ex + 0.01, ey, 0.07), eye_sdf)));
    c = Mix(c, dark, g.Coverage(std::max(CircleSdf(ex + 0.01, ey, 0.033), eye_sdf)));
    c = Mix(c, eye_white * 1.15, g.Coverage(CircleSdf(ex + 0.035, ey + 0.025, 0.014)));
    const double lid = std::max(std::abs(eye_sdf + 0.003) - 0.011, ey - 0.01);
    c = Mix(c, dark, g.Coverage(lid));
    const double bt = std::clamp(ex / 0.2, -1.0, 1.0);
    const double brow_mid = -0.31 - 0.055 * (1 - bt * bt) + 0.02 * side * bt;
    // Thick near the nose, tapering to a point at the temple.
    const double taper = side * bt > 0 ? 1 - bt * bt : 1 - 0.5 * bt * bt;
    const double brow = std::max(std::abs(v - brow_mid) - 0.03 * taper, std::abs(ex) - 0.2);
    c = Mix(c, hair * 1.3, g.Coverage(brow));
  }
  // Fringe over the forehead, casting a soft shadow below it.
  const double fringe_sdf = g.FringeSdf(u, v);
  c *= 1 - 0.3 * Smoothstep(0.08, 0.0, fringe_sdf);
  c = Mix(c, hair_colour(u, v), g.Coverage(fringe_sdf));

  premult = c * a_face + premult * (1 - a_face);
  a = a_face + a * (1 - a_face);
  *alpha = a;
  return a > 0 ? premult / a : cv::Vec3d(0, 0, 0);
}

}  // namespace

cv::Vec3d EquirectDirection(double x, double y, int width_px) {
  const int height_px = width_px / 2;
  const double theta = M_PI * (y + 0.5) / height_px, phi = 2 * M_PI * (x + 0.5) / width_px;
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

cv::Mat SoccerTexture(int width_px, double seam_width_deg) {
  CheckWidth("SoccerTexture", width_px, 16, true);
  if (!(seam_width_deg >= 0 && seam_width_deg < 10))
    throw Error(ErrorKind::kUsage, "SoccerTexture: seam_width_deg must be in [0, 10), got " +
                                       std::to_string(seam_width_deg));
  static const Polyhedron poly = MakeTruncatedIcosahedron();
  const double seam_half_rad = seam_width_deg / 2 * M_PI / 180;
  // No texel spans more than pi / H in latitude or longitude (longitude texels shrink towards the poles), so one
  // whose centre lies farther than that from every border and seam is one flat colour: sample it once.
  const double texel_reach_rad = M_PI / (width_px / 2);
  constexpr int kSub = 3;  // 3 x 3 supersampling elsewhere, averaged in linear light
  cv::Mat linear(width_px / 2, width_px, CV_64FC3);
  cv::parallel_for_(cv::Range(0, linear.rows), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y)
      for (int x = 0; x < width_px; ++x) {
        double border_rad = 0;
        const int face = PanelAt(poly, EquirectDirection(x, y, width_px), &border_rad);
        if (border_rad - seam_half_rad > texel_reach_rad) {
          linear.at<cv::Vec3d>(y, x) = PanelColour(poly, face, border_rad, seam_half_rad);
          continue;
        }
        cv::Vec3d sum(0, 0, 0);
        for (int sy = 0; sy < kSub; ++sy)
          for (int sx = 0; sx < kSub; ++sx) {
            const cv::Vec3d d = EquirectDirection(x + (sx + 0.5) / kSub - 0.5, y + (sy + 0.5) / kSub - 0.5, width_px);
            const int f = PanelAt(poly, d, &border_rad);
            sum += PanelColour(poly, f, border_rad, seam_half_rad);
          }
        linear.at<cv::Vec3d>(y, x) = sum / double(kSub * kSub);
      }
  });
  return Encode(linear);
}

cv::Mat WoodTexture(int width_px, uint64_t seed) {
  CheckWidth("WoodTexture", width_px, 16, true);
  const ValueNoise noise(seed);
  // The ball is cut from a log whose pith runs beside it: the axis is tilted a little and offset from the centre
  // by a seeded amount, so each seed shows a different part of the ring pattern.
  std::mt19937_64 rng(seed ^ 0x9E3779B97F4A7C15ull);
  const double tilt = Uniform(rng, -0.25, 0.25), turn = Uniform(rng, 0, 2 * M_PI);
  const cv::Vec3d axis = cv::normalize(cv::Vec3d(1, tilt * std::cos(turn), tilt * std::sin(turn)));
  const cv::Vec3d e1 = cv::normalize(axis.cross(cv::Vec3d(0, 0, 1))), e2 = axis.cross(e1);
  const double pith_angle = Uniform(rng, 0, 2 * M_PI), pith_distance = Uniform(rng, 0.6, 1.4);
  const cv::Vec3d pith = pith_distance * (std::cos(pith_angle) * e1 + std::sin(pith_angle) * e2);
  const double rings_per_unit = Uniform(rng, 7, 10);
  const cv::Vec3d light_wood{0.18, 0.40, 0.68}, dark_wood{0.018, 0.06, 0.19};

  auto colour = [&](const cv::Vec3d& d) {
    const double along = d.dot(axis);
    // A slightly wavy axis: the pith wanders with distance along the log.
    const cv::Vec3d wobble = 0.12 * (noise(cv::Vec3d(along * 1.2, 3.5, 7.1)) - 0.5) * e1 +
                             0.12 * (noise(cv::Vec3d(along * 1.2, 11.3, 2.9)) - 0.5) * e2;
    const cv::Vec3d q = d - pith - wobble - along * axis;
    const double r = cv::norm(q) + 0.05 * noise.Fbm(d * 2.5, 3);
    // Rings: wide light earlywood, narrower dark latewood.
    const double wave = 0.5 + 0.5 * std::sin(2 * M_PI * rings_per_unit * r);
    const double ring = Smoothstep(0.35, 1.0, wave) * (0.6 + 0.5 * noise(cv::Vec3d(r * rings_per_unit, 0.5, 9.5)));
    // Fine grain: noise stretched along the axis.
    const double cross1 = d.dot(e1), cross2 = d.dot(e2);
    const double grain = noise.Fbm(cv::Vec3d(along * 3, cross1 * 45, cross2 * 45), 2);
    const double blotch = noise.Fbm(d * 1.5 + cv::Vec3d(40, 40, 40), 3);
    const cv::Vec3d c = Mix(light_wood, dark_wood, Clamp01(0.65 * ring + 0.35 * grain - 0.08));
    return c * (0.8 + 0.4 * blotch);
  };

  // One sample per texel: the finest grain (45 cycles per unit, about 280 around the equator) is band-limited
  // well below the texel rate of the sizes we use, and equirectangular texels only shrink towards the poles.
  cv::Mat linear(width_px / 2, width_px, CV_64FC3);
  cv::parallel_for_(cv::Range(0, linear.rows), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y)
      for (int x = 0; x < width_px; ++x) linear.at<cv::Vec3d>(y, x) = colour(EquirectDirection(x, y, width_px));
  });
  return Encode(linear);
}

double GridLineWidthPx(int size_px, int cells) { return size_px / (8.0 * cells); }
double GridLinePositionPx(int size_px, int i, int cells) {
  return i * (size_px - GridLineWidthPx(size_px, cells)) / double(cells);
}

cv::Mat GridBoard(int size_px, int cells) {
  if (cells < 1 || cells > 100) throw Error(ErrorKind::kDomain, "GridBoard: cells must be 1-100, got " +
                                                                    std::to_string(cells));
  CheckWidth("GridBoard", size_px, std::max(40, 8 * cells), false);
  const double w = GridLineWidthPx(size_px, cells);
  // Exact ink coverage of each pixel column (row) by the cells + 1 lines, so edges are anti-aliased in linear light.
  std::vector<double> ink(size_px, 0.0);
  for (int i = 0; i <= cells; ++i) {
    const double a = GridLinePositionPx(size_px, i, cells), b = a + w;
    for (int p = std::max(0, int(std::floor(a))); p < std::min(size_px, int(std::ceil(b))); ++p)
      ink[p] += std::max(0.0, std::min(b, p + 1.0) - std::max(a, double(p)));
  }
  cv::Mat linear(size_px, size_px, CV_64FC3);
  for (int y = 0; y < size_px; ++y)
    for (int x = 0; x < size_px; ++x) {
      const double paper = (1 - Clamp01(ink[x])) * (1 - Clamp01(ink[y]));
      linear.at<cv::Vec3d>(y, x) = Mix(kInkBlack, kCardWhite, paper);
    }
  return Encode(linear, cv::Mat(size_px, size_px, CV_64F, cv::Scalar(1.0)));
}

cv::Mat FacePicture(int width_px) {
  CheckWidth("FacePicture", width_px, 16, true);
  const int height_px = width_px * 3 / 2;
  const FaceGeometry g{2.0 / width_px};
  cv::Mat linear(height_px, width_px, CV_64FC3), alpha(height_px, width_px, CV_64F);
  cv::parallel_for_(cv::Range(0, height_px), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y)
      for (int x = 0; x < width_px; ++x) {
        const double u = (x + 0.5) * g.px - 1, v = (y + 0.5) * g.px - 1.5;
        linear.at<cv::Vec3d>(y, x) = FaceColour(g, u, v, &alpha.at<double>(y, x));
      }
  });
  return Encode(linear, alpha);
}

std::vector<std::filesystem::path> WriteStandardStimuli(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> written;
  auto write = [&](const char* name, const cv::Mat& image) {
    // WriteImage reports encoder failures as Error but lets the folder's filesystem_error through; make that an
    // input error too, so the command's exit code says "bad path" rather than "bug".
    try {
      WriteImage(dir / name, image);
    } catch (const std::filesystem::filesystem_error& e) {
      throw InputError((dir / name).string(), std::string("cannot write: ") + e.code().message());
    }
    written.push_back(dir / name);
  };
  write("soccer.png", SoccerTexture(2048));
  write("wood.png", WoodTexture(2048, 1));
  write("grid.png", GridBoard(1024));
  write("face.png", FacePicture(800));
  return written;
}

}  // namespace blurcue::scene
