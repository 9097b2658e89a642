#pragma once
// The camera description every module shares: optics (focal length, f-number, sensor) and the image it makes.
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/json_io.h"
#include "core/limits.h"

namespace blurcue {

// What a camera's numbers can physically be. Wider than any real camera, narrow enough that a typo (a focal length
// in metres, a sensor in pixels) or an overflowed integer is refused instead of calibrated.
struct CameraLimits {
  static constexpr double kFocalLengthMm[2] = {0.5, 2000};     // phone ultra-wide .. long telephoto
  static constexpr double kFNumber[2] = {0.5, 256};            // the physical limit .. pinhole-like
  static constexpr double kSensorMm[2] = {0.5, 500};           // a phone sensor's side .. large format
  static constexpr double kFocalLengthPx[2] = {1, 1e6};        // camera_matrix fx, fy
  static constexpr double kDistCoeff = 1e4;                    // |each dist_coeffs value|
  static constexpr double kExposureMs[2] = {0, 60000};         // an instantaneous shutter .. a minute
};

struct Camera {
  double focal_length_mm = 0;
  double f_number = 0;
  double sensor_width_mm = 0;
  double sensor_height_mm = 0;
  int image_width_px = 0;
  int image_height_px = 0;
  // Row-major 3x3 intrinsics in pixels when a lens calibration exists; otherwise derived from the optics.
  std::optional<std::array<double, 9>> camera_matrix;
  std::vector<double> dist_coeffs;  // OpenCV order (k1 k2 p1 p2 [k3 ...]); empty = none
  // The shutter time each image was exposed over, ms: what streaks a moving object's image (EXIF ExposureTime; 0 for
  // an image synthesised at one instant). Empty when unknown.
  std::optional<double> exposure_ms;

  // mm per pixel on the sensor (the thesis's sigma): sensor width / image width.
  double PixelPitchMm() const { return sensor_width_mm / image_width_px; }
  // Aperture diameter D = f / N in mm.
  double ApertureMm() const { return focal_length_mm / f_number; }
  // camera_matrix if given, else fx = fy = f / pitch and the principal point at the image centre.
  std::array<double, 9> Intrinsics() const;
  // The same camera with the image resampled to width x height (intrinsics scaled, optics unchanged).
  Camera Resized(int width_px, int height_px) const;
  // The camera that sees this one's image resampled by (sx, sy) with an area filter (pixel centres at integers:
  // x' = sx (x + 0.5) - 0.5) and then shifted by (dx, dy) px into a width x height image, cropped or letterboxed:
  // what a screen showing the photo at that scale and place shows. Optics and pixel pitch follow the image.
  Camera Viewed(double sx, double sy, double dx, double dy, int width_px, int height_px) const;

  // Throws Error(kInput) "where/field: must be in [lo, hi] unit, got ..." for the first value outside
  // CameraLimits, an image side outside [1, kMaxImageSidePx] px, or a camera_matrix / dist_coeffs that is not
  // finite and shaped as OpenCV's, or dist_coeffs that fold the photo over (no lens maps an image onto some pixel).
  void Validate(const std::string& where) const;
};

// Integers are read without wrapping: 4294968444 px is refused, not taken as 1148.
Camera CameraFromJson(const Json& json, const std::string& where);
Json CameraToJson(const Camera& camera);
// Reads and validates camera.json; errors name the file and the field.
Camera LoadCamera(const std::filesystem::path& path);

// The thesis's camera (Table 4.1/4.2): f = 21 mm, f/5.6, 23.4 x 15.6 mm sensor, 4592 x 3056 px.
Camera ThesisCamera();

}  // namespace blurcue
