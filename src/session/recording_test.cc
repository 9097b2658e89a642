#include "session/recording.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "scene/frame.h"
#include "procedure/observer.h"
#include "stimulus/test_scenes.h"
#include "store/export.h"
#include "store/record.h"
#include "store/test_util.h"

namespace blurcue::session {
namespace {

using stimulus::DescribeTrial;
using stimulus::Presentation;
using stimulus::TrialScene;
using stimulus::fixtures::BallProtocol;
using stimulus::fixtures::PairTrial;
using stimulus::fixtures::ThesisScene;

// Edge 11's grid cards (stimulus's DescribeTrial.GridCardsSitBesideTheBoardAtTheirEdge) fitted into a 1920 x 1080
// window: each radius recorded as the camera made it, as the window shows it and as the eye gets it.
TEST(TrialVariables, GridTrialRecordsEachRadiusInPhotoPxScreenPxAndArcmin) {
  const calib::SceneCalib scene = ThesisScene();
  protocol::Protocol p = BallProtocol();
  p.content.type = protocol::ContentType::kGrid;
  const TrialScene far = DescribeTrial(p, PairTrial({{"edge", 11}}, "estimated", "fitted"), &scene);
  // A 4592 x 3056 photo fitted into a 1920 x 1080 window: 1080 / 3056 of a photo px per screen px, floored to
  // whole shown pixels (1622 of 1622.8); on the default monitor (37.84 px per degree) that is the arcmin.
  Presentation shown;
  shown.frame_width_px = 4592, shown.frame_height_px = 3056, shown.window_width_px = 1920, shown.window_height_px = 1080;
  shown.scale = scene::FitScale(4592, 3056, 1920, 1080);
  const Json v = TrialVariables(PairTrial({{"edge", 2}}, "measured", "fitted"), far, shown);
  for (const char* key : {"edge", "practice", "block_name", "swapped", "r_left_px", "r_right_px", "r_scene_px",
                          "r_left_screen_px", "r_right_arcmin", "r_scene_arcmin", "screen_px_per_photo_px"})
    EXPECT_TRUE(v.contains(key)) << key;
  const double r = far.side(protocol::Side::kRight).r_px;
  EXPECT_NEAR(v["r_right_screen_px"].get<double>(), r * 1622.0 / 4592.0, 1e-4);
  const double pitch_mm = 531.4 / 1920, deg = 180 / 3.14159265358979323846;
  EXPECT_NEAR(v["r_right_arcmin"].get<double>(), 2 * std::atan(0.5 * r * 1622.0 / 4592.0 * pitch_mm / 600) * deg * 60,
              1e-4);
}

// Each object's depth and its place in the picture reach the record: u as the scene worked it out (its geometry is
// stimulus's DescribeTrial.AnObjectsDepthIsTheCalibrationsGeometryAtItsEdge), and the elevation on the display as the
// visual angle of the image's offset from the principal point, atan(offset px x scale x mm per px / distance).
TEST(TrialVariables, RecordsEachObjectsDepthAndElevation) {
  const calib::SceneCalib scene = ThesisScene();
  protocol::Protocol p = BallProtocol();
  p.content.type = protocol::ContentType::kGrid;
  const TrialScene t = DescribeTrial(p, PairTrial({{"edge", 11}}, "fitted", "fitted"), &scene);
  Presentation shown;
  shown.scale = 1.5;
  const Json v = TrialVariables(PairTrial({{"edge", 11}}, "fitted", "fitted"), t, shown);
  EXPECT_NEAR(v["u_left_mm"].get<double>(), t.side(protocol::Side::kLeft).u_mm, 0.005);
  EXPECT_NEAR(v["u_right_mm"].get<double>(), t.side(protocol::Side::kRight).u_mm, 0.005);
  const double pitch_mm = 531.4 / 1920, deg = 180 / 3.14159265358979323846;
  EXPECT_NEAR(v["elevation_left_deg"].get<double>(),
              -std::atan(t.side(protocol::Side::kLeft).below_axis_px * 1.5 * pitch_mm / 600) * deg, 1e-4);
  EXPECT_GT(v["elevation_left_deg"].get<double>(), 0);  // edge 11 lies above the principal point (the board's far end)
  // The single layout has no right object: nothing is recorded for it.
  TrialScene single = t;
  single.left_only = true;
  const Json one = TrialVariables(PairTrial({{"edge", 11}}, "fitted", "fitted"), single, shown);
  EXPECT_TRUE(one.contains("u_left_mm"));
  EXPECT_FALSE(one.contains("u_right_mm"));
  EXPECT_FALSE(one.contains("elevation_right_deg"));
}

// A staircase steps by adding: 0.5 - 0.1 - 0.1 - 0.1 is 0.20000000000000004 in binary, which trials.csv wrote as
// such. The level shown is recorded as the protocol gives its numbers (0.2), in the variables and the typed column.
TEST(ShownVariables, RecordAProceduresLevelAsTheProtocolWritesIt) {
  const calib::SceneCalib scene = ThesisScene();
  protocol::Protocol p = BallProtocol();
  p.content.type = protocol::ContentType::kGrid;
  TrialScene t = DescribeTrial(p, PairTrial({{"edge", 6}}, "fitted", "fitted"), &scene);
  protocol::Trial trial = PairTrial({{"edge", 6}}, "fitted", "fitted");
  trial.cell = 0, trial.test_side = "right";
  t.level = 0.5 - 0.1 - 0.1 - 0.1;
  ASSERT_NE(t.level, 0.2);  // the binary sum, as the staircase reaches it
  Presentation shown;
  shown.scale = 1;
  const Json v = Json::parse(ShownVariables(trial, t, shown, procedure::Scored{true, std::nullopt, std::nullopt}));
  EXPECT_EQ(v["level"].get<double>(), 0.2);
  EXPECT_EQ(v["level"].dump(), "0.2");
  EXPECT_EQ(TrialVariables(trial, t, shown)["level"].dump(), "0.2");
}

// The per-pixel plan (stimulus's PlanOnScreen.PerPixelExactlyWhenTheObjectsDepthSpanReachesTheThresholdOnScreen) is
// recorded as such.
TEST(TrialVariables, RecordsThePerPixelBlurPlan) {
  const calib::SceneCalib scene = ThesisScene();
  protocol::Protocol p = BallProtocol();
  p.content.type = protocol::ContentType::kGrid;
  TrialScene t = DescribeTrial(p, PairTrial({{"edge", 2}}, "fitted", "fitted"), &scene);
  Presentation shown;
  shown.scale = 0.5;
  p.content.depth_blur_threshold = 1e-6;
  stimulus::PlanOnScreen(p, scene, shown, &t);
  ASSERT_TRUE(t.per_pixel);
  EXPECT_EQ(TrialVariables(PairTrial({{"edge", 2}}, "fitted", "fitted"), t, shown)["blur_plan"], "per_pixel");
  t.per_pixel = false;
  EXPECT_EQ(TrialVariables(PairTrial({{"edge", 2}}, "fitted", "fitted"), t, shown)["blur_plan"], "one_radius");
}

// A level named like something the record or trials.csv holds of its own (a conditions table's r_left_px, status or
// participant; a staircase block's level, test_side or correct) is recorded as factor_NAME with its own value, and
// the variable recorded under that name is the one the trial showed: neither overwrites the other. Every name
// recorded beside the levels is one store::IsRecordedName reserves, so no future variable can take a level's place.
TEST(TrialVariables, LevelsNamedLikeRecordedVariablesKeepTheirValuesUnderFactorNames) {
  const calib::SceneCalib scene = ThesisScene();
  protocol::Protocol p = BallProtocol();
  p.content.type = protocol::ContentType::kGrid;
  const Json row = {{"edge", 2}, {"status", "x"}, {"participant", "P8"}, {"r_left_px", 7.5}, {"info_age", 40},
                    {"level", 99}, {"test_side", "left"}, {"correct", 1}, {"label", "near"}};
  protocol::Trial trial = PairTrial({{"row", row}, {"group", "g"}}, "fitted", "fitted");
  trial.cell = 0;  // a procedure's trial: level, test_side and the procedure cell are recorded
  trial.test_side = "right";
  TrialScene t = DescribeTrial(p, trial, &scene);
  t.level = 0.4;
  Presentation shown;
  shown.scale = 0.5;
  const Json v = TrialVariables(trial, t, shown);
  EXPECT_EQ(v["factor_status"], "x");
  EXPECT_EQ(v["factor_participant"], "P8");
  EXPECT_EQ(v["factor_r_left_px"], 7.5);
  EXPECT_EQ(v["factor_info_age"], 40);
  EXPECT_EQ(v["factor_level"], 99);
  EXPECT_EQ(v["factor_test_side"], "left");
  EXPECT_EQ(v["factor_correct"], 1);
  EXPECT_EQ(v["factor_group"], "g");
  EXPECT_EQ(v["edge"], 2);
  EXPECT_EQ(v["label"], "near");
  // The radius shown, not the table's 7.5.
  EXPECT_NEAR(v["r_left_px"].get<double>(), t.side(protocol::Side::kLeft).r_px, 1e-4);
  EXPECT_NE(v["r_left_px"], 7.5);
  EXPECT_EQ(v["level"], 0.4);
  EXPECT_EQ(v["test_side"], "right");
  for (const auto& [key, value] : v.items())
    if (!row.contains(key) && key != "group" && key.rfind("factor_", 0) != 0) {
      EXPECT_TRUE(store::IsRecordedName(key)) << key << " is recorded but not reserved for it";
    }
  for (const char* name : {"status", "participant", "r_left_px", "level", "test_side", "correct", "practice",
                           "swapped", "block_name", "info_age", "group", "round", "odd_interval"})
    EXPECT_TRUE(store::IsRecordedName(name)) << name;
  for (const char* name : {"edge", "label", "speed_cm_s", "right_x_mm", "factor_status"})
    EXPECT_FALSE(store::IsRecordedName(name)) << name;
}

// A session an older build started with a simulated observer recorded as sim:jnd=... (before model= existed)
// resumes with today's spelling of that observer (issue 24): every spelling used to be refused, the suggested one too.
TEST(Recording, AnOldObserverSpellingResumesWithTodaysCanonicalForm) {
  store::testing::TempDir dir;
  const std::string protocol = R"({"name":"s","version":1})";
  {
    store::Record old = store::Record::Open(dir / "r.sqlite");
    store::SessionMeta meta;
    meta.simulated = true;
    meta.observer_params = "sim:jnd=0.3";  // as the record of an older build holds it
    old.StartOrResumeSession("s", "P1", protocol, 7, meta, false);
  }
  Recording record = Recording::Open(dir / "r.sqlite");
  SessionInfo info;
  info.simulated = true;
  info.observer_params = procedure::ToString(procedure::ParseObserver("sim:model=pixel,jnd=0.3"));
  EXPECT_TRUE(record.StartOrResumeSession("s", "P1", protocol, 7, info, true).resumed);
  info.observer_params = procedure::ToString(procedure::ParseObserver("sim:model=pixel,jnd=0.4"));  // another observer is still refused
  EXPECT_THROW(record.StartOrResumeSession("s", "P1", protocol, 7, info, true), Error);
}

// The adapter records the procedures of the blocks the session parsed (SessionInfo::blocks), once per protocol
// version: a text that holds no procedure at all still gets the given block's row, so nothing was parsed from it.
TEST(Recording, RecordsTheProceduresOfTheBlocksTheSessionParsed) {
  store::testing::TempDir dir;
  SessionInfo info;
  protocol::Block plain, adaptive;
  plain.name = "practice";
  adaptive.name = "q";
  adaptive.procedure = protocol::Procedure{};
  adaptive.procedure->kind = protocol::ProcedureKind::kQuestPlus;
  adaptive.procedure->variable = protocol::ProcedureVariable::kDifferenceArcmin;
  adaptive.procedure->trials = 12;
  adaptive.procedure->guess = 1.0 / 3;
  info.blocks = {plain, adaptive};
  {
    Recording record = Recording::Open(dir / "r.sqlite");
    record.StartOrResumeSession("s", "P1", R"({"name":"s","version":1})", 7, info, false);
  }
  store::Database db(dir / "r.sqlite", store::OpenMode::kReadOnly);
  EXPECT_EQ(db.QueryText("SELECT group_concat(block || '|' || block_name || '|' || procedure || '|' || variable || '|' "
                         "|| trials || '|' || round(guess, 4), ',') FROM procedures"),
            "1|q|quest_plus|difference_arcmin|12|0.3333");
  EXPECT_NE(db.QueryText("SELECT parameters FROM procedures").find(R"("guess":0.3333333333333333)"), std::string::npos);
}

}  // namespace
}  // namespace blurcue::session
