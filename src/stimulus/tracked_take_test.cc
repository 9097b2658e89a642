// Objects placed in a tracked take, against hand-worked values: a camera translating sideways at a known speed.
#include "stimulus/tracked_take.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "core/error.h"

namespace blurcue::stimulus {
namespace {

// A take of `n` frames 1/30 s apart, the board face-on at 500 mm (identity rotation), the camera moving +10 mm in x a
// frame (the board -10 mm in the camera frame); frame `lost` (or none) has no pose. f = 20 mm, pitch 0.02 mm: 1000 px.
TrackedTake SidewaysTake(int n, int lost = -1) {
  Camera camera;
  camera.focal_length_mm = 20, camera.f_number = 4, camera.sensor_width_mm = 20, camera.sensor_height_mm = 15;
  camera.image_width_px = 1000, camera.image_height_px = 750;
  TrackedTake take;
  for (int i = 0; i < n; ++i) {
    TrackedFrame f;
    f.index = i;
    f.time_s = i / 30.0;
    f.status = i == lost ? track::FrameStatus::kLost : track::FrameStatus::kTracked;
    if (i != lost) {
      calib::SceneCalib c;
      c.camera = camera;
      c.rvec = {0, 0, 0};
      c.tvec = {-10.0 * i, 0, 500};
      f.calib = c;
    }
    take.frames.push_back(f);
  }
  return take;
}

std::vector<PlacedObject> OneBall() {
  PlacedObject p;
  p.name = "ball1";
  p.object = BallAt(0, 0, 10);  // centre at board z = 10: camera z 510
  return {p};
}

TEST(TrackedTake, MotionIsTheImageVelocityTimesTheExposure) {
  const TrackedTake take = SidewaysTake(5);
  TakeBlur blur;
  blur.source = BlurSource::kNone;
  blur.exposure_ms = 15;
  const TrackedFramePlan plan = PlanTrackedFrame(take, 2, OneBall(), blur);
  ASSERT_EQ(plan.drawn.size(), 1u);
  const DrawnObject& d = plan.drawn[0];
  // x = 1000 px x (-20 mm) / 510 mm + 500 px; velocity -10 mm a frame x 30 frames/s -> 1000 x 300 / 510 px/s.
  EXPECT_NEAR(d.screen_px.x, 500 - 1000.0 * 20 / 510, 1e-9);
  EXPECT_NEAR(d.screen_px.y, 375, 1e-9);
  EXPECT_NEAR(d.depth_mm, 510, 1e-9);
  EXPECT_NEAR(d.motion_px[0], -1000.0 * 300 / 510 * 0.015, 1e-9);
  EXPECT_NEAR(d.motion_px[1], 0, 1e-9);
  EXPECT_EQ(plan.objects[0].motion_px, d.motion_px);
}

TEST(TrackedTake, ALostNeighbourGivesTheOneSidedDifferenceAndALostFrameNothing) {
  const TrackedTake take = SidewaysTake(5, 3);
  TakeBlur blur;
  blur.source = BlurSource::kNone;
  blur.exposure_ms = 15;
  // Frame 2's neighbours: 1 and 4 (3 is lost), 3 frames apart: still the same velocity (the motion is linear).
  EXPECT_NEAR(PlanTrackedFrame(take, 2, OneBall(), blur).drawn[0].motion_px[0], -1000.0 * 300 / 510 * 0.015, 1e-9);
  // The last frame: one-sided, from the nearest earlier frame with a pose (2; 3 is lost) to itself.
  EXPECT_NEAR(PlanTrackedFrame(take, 4, OneBall(), blur).drawn[0].motion_px[0], -1000.0 * 300 / 510 * 0.015, 1e-9);
  EXPECT_TRUE(PlanTrackedFrame(take, 3, OneBall(), blur).drawn.empty());
  blur.exposure_ms = 0;
  EXPECT_EQ(PlanTrackedFrame(take, 2, OneBall(), blur).drawn[0].motion_px, cv::Vec2d(0, 0));
}

TEST(TrackedTake, ObjectsFileKeysAreCheckedWithADidYouMean) {
  const Json j = Json::parse(R"({"objects": [{"kind": "card", "x_mm": 1, "y_mm": 2, "widht_mm": 3}]})");
  try {
    PlacedObjectsFromJson(j, "o.json: ");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    EXPECT_NE(std::string(e.what()).find("o.json: /objects/0/widht_mm: unknown key for a card (did you mean width_mm?)"),
              std::string::npos)
        << e.what();
  }
}

// A track.csv over the 16 MiB any text input may have is refused in a track's words, not a JSON file's.
TEST(TrackedTake, ATrackCsvTooLargeIsSaidToBeOne) {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "tracked-take-too-large";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "track.csv") << "frame,time_s,status\n";
  std::filesystem::resize_file(dir / "track.csv", (size_t(16) << 20) + 1);  // sparse: no 16 MiB written
  try {
    LoadTrackedTake(dir);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    EXPECT_NE(std::string(e.what()).find("track.csv: is 16777217 bytes; a track.csv may have at most 16 MiB"),
              std::string::npos)
        << e.what();
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace blurcue::stimulus
