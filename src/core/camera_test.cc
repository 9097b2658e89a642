#include "core/camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/error.h"

namespace blurcue {
namespace {

Json ThesisJson() { return CameraToJson(ThesisCamera()); }

std::string ErrorOf(const Json& j) {
  try {
    CameraFromJson(j, "cam.json: ");
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    return e.what();
  }
  return "";
}

TEST(Camera, ThesisPitchMatchesTable42) {
  // Table 4.2 gives 5.1e-3 mm/pixel for 23.4 mm over 4592 px.
  EXPECT_NEAR(ThesisCamera().PixelPitchMm(), 5.1e-3, 0.01e-3);
  EXPECT_NEAR(ThesisCamera().ApertureMm(), 3.75, 1e-9);
}

TEST(Camera, RoundTripsThroughJson) {
  Camera c = CameraFromJson(ThesisJson(), "x");
  EXPECT_EQ(c.image_width_px, 4592);
  EXPECT_DOUBLE_EQ(c.f_number, 5.6);
  auto k = c.Intrinsics();
  EXPECT_NEAR(k[0], 21 / (23.4 / 4592), 1e-9);
  EXPECT_DOUBLE_EQ(k[2], 2296);
}

TEST(Camera, RejectsNonPositiveFNumberNamingTheField) {
  Json j = ThesisJson();
  j["f_number"] = -1;
  EXPECT_EQ(ErrorOf(j), "cam.json: /f_number: must be in [0.5, 256], got -1");
}

TEST(Camera, RejectsMissingAndMistypedFields) {
  Json j = ThesisJson();
  j.erase("sensor_width_mm");
  EXPECT_NE(ErrorOf(j).find("/sensor_width_mm: is required"), std::string::npos);
  j = ThesisJson();
  j["image_width_px"] = "wide";
  EXPECT_NE(ErrorOf(j).find("/image_width_px: must be an integer, got \"wide\""), std::string::npos);
  j = ThesisJson();
  j["focal_lenght_mm"] = 21;
  EXPECT_NE(ErrorOf(j).find("/focal_lenght_mm: is not a camera field"), std::string::npos);
}

TEST(Camera, RejectsZeroSensorAndNonSquarePixels) {
  Json j = ThesisJson();
  j["sensor_height_mm"] = 0;
  EXPECT_NE(ErrorOf(j).find("/sensor_height_mm: must be in [0.5, 500] mm, got 0"), std::string::npos);
  j = ThesisJson();
  j["sensor_height_mm"] = 20;
  EXPECT_NE(ErrorOf(j).find("non-square"), std::string::npos);
  // An image width changed alone: the message names the four numbers that decide the pitch, not one of them.
  j = ThesisJson();
  j["image_width_px"] = 4000;
  const std::string e = ErrorOf(j);
  EXPECT_NE(e.find("/image_width_px"), std::string::npos) << e;
  EXPECT_NE(e.find("4000 x 3056 px"), std::string::npos) << e;
}

TEST(Camera, ExposureIsOptionalCheckedAndKept) {
  Json j = ThesisJson();
  EXPECT_FALSE(CameraFromJson(j, "cam.json: ").exposure_ms.has_value());
  EXPECT_FALSE(CameraToJson(CameraFromJson(j, "cam.json: ")).contains("exposure_ms"));
  j["exposure_ms"] = 0;  // a synthesised take: an instantaneous shutter
  EXPECT_EQ(CameraFromJson(j, "cam.json: ").exposure_ms, 0.0);
  j["exposure_ms"] = 16.6667;
  EXPECT_DOUBLE_EQ(CameraToJson(CameraFromJson(j, "cam.json: "))["exposure_ms"].get<double>(), 16.6667);
  j["exposure_ms"] = -1;
  EXPECT_NE(ErrorOf(j).find("/exposure_ms: must be in [0, 60000] ms, got -1"), std::string::npos) << ErrorOf(j);
  j["exposure_ms"] = "1/60";
  EXPECT_NE(ErrorOf(j).find("/exposure_ms"), std::string::npos);
  j.erase("exposure_ms");
  j["exposure"] = 10;
  EXPECT_NE(ErrorOf(j).find("did you mean exposure_ms?"), std::string::npos) << ErrorOf(j);
}

TEST(Camera, ResizedScalesIntrinsicsNotOptics) {
  Camera c = ThesisCamera().Resized(1148, 764);
  EXPECT_NEAR(c.PixelPitchMm(), 4 * ThesisCamera().PixelPitchMm(), 1e-12);
  EXPECT_DOUBLE_EQ(c.focal_length_mm, 21);
}

TEST(Camera, ImageSizeOverflowIsRefusedNotWrapped) {
  // 4294968444 = 2^32 + 1148: read as a 32-bit int it would wrap to a plausible 1148.
  Json j = ThesisJson();
  j["image_width_px"] = 4294968444ULL;
  EXPECT_EQ(ErrorOf(j), "cam.json: /image_width_px: must be in [1, 20000] px, got 4294968444");
  for (long long bad : {0LL, -1148LL, 20001LL, -4294967296LL + 1148}) {
    j["image_width_px"] = bad;
    EXPECT_EQ(ErrorOf(j), "cam.json: /image_width_px: must be in [1, 20000] px, got " + std::to_string(bad));
  }
  j = ThesisJson();
  j["image_height_px"] = 18446744073709551615ULL;
  EXPECT_EQ(ErrorOf(j), "cam.json: /image_height_px: must be in [1, 20000] px, got 18446744073709551615");
}

TEST(Camera, EveryNumberHasAPhysicalRangeWithItsUnit) {
  const struct {
    const char* field;
    double value;
    const char* message;
  } cases[] = {
      {"focal_length_mm", 1e308, "/focal_length_mm: must be in [0.5, 2000] mm, got 1e+308"},
      {"focal_length_mm", 21000, "/focal_length_mm: must be in [0.5, 2000] mm, got 21000"},
      {"f_number", 0.1, "/f_number: must be in [0.5, 256], got 0.1"},
      {"sensor_width_mm", -23.4, "/sensor_width_mm: must be in [0.5, 500] mm, got -23.4"},
      {"sensor_height_mm", 1e308, "/sensor_height_mm: must be in [0.5, 500] mm, got 1e+308"},
  };
  for (const auto& c : cases) {
    Json j = ThesisJson();
    j[c.field] = c.value;
    EXPECT_EQ(ErrorOf(j), std::string("cam.json: ") + c.message);
  }
}

TEST(Camera, NonFiniteValuesAreRefused) {
  // JSON has no NaN, but a camera built in code can: Validate names the field.
  Camera c = ThesisCamera();
  c.f_number = std::nan("");
  try {
    c.Validate("camera");
    FAIL() << "NaN f-number accepted";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "camera/f_number: must be in [0.5, 256], got nan");
  }
  Json j = ThesisJson();
  j["camera_matrix"] = {{4000.0, 0.0, 2296.0}, {0.0, 4000.0, 1528.0}, {0.0, 0.0, 1.0}};
  EXPECT_EQ(ErrorOf(j), "");
  j["camera_matrix"][0][2] = INFINITY;
  EXPECT_EQ(ErrorOf(j), "cam.json: /camera_matrix/0/2: must be finite, got inf");
  j["camera_matrix"][0][2] = 1e9;
  EXPECT_EQ(ErrorOf(j), "cam.json: /camera_matrix/0/2: must be in [0, 4592] px, got 1e+09");
  j["camera_matrix"][0][2] = 2296.0;
  j["camera_matrix"][0][1] = 1030.0;  // a skew the pose took and the drawing did not
  EXPECT_EQ(ErrorOf(j), "cam.json: /camera_matrix/0/1: (skew) must be 0: blurcue's camera model has none, got 1030");
  j["camera_matrix"] = {{1.0, 0.0, 2296.0}, {0.0, 4000.0, 1528.0}, {0.0, 0.0, 1.0}};  // another camera's
  EXPECT_EQ(ErrorOf(j), "cam.json: /camera_matrix/0/0: must be within 0.5-3 x focal_length_mm / pixel pitch (4121 px), "
                        "got 1: a matrix for another camera or image size?");
  j = ThesisJson();
  j["dist_coeffs"] = {0.1, -0.2, 0.0, 0.0, 1e308};
  EXPECT_EQ(ErrorOf(j), "cam.json: /dist_coeffs/4: must be in [-10000, 10000], got 1e+308");
}

TEST(Camera, DistortionThatFoldsThePhotoIsRefused) {
  // k1 = -1: rho (1 - rho^2) peaks at rho = 1/sqrt(3) (0.385 distorted); the thesis photo's corner lies at a
  // distorted rho of 0.67 (half its diagonal over f = 4121 px), which no ideal point reaches.
  Json j = ThesisJson();
  j["dist_coeffs"] = {-1.0, 0.0, 0.0, 0.0};
  EXPECT_EQ(ErrorOf(j), "cam.json: /dist_coeffs: fold the 4592 x 3056 px photo over near pixel (-0.5, -0.5): no lens "
                        "maps an image there (OpenCV's order: k1 k2 p1 p2 [k3 ...]), got [-1, 0, 0, 0]");
  // k1 = -0.3 stays monotonic out to rho = 1.05 (0.70 distorted), past the corner: a strong barrel, accepted; so
  // is pincushion of any strength (rho (1 + k1 rho^2) only grows).
  j["dist_coeffs"] = {-0.3, 0.0, 0.0, 0.0};
  EXPECT_EQ(ErrorOf(j), "");
  j["dist_coeffs"] = {5.0, 0.0, 0.0, 0.0};
  EXPECT_EQ(ErrorOf(j), "");
  // k1 = -0.5 folds at rho = 0.816 (0.544 distorted), short of the photo's corner (0.67).
  j["dist_coeffs"] = {-0.5, 0.0, 0.0, 0.0};
  EXPECT_NE(ErrorOf(j).find("/dist_coeffs: fold the 4592 x 3056 px photo over near pixel"), std::string::npos);
}

TEST(Camera, UnknownFieldSaysTheNearestName) {
  Json j = ThesisJson();
  j["dist_coef"] = {0.0, 0.0, 0.0, 0.0};
  EXPECT_EQ(ErrorOf(j), "cam.json: /dist_coef: is not a camera field (did you mean dist_coeffs?)");
}

}  // namespace
}  // namespace blurcue
