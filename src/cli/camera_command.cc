// blurcue camera: camera.json from a photo's EXIF.
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "core/camera.h"
#include "core/camera_exif.h"
#include "core/error.h"
#include "core/json_io.h"
#include "core/output_guard.h"
#include "core/own_output.h"

namespace blurcue::cli {
namespace {

struct CameraArgs {
  std::string photo, out;
  std::vector<double> sensor_mm;
  double focal_length_mm = 0, f_number = 0;  // 0: from the EXIF
};

}  // namespace

void AddCameraCommand(CLI::App& app) {
  auto args = std::make_shared<CameraArgs>();
  std::string sensors;
  for (const KnownSensor& k : KnownSensors()) {
    char line[96];
    std::snprintf(line, sizeof line, "\n  %-22s %5.1f x %4.1f mm", k.model, k.width_mm, k.height_mm);
    sensors += line;
  }
  CLI::App* cmd = app.add_subcommand(
      "camera",
      "Write camera.json (the optics calibrate needs) from a photo's EXIF.\n"
      "Focal length and f-number come from the EXIF FocalLength and FNumber tags; the image size is the photo's as\n"
      "calibrate reads it (EXIF orientation applied). The sensor size comes from, in this order: --sensor-mm, the\n"
      "EXIF focal-plane resolution (FocalPlaneXResolution with its unit, as most cameras write it), the table of\n"
      "sensors below (by EXIF Model), or the 35 mm equivalent focal length (approximate: said so). A missing number\n"
      "is an error naming the tag and the option that gives it, never a guess. The focus distance, where the camera\n"
      "records it (EXIF SubjectDistance), is printed for comparison with the focus calibrate fits from the blur.\n"
      "A lens calibration (camera_matrix, dist_coeffs) is not in EXIF: add it by hand when you have one.\n"
      "Example:\n"
      "  blurcue camera photos/scene.jpg --out scene/camera.json\n"
      "Sensors known by model:" + sensors);
  cmd->add_option("photo", args->photo, "the photo (JPEG with EXIF, as the camera wrote it)")
      ->required()->check(CLI::ExistingFile);
  cmd->add_option("--out", args->out, "camera.json to write (default: print it)");
  cmd->add_option("--sensor-mm", args->sensor_mm, "the sensor's width and height in mm, as the maker gives them")
      ->expected(2)->check(FiniteRange(CameraLimits::kSensorMm[0], CameraLimits::kSensorMm[1], "mm"));
  // The ranges camera.json holds (CameraLimits): a value outside is refused naming the option, not the photo.
  cmd->add_option("--focal-length-mm", args->focal_length_mm, "the focal length, where EXIF lacks it")
      ->check(FiniteRange(CameraLimits::kFocalLengthMm[0], CameraLimits::kFocalLengthMm[1], "mm"));
  cmd->add_option("--f-number", args->f_number, "the f-number, where EXIF lacks it")
      ->check(FiniteRange(CameraLimits::kFNumber[0], CameraLimits::kFNumber[1], ""));
  cmd->callback([args] {
    if (!args->out.empty()) {
      OutputGuard().Input("PHOTO", args->photo).OutputFile("--out", args->out).Check();
      // A camera.json (one's own, written by hand, is the same kind) and nothing else: what the camera.json reader
      // takes whole, so not a protocol or a calib.json that names a focal length.
      RequireOwnFile("--out", args->out, "a camera.json", [&](std::string_view) {
        try {
          LoadCamera(args->out);
          return true;
        } catch (const Error&) {
          return false;
        }
      });
    }
    std::optional<std::pair<double, double>> sensor;
    if (args->sensor_mm.size() == 2) sensor = std::make_pair(args->sensor_mm[0], args->sensor_mm[1]);
    auto given = [](double v) { return v > 0 ? std::optional<double>(v) : std::nullopt; };
    const ExifCamera e = CameraFromExif(args->photo, sensor, given(args->focal_length_mm), given(args->f_number));
    Json j = CameraToJson(e.camera);
    const std::string name = e.make + (e.make.empty() || e.model.empty() ? "" : " ") + e.model;
    if (!name.empty()) j["name"] = name;
    if (args->out.empty()) {
      std::cout << j.dump(2) << "\n";
    } else {
      WriteJsonFile(args->out, j);
      std::cout << "wrote " << args->out << "\n";
    }
    std::cerr << "camera: " << (name.empty() ? "(no make or model in EXIF)" : name) << ", f = "
              << e.camera.focal_length_mm << " mm, f/" << e.camera.f_number << ", sensor "
              << e.camera.sensor_width_mm << " x " << e.camera.sensor_height_mm << " mm from " << e.sensor_source
              << ", image " << e.camera.image_width_px << " x " << e.camera.image_height_px << " px\n";
    if (e.focus_distance_mm)
      std::cerr << "focus distance (EXIF SubjectDistance): " << *e.focus_distance_mm
                << " mm; calibrate fits its own from the blur\n";
    else if (e.focus_at_infinity)
      std::cerr << "focus distance (EXIF SubjectDistance): infinity; calibrate fits its own from the blur\n";
    else
      std::cerr << "focus distance: not in EXIF; calibrate fits it from the blur\n";
    for (const std::string& note : e.notes) std::cerr << "note: " << note << "\n";
  });
}

}  // namespace blurcue::cli
