#pragma once
// A camera.json from a photo's EXIF (libexif, Debian's libexif-dev): what the camera itself recorded.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/camera.h"

namespace blurcue {

// Where each number came from, for the experimenter to check.
struct ExifCamera {
  Camera camera;                           // validated; image size as calibrate decodes the photo (EXIF orientation applied)
  std::string make, model;                 // as recorded, trimmed
  std::string sensor_source;               // "focal-plane resolution", "sensor table (MODEL)", "35 mm equivalent (...)"
  std::optional<double> focus_distance_mm; // EXIF SubjectDistance when recorded (not infinity, not 0 = unknown)
  bool focus_at_infinity = false;          // EXIF SubjectDistance says infinity (0xFFFFFFFF/1)
  std::vector<std::string> notes;          // approximations and what was missing
};

// The sensor sizes of a few cameras, by EXIF Model, for photos whose EXIF lacks the focal-plane resolution.
struct KnownSensor {
  const char* model;
  double width_mm, height_mm;
};
const std::vector<KnownSensor>& KnownSensors();

// Reads PHOTO's EXIF. The sensor size comes from, in this order: `sensor_mm` (given by the experimenter), the
// focal-plane resolution, the sensor table, the 35 mm equivalent focal length (approximate: said in notes).
// Throws Error(kInput) naming the file and the tag when a number is missing or impossible ("photo.jpg: EXIF
// FNumber (0x829d) is missing; give --f-number"), never a guess. f_number and focal_length_mm override the EXIF.
ExifCamera CameraFromExif(const std::filesystem::path& photo, std::optional<std::pair<double, double>> sensor_mm = {},
                          std::optional<double> focal_length_mm = {}, std::optional<double> f_number = {});

}  // namespace blurcue
