#include "core/camera.h"

#include <cmath>
#include <sstream>

#include "core/error.h"

namespace blurcue {

static std::string Num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

std::array<double, 9> Camera::Intrinsics() const {
  if (camera_matrix) return *camera_matrix;
  const double fpx = focal_length_mm / PixelPitchMm();
  return {fpx, 0, image_width_px / 2.0, 0, fpx, image_height_px / 2.0, 0, 0, 1};
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

void Camera::Validate(const std::string& where) const {
  auto positive = [&](const char* field, double v) {
    if (!(v > 0) || !std::isfinite(v)) throw InputError(where + "/" + field, "must be > 0, got " + Num(v));
  };
  positive("focal_length_mm", focal_length_mm);
  positive("f_number", f_number);
  positive("sensor_width_mm", sensor_width_mm);
  positive("sensor_height_mm", sensor_height_mm);
  positive("image_width_px", image_width_px);
  positive("image_height_px", image_height_px);
  // Square pixels: the two pitches may differ by rounding of the resolution, not by more.
  const double pitch_w = sensor_width_mm / image_width_px, pitch_h = sensor_height_mm / image_height_px;
  if (std::abs(pitch_w - pitch_h) > 0.02 * pitch_w)
    throw InputError(where + "/sensor_height_mm", "gives a pixel pitch of " + Num(pitch_h) +
                                                     " mm, but the width gives " + Num(pitch_w) +
                                                     " mm (non-square pixels are not supported)");
  if (camera_matrix) {
    const auto& k = *camera_matrix;
    if (!(k[0] > 0) || !(k[4] > 0) || k[8] != 1)
      throw InputError(where + "/camera_matrix", "must be [[fx,0,cx],[0,fy,cy],[0,0,1]] with fx, fy > 0");
  }
  const size_t n = dist_coeffs.size();
  if (n != 0 && n != 4 && n != 5 && n != 8 && n != 12 && n != 14)
    throw InputError(where + "/dist_coeffs", "must have 4, 5, 8, 12 or 14 values, got " + std::to_string(n));
}

Camera CameraFromJson(const Json& json, const std::string& where) {
  Camera c;
  c.focal_length_mm = RequireNumber(json, "focal_length_mm", where);
  c.f_number = RequireNumber(json, "f_number", where);
  c.sensor_width_mm = RequireNumber(json, "sensor_width_mm", where);
  c.sensor_height_mm = RequireNumber(json, "sensor_height_mm", where);
  c.image_width_px = RequireInt(json, "image_width_px", where);
  c.image_height_px = RequireInt(json, "image_height_px", where);
  static const char* kKnown[] = {"focal_length_mm", "f_number", "sensor_width_mm", "sensor_height_mm",
                                 "image_width_px", "image_height_px", "camera_matrix", "dist_coeffs", "name"};
  for (auto it = json.begin(); it != json.end(); ++it) {
    bool known = false;
    for (const char* k : kKnown) known = known || it.key() == k;
    if (!known) throw InputError(where + "/" + it.key(), "is not a camera field");
  }
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
