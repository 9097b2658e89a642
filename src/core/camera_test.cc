#include "core/camera.h"

#include <gtest/gtest.h>

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
  EXPECT_EQ(ErrorOf(j), "cam.json: /f_number: must be > 0, got -1");
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
  EXPECT_NE(ErrorOf(j).find("/sensor_height_mm: must be > 0, got 0"), std::string::npos);
  j = ThesisJson();
  j["sensor_height_mm"] = 20;
  EXPECT_NE(ErrorOf(j).find("non-square"), std::string::npos);
}

TEST(Camera, ResizedScalesIntrinsicsNotOptics) {
  Camera c = ThesisCamera().Resized(1148, 764);
  EXPECT_NEAR(c.PixelPitchMm(), 4 * ThesisCamera().PixelPitchMm(), 1e-12);
  EXPECT_DOUBLE_EQ(c.focal_length_mm, 21);
}

}  // namespace
}  // namespace blurcue
