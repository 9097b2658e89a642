#pragma once
// The synthetic scene's rays (synth/scene.cc): a camera's view of the table and the wall, where a sub-pixel's ray lands
// and the blur radius it gets there. Internal to synth: shared by the scene renderer and its blur (scene_blur.cc).
#include <cmath>
#include <optional>

#include <opencv2/core.hpp>

namespace blurcue::synth::detail {

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
inline bool RadiusRow(const View& v, int j, int wss, float* r) {
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

}  // namespace blurcue::synth::detail
