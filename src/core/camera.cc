#include "core/camera.h"

#include <cmath>
#include <sstream>

#include "core/distortion.h"
#include "core/error.h"
#include "core/names.h"

namespace blurcue {

std::array<double, 9> Camera::Intrinsics() const {
  if (camera_matrix) return *camera_matrix;
  const double fpx = focal_length_mm / PixelPitchMm();
  return {fpx, 0, image_width_px / 2.0, 0, fpx, image_height_px / 2.0, 0, 0, 1};
}

Camera Camera::Viewed(double sx, double sy, double dx, double dy, int width_px, int height_px) const {
  Camera c = *this;
  auto k = Intrinsics();
  k[0] *= sx, k[1] *= sx, k[4] *= sy;
  k[2] = sx * (k[2] + 0.5) - 0.5 + dx;
  k[5] = sy * (k[5] + 0.5) - 0.5 + dy;
  c.camera_matrix = k;
  c.sensor_width_mm = PixelPitchMm() / sx * width_px;
  c.sensor_height_mm = sensor_height_mm / image_height_px / sy * height_px;
  c.image_width_px = width_px;
  c.image_height_px = height_px;
  return c;
}

Camera Camera::Resized(int width_px, int height_px) const {
  Camera c = *this;
  const double sx = static_cast<double>(width_px) / image_width_px;
  const double sy = static_cast<double>(height_px) / image_height_px;
  c.image_width_px = width_px;
  c.image_height_px = height_px;
  if (camera_matrix) {
    auto k = *camera_matrix;
    k[0] *= sx, k[1] *= sx, k[2] *= sx, k[4] *= sy, k[5] *= sy;
    c.camera_matrix = k;
  }
  return c;
}

namespace {

std::string Range(double lo, double hi, const char* unit) {
  return "in [" + Num(lo) + ", " + Num(hi) + "]" + (*unit ? std::string(" ") + unit : "");
}

// Written so that NaN fails: every comparison with NaN is false.
void RequireIn(const std::string& where, const char* field, double v, const double (&range)[2], const char* unit) {
  if (!(v >= range[0] && v <= range[1]))
    throw InputError(where + "/" + field, "must be " + Range(range[0], range[1], unit) + ", got " + Num(v));
}

// An image side in px, read as the JSON's own integer (signed or unsigned, any width) before it is narrowed to an
// int, so 4294968444 is refused rather than wrapped to 1148.
int ImageSidePx(const Json& json, const char* key, const std::string& where) {
  const std::string field = where + "/" + key;
  if (!json.contains(key)) throw InputError(field, "is required but missing");
  const Json& v = json[key];
  if (!v.is_number_integer()) throw InputError(field, "must be an integer, got " + v.dump());
  const bool in = v.is_number_unsigned() ? v.get<uint64_t>() >= 1 && v.get<uint64_t>() <= uint64_t(kMaxImageSidePx)
                                         : v.get<int64_t>() >= 1 && v.get<int64_t>() <= kMaxImageSidePx;
  if (!in) throw InputError(field, "must be " + Range(1, kMaxImageSidePx, "px") + ", got " + v.dump());
  return static_cast<int>(v.get<int64_t>());
}

// Coefficients that fold the photo over (a pixel no ideal point maps onto, or one reached only from beyond the fold,
// where the map's Jacobian has turned) describe no lens for this image: pose, stretch and undistortion would be
// wrong there, silently. A 17 x 17 grid over the photo, its border included (half a pixel beyond the centres).
void CheckNoFold(const Camera& c, const std::string& where) {
  const LensDistortion distortion(c);
  if (distortion.Identity()) return;
  constexpr int kSteps = 16;
  for (int i = 0; i <= kSteps; ++i) {
    for (int j = 0; j <= kSteps; ++j) {
      const Point2 px{-0.5 + double(c.image_width_px) * i / kSteps, -0.5 + double(c.image_height_px) * j / kSteps};
      bool ok = false;
      try {
        const Jacobian2 jac = distortion.JacobianAt(distortion.Undistort(px));
        ok = jac[0] * jac[3] - jac[1] * jac[2] > 0;
      } catch (const Error&) {
      }
      if (ok) continue;
      std::string got;
      for (double d : c.dist_coeffs) got += (got.empty() ? "" : ", ") + Num(d);
      throw InputError(where + "/dist_coeffs",
                       "fold the " + std::to_string(c.image_width_px) + " x " + std::to_string(c.image_height_px) +
                           " px photo over near pixel (" + Num(px[0]) + ", " + Num(px[1]) +
                           "): no lens maps an image there (OpenCV's order: k1 k2 p1 p2 [k3 ...]), got [" + got + "]");
    }
  }
}

}  // namespace

void Camera::Validate(const std::string& where) const {
  RequireIn(where, "focal_length_mm", focal_length_mm, CameraLimits::kFocalLengthMm, "mm");
  RequireIn(where, "f_number", f_number, CameraLimits::kFNumber, "");
  RequireIn(where, "sensor_width_mm", sensor_width_mm, CameraLimits::kSensorMm, "mm");
  RequireIn(where, "sensor_height_mm", sensor_height_mm, CameraLimits::kSensorMm, "mm");
  const double side[2] = {1, kMaxImageSidePx};
  RequireIn(where, "image_width_px", image_width_px, side, "px");
  RequireIn(where, "image_height_px", image_height_px, side, "px");
  // Square pixels: the two pitches may differ by rounding of the resolution, not by more.
  const double pitch_w = sensor_width_mm / image_width_px, pitch_h = sensor_height_mm / image_height_px;
  if (std::abs(pitch_w - pitch_h) > 0.02 * pitch_w)
    throw InputError(where + "/sensor_width_mm, /sensor_height_mm, /image_width_px, /image_height_px",
                     "a " + Num(sensor_width_mm) + " x " + Num(sensor_height_mm) + " mm sensor making " +
                         std::to_string(image_width_px) + " x " + std::to_string(image_height_px) + " px images has pixels " +
                         Num(pitch_w) + " mm wide and " + Num(pitch_h) +
                         " mm tall: one of the four is wrong (non-square pixels are not supported)");
  if (exposure_ms) RequireIn(where, "exposure_ms", *exposure_ms, CameraLimits::kExposureMs, "ms");
  if (camera_matrix) {
    const auto& k = *camera_matrix;
    for (int i = 0; i < 9; ++i)
      if (!std::isfinite(k[i]))
        throw InputError(where + "/camera_matrix/" + std::to_string(i / 3) + "/" + std::to_string(i % 3),
                         "must be finite, got " + Num(k[i]));
    if (!(k[3] == 0 && k[6] == 0 && k[7] == 0 && k[8] == 1))
      throw InputError(where + "/camera_matrix", "must be [[fx,s,cx],[0,fy,cy],[0,0,1]]");
    RequireIn(where, "camera_matrix/0/0", k[0], CameraLimits::kFocalLengthPx, "px");
    RequireIn(where, "camera_matrix/1/1", k[4], CameraLimits::kFocalLengthPx, "px");
    // The scene's projections (render, the objects' outlines) take fx, fy, cx, cy alone: a skew would move the board's
    // pose and not what is drawn on it. OpenCV's calibrateCamera gives 0 (CALIB_FIX_SKEW is its default).
    if (k[1] != 0)
      throw InputError(where + "/camera_matrix/0/1", "(skew) must be 0: blurcue's camera model has none, got " + Num(k[1]));
    // fx and fy are the lens-to-sensor distance in pixels: near focal_length_mm / pitch (more when focused near: twice it
    // at 1:1 magnification). A matrix far from it is another camera's or another image size's; the thin lens takes
    // focal_length_mm, the drawing fx, and they would disagree (an identity matrix drew a 67 px ball as 5 px).
    const double nominal = focal_length_mm / PixelPitchMm();
    for (const int i : {0, 4})
      if (!(k[i] >= 0.5 * nominal && k[i] <= 3 * nominal))
        throw InputError(where + "/camera_matrix/" + std::to_string(i / 3) + "/" + std::to_string(i % 3),
                         "must be within 0.5-3 x focal_length_mm / pixel pitch (" + Num(std::round(nominal)) +
                             " px), got " + Num(k[i]) + ": a matrix for another camera or image size?");
    // The principal point lies on the sensor: anything else is a matrix for another image size.
    const double cx[2] = {0, double(image_width_px)}, cy[2] = {0, double(image_height_px)};
    RequireIn(where, "camera_matrix/0/2", k[2], cx, "px");
    RequireIn(where, "camera_matrix/1/2", k[5], cy, "px");
  }
  const size_t n = dist_coeffs.size();
  if (n != 0 && n != 4 && n != 5 && n != 8 && n != 12 && n != 14)
    throw InputError(where + "/dist_coeffs", "must have 4, 5, 8, 12 or 14 values, got " + std::to_string(n));
  const double coeff[2] = {-CameraLimits::kDistCoeff, CameraLimits::kDistCoeff};
  for (size_t i = 0; i < n; ++i)
    RequireIn(where, ("dist_coeffs/" + std::to_string(i)).c_str(), dist_coeffs[i], coeff, "");
  CheckNoFold(*this, where);
}

Camera CameraFromJson(const Json& json, const std::string& where) {
  Camera c;
  // An unknown key first: a misspelt f_number ("f_numbr") is named with its did-you-mean, not reported as the
  // required f_number missing.
  static const char* kKnown[] = {"focal_length_mm", "f_number", "sensor_width_mm", "sensor_height_mm",
                                 "image_width_px", "image_height_px", "camera_matrix", "dist_coeffs", "exposure_ms",
                                 "name"};
  for (auto it = json.begin(); json.is_object() && it != json.end(); ++it) {
    bool known = false;
    for (const char* k : kKnown) known = known || it.key() == k;
    if (!known)
      throw InputError(where + "/" + it.key(),
                       "is not a camera field" + DidYouMean(it.key(), std::vector<std::string>(std::begin(kKnown),
                                                                                              std::end(kKnown))));
  }
  c.focal_length_mm = RequireNumber(json, "focal_length_mm", where);
  c.f_number = RequireNumber(json, "f_number", where);
  c.sensor_width_mm = RequireNumber(json, "sensor_width_mm", where);
  c.sensor_height_mm = RequireNumber(json, "sensor_height_mm", where);
  c.image_width_px = ImageSidePx(json, "image_width_px", where);
  c.image_height_px = ImageSidePx(json, "image_height_px", where);
  if (json.contains("camera_matrix")) {
    const Json& m = json["camera_matrix"];
    std::array<double, 9> k{};
    bool ok = m.is_array() && m.size() == 3;
    for (size_t r = 0; ok && r < 3; ++r) {
      ok = m[r].is_array() && m[r].size() == 3;
      for (size_t col = 0; ok && col < 3; ++col) {
        ok = m[r][col].is_number();
        if (ok) k[r * 3 + col] = m[r][col].get<double>();
      }
    }
    if (!ok) throw InputError(where + "/camera_matrix", "must be a 3x3 array of numbers, got " + m.dump());
    c.camera_matrix = k;
  }
  if (json.contains("exposure_ms")) c.exposure_ms = RequireNumber(json, "exposure_ms", where);
  if (json.contains("dist_coeffs")) {
    const Json& d = json["dist_coeffs"];
    if (!d.is_array()) throw InputError(where + "/dist_coeffs", "must be an array of numbers, got " + d.dump());
    for (size_t i = 0; i < d.size(); ++i) {
      if (!d[i].is_number())
        throw InputError(where + "/dist_coeffs/" + std::to_string(i), "must be a number, got " + d[i].dump());
      c.dist_coeffs.push_back(d[i].get<double>());
    }
  }
  c.Validate(where);
  return c;
}

Json CameraToJson(const Camera& c) {
  Json j = {{"focal_length_mm", c.focal_length_mm}, {"f_number", c.f_number},
            {"sensor_width_mm", c.sensor_width_mm}, {"sensor_height_mm", c.sensor_height_mm},
            {"image_width_px", c.image_width_px},   {"image_height_px", c.image_height_px}};
  if (c.camera_matrix) {
    const auto& k = *c.camera_matrix;
    j["camera_matrix"] = {{k[0], k[1], k[2]}, {k[3], k[4], k[5]}, {k[6], k[7], k[8]}};
  }
  if (!c.dist_coeffs.empty()) j["dist_coeffs"] = c.dist_coeffs;
  if (c.exposure_ms) j["exposure_ms"] = *c.exposure_ms;
  return j;
}

Camera LoadCamera(const std::filesystem::path& path) {
  return CameraFromJson(ReadJsonFile(path), path.string() + ": ");
}

Camera ThesisCamera() {
  Camera c;
  c.focal_length_mm = 21;
  c.f_number = 5.6;
  c.sensor_width_mm = 23.4;
  c.sensor_height_mm = 15.6;
  c.image_width_px = 4592;
  c.image_height_px = 3056;
  return c;
}

}  // namespace blurcue
