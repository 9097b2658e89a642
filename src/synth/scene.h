#pragma once
// Ground-truth scenes: a checkerboard lying on a table, photographed through a thin lens with known blur.
// Everything is rendered in linear light and encoded to sRGB at the end, like a camera's JPEG/PNG.
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/board.h"
#include "core/camera.h"
#include "core/json_io.h"
#include "synth/post_filter.h"

namespace blurcue::synth {

enum class Psf { kDisc, kGaussian };

struct SceneOptions {
  // Thesis set-up (Table 4.2) at a quarter of its 4592 x 3056 resolution, so the default renders in seconds.
  Camera camera = ThesisCamera().Resized(1148, 764);
  Board board;
  double tilt_deg = 38;        // camera pitched down from the horizontal (the thesis's "tilting angle")
  double edge1_u_mm = 342.3;   // depth (camera z) of the midpoint of edge 1
  double lateral_mm = 0;       // board shifted sideways (board x) from the optical axis
  double yaw_deg = 0;          // board turned about the table normal (0: edges parallel to the image rows)
  // Focus distance (camera z, mm); NaN = on edge 1, as in the thesis; +infinity allowed.
  double focus_mm = std::numeric_limits<double>::quiet_NaN();
  // When set, every pixel gets this blur radius instead of the thin lens's (for measurement tests).
  std::optional<double> fixed_r_px;
  double blur_gain = 1.0;      // multiplies every thin-lens radius (a lens blurrier than ideal)
  Psf psf = Psf::kDisc;
  // The lens floor: every point's defocus PSF convolved with a Gaussian of this std (px), as aberrations,
  // diffraction and demosaicing do in a real camera; 0 = an ideal thin lens.
  double floor_sigma_px = 0;
  // Vignetting: linear light falls off as 1 - vignetting (rho / rho_corner)^2 from the principal point (0.35: the
  // corners get 65 % of the centre's light).
  double vignetting = 0;
  double white = 0.80;         // linear reflectance x exposure of the white squares
  double black = 0.04;         // ... of the black squares
  double table = 0.30;         // mean of the (textured) table
  double noise_std = 0.0;      // Gaussian sensor noise, linear units, plus shot noise of the same scale at white
  // A filter on the sampled image after the sensor noise (demosaicing, sharpening: post_filter.h); none by default.
  PostFilterOptions post_filter;
  int jpeg_quality = 0;        // 0: none; 1..100: JPEG round trip before writing PNG
  int flaws = 0;               // dark printing spots on white squares near edges (thesis Fig. 4.15)
  uint64_t seed = 1;
  // Seed of the sensor noise alone (empty: `seed`): a take's frames share the table and flaws but not the noise.
  std::optional<uint64_t> noise_seed;
  int supersample = 4;         // sub-pixels per pixel side for anti-aliasing and the PSF
};

struct SectionTruth {
  int edge = 0;      // 1-based
  int section = 0;   // 1-based
  double u_mm = 0;   // camera z of the midpoint
  double r_px = 0;   // true optical blur radius at the midpoint (DESIGN.md unit; excludes pixel area): 2 x the std
                     // of the LSF of the kernels actually applied (defocus levels mixed there, floor), from their arrays
  double defocus_r_px = 0;  // the defocus part alone (the thin lens's radius at the midpoint, ideal px)
  // With dist_coeffs: r_px = r_ideal_px x stretch, the blur applied in the ideal (pinhole) image times the map's
  // stretch across the edge at the midpoint (core/distortion.h); both 1:1 without distortion.
  double r_ideal_px = 0, stretch = 1;
  // The blur before the post-sampling filter (r_ideal_px x stretch); r_px adds the filter's second moment to it:
  // r_px^2 = r_optical_px^2 + 4 variance of the filter's taps (0 when the sum is not positive: sharpened past it).
  double r_optical_px = 0;
  bool flawed = false;  // a printing flaw touches this section
};

struct Scene {
  cv::Mat image;           // 8-bit BGR sRGB, with board
  cv::Mat image_no_board;  // the same view with only the table
  Camera camera;
  Board board;
  cv::Vec3d rvec, tvec;    // board frame -> camera (OpenCV convention), mm
  double focus_mm = 0;
  std::vector<SectionTruth> sections;  // edge-major: edges 1..E, sections 1..S
  Json truth;              // everything above plus the options, as written to truth.json
};

// Throws Error(kInput) for impossible options (board not in view, focus <= f, ...), naming the option.
Scene RenderScene(const SceneOptions& options);
// Throws the Error(kInput) RenderScene would throw for these options (an option out of range, a board not wholly in
// view), without rendering: a take checks every frame's view before it writes its first frame.
void CheckSceneOptions(const SceneOptions& options);

// Writes DIR/scene.png, DIR/scene-no-board.png, DIR/camera.json, DIR/truth.json.
void WriteScene(const Scene& scene, const std::filesystem::path& dir);

}  // namespace blurcue::synth
