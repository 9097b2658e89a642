// What a trial shows, worked out without GL: placement, motion and radii per side.
#include "stimulus/stimulus.h"

#include "scene/frame.h"

#include <gtest/gtest.h>

#include <cmath>

#include <opencv2/calib3d.hpp>

#include "core/error.h"
#include "stimulus/test_scenes.h"

namespace blurcue::stimulus {
namespace {

using fixtures::BallProtocol;
using fixtures::PairTrial;
using fixtures::ThesisScene;
using protocol::Side;

TEST(DescribeTrial, SectionRunGoesEdgeToEdgeAtThePatternSpeedAndIsWiped) {
  const calib::SceneCalib scene = ThesisScene();
  const Json pattern = {{"id", 2}, {"speed_cm_s", 1.8}, {"left", "measured"}, {"right", "none"}};
  const TrialScene t = DescribeTrial(BallProtocol(), PairTrial({{"pattern", pattern}, {"section", 3}}, 1.5, "none"),
                                     &scene);
  EXPECT_DOUBLE_EQ(t.from_y_mm, 50);  // edge 3 of 25 mm squares
  EXPECT_DOUBLE_EQ(t.to_y_mm, 75);    // edge 4
  EXPECT_NEAR(t.MotionS(), 25.0 / 18.0, 1e-12);
  EXPECT_DOUBLE_EQ(t.BallYMm(0), 50);
  EXPECT_NEAR(t.BallYMm(t.MotionS() / 2), 62.5, 1e-9);
  EXPECT_TRUE(std::isinf(t.BallYMm(t.MotionS() + 0.01)));  // gone at the edge
  EXPECT_DOUBLE_EQ(t.side(Side::kLeft).r_px, 1.5);         // a fixed radius, the same all along
  EXPECT_DOUBLE_EQ(t.side(Side::kRight).r_px, 0);
}

TEST(DescribeTrial, WholeRunRestsAtTheFarEdgeAndAveragesTheGrowingBlur) {
  const calib::SceneCalib scene = ThesisScene();
  const Json pattern = {{"id", 3}, {"speed_cm_s", 3}, {"left", "estimated"}, {"right", "none"}};
  const TrialScene t = DescribeTrial(BallProtocol(), PairTrial({{"pattern", pattern}}, "fitted", "none"), &scene);
  EXPECT_DOUBLE_EQ(t.from_y_mm, 0);
  EXPECT_DOUBLE_EQ(t.to_y_mm, 250);
  EXPECT_NEAR(t.MotionS(), 250.0 / 30.0, 1e-12);
  EXPECT_DOUBLE_EQ(t.BallYMm(100), 250);  // arrived, not wiped
  // The fitted source is the scene's own blur: the two agree; the mean lies between the run's ends.
  EXPECT_NEAR(t.side(Side::kLeft).r_px, t.r_scene_px, 0.05);
  const double r0 = calib::BlurAtPx(scene, calib::BlurSource::kFitted, scene.ToCamera({62.5, 0, 10}));
  const double r1 = calib::BlurAtPx(scene, calib::BlurSource::kFitted, scene.ToCamera({62.5, 250, 10}));
  EXPECT_GT(t.side(Side::kLeft).r_px, std::min(r0, r1));
  EXPECT_LT(t.side(Side::kLeft).r_px, std::max(r0, r1));
}

// What Compose draws comes from ObjectsAt: the protocol's kernel and brightness/contrast reach every object, and the
// radius is the side's own source at the object's place.
TEST(ObjectsAt, CarryTheProtocolsKernelAndMatchingAndEachSidesRadius) {
  const calib::SceneCalib scene = ThesisScene();
  protocol::Protocol p = BallProtocol();
  p.content.kernel = protocol::Kernel::kDisc;
  p.content.brightness = 1.3;
  p.content.contrast = 0.8;
  const Json pattern = {{"id", 2}, {"speed_cm_s", 1.8}, {"left", "measured"}, {"right", "none"}};
  const TrialScene t = DescribeTrial(p, PairTrial({{"pattern", pattern}, {"section", 3}}, 1.5, "fitted"), &scene);
  const auto shown = ObjectsAt(p, scene, t, 0.5);
  ASSERT_TRUE(shown[0] && shown[1]);
  for (const auto& o : shown) {
    EXPECT_EQ(o->method, "disc");
    EXPECT_DOUBLE_EQ(o->object.brightness, 1.3);
    EXPECT_DOUBLE_EQ(o->object.contrast, 0.8);
    EXPECT_NEAR(o->object.center_board_mm[1], t.BallYMm(0.5), 1e-9);
  }
  EXPECT_DOUBLE_EQ(shown[0]->r_px, 1.5);
  EXPECT_DOUBLE_EQ(shown[1]->r_px,
                   calib::BlurAtPx(scene, calib::BlurSource::kFitted, scene.ToCamera(shown[1]->object.center_board_mm)));
  // Wiped at the end of the section: nothing is shown.
  const auto gone = ObjectsAt(p, scene, t, t.MotionS() + 0.01);
  EXPECT_FALSE(gone[0] || gone[1]);
}

// A ball at an edge rests there, and the record holds the blur of that place (it used to rest at edge 1 while the
// record held the mean of a run from edge 1 to 11).
TEST(DescribeTrial, BallAtAnEdgeRestsThereWithThatPlacesBlur) {
  const calib::SceneCalib scene = ThesisScene();
  const TrialScene t = DescribeTrial(BallProtocol(), PairTrial({{"edge", 9}}, "fitted", "none"), &scene);
  EXPECT_DOUBLE_EQ(t.from_y_mm, 200);  // edge 9 of 25 mm squares
  EXPECT_DOUBLE_EQ(t.to_y_mm, 200);
  EXPECT_DOUBLE_EQ(t.MotionS(), 0);
  const auto shown = ObjectsAt(BallProtocol(), scene, t, 3.0);
  ASSERT_TRUE(shown[0]);
  EXPECT_DOUBLE_EQ(shown[0]->object.center_board_mm[1], 200);
  EXPECT_NEAR(t.side(Side::kLeft).r_px, shown[0]->r_px, 1e-9);  // the record is what the frame shows
  // Without a speed a ball rests where it starts, and is recorded there too.
  const TrialScene still = DescribeTrial(BallProtocol(), PairTrial(Json::object(), "fitted", "none"), &scene);
  const auto at_rest = ObjectsAt(BallProtocol(), scene, still, 0);
  EXPECT_NEAR(still.side(Side::kLeft).r_px, at_rest[0]->r_px, 1e-9);
  // An edge with a speed is a contradiction, named at the field.
  EXPECT_THROW(DescribeTrial(BallProtocol(), PairTrial({{"edge", 9}, {"speed_cm_s", 3}}, "fitted", "none"), &scene),
               Error);
  // So is a run's end or section without a speed: the ball rests at its start, and the level would be recorded
  // though never shown.
  for (const Json& levels : {Json{{"section", 3}}, Json{{"from_edge", 2}, {"to_edge", 5}}, Json{{"to_y_mm", 90}}}) {
    try {
      DescribeTrial(BallProtocol(), PairTrial(levels, "fitted", "none"), &scene);
      ADD_FAILURE() << levels.dump() << " without a speed was accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::kInput);
      EXPECT_NE(std::string(e.what()).find("rests where it starts"), std::string::npos) << e.what();
    }
  }
  const TrialScene from_only = DescribeTrial(BallProtocol(), PairTrial({{"from_edge", 4}}, "fitted", "none"), &scene);
  EXPECT_DOUBLE_EQ(from_only.from_y_mm, 75);  // a start alone places a resting ball
  EXPECT_DOUBLE_EQ(from_only.to_y_mm, 75);
}

// In an intervals trial each side's object is shown alone at the left object's place (IntervalScene): the right
// side's recorded radius is the one its interval draws, evaluated there, not at the right object's unshown place.
TEST(DescribeTrial, IntervalsRecordTheRightSidesRadiusWhereItsIntervalShowsIt) {
  calib::SceneCalib scene = ThesisScene();  // edge 6 measured at its first and last sections only: 0.5 and 1.5 px
  for (const auto& [section, r] : {std::pair{1, 0.5}, {7, 1.5}}) {
    calib::SceneCalib::Section measured = scene.sections.front();
    measured.edge = 6, measured.section = section, measured.r_px = r;
    measured.midpoint_camera_mm = scene.ToCamera({(section - 0.5) * 25, 125, 0});
    scene.sections.push_back(measured);
  }
  protocol::Protocol pair = BallProtocol();
  pair.layout = protocol::Layout::kSideBySide;
  protocol::Protocol intervals = BallProtocol();
  intervals.layout = protocol::Layout::kTwoIntervals;
  const protocol::Trial trial = PairTrial({{"edge", 6}, {"left_x_mm", -30}}, "measured_section", "measured_section");
  const TrialScene side_by_side = DescribeTrial(pair, trial, &scene);
  EXPECT_DOUBLE_EQ(side_by_side.side(Side::kLeft).r_px, 0.5);   // nearest the left ball: section 1
  EXPECT_DOUBLE_EQ(side_by_side.side(Side::kRight).r_px, 1.5);  // nearest the right ball on section 5: section 7
  const TrialScene t = DescribeTrial(intervals, trial, &scene);
  ASSERT_EQ(t.intervals, 2);
  const auto shown = ObjectsAt(intervals, scene, IntervalScene(t, true), 0);
  ASSERT_TRUE(shown[0]);
  EXPECT_NEAR(shown[0]->object.center_board_mm[0], -30, 1e-9);  // the right side's interval, at the left's place
  EXPECT_NEAR(t.side(Side::kRight).r_px, shown[0]->r_px, 1e-9);            // recorded as drawn
  EXPECT_NEAR(t.side(Side::kRight).r_px, t.side(Side::kLeft).r_px, 1e-9);  // the same source at the same place
  // Nor is the photo checked at the right object's unshown place: only where the intervals draw (the parser refuses
  // a right_x_mm with intervals; here it stands for a right default place off the photo).
  const protocol::Trial off = PairTrial({{"edge", 6}, {"left_x_mm", -30}, {"right_x_mm", 5000}}, "fitted", "fitted");
  EXPECT_NO_THROW(DescribeTrial(intervals, off, &scene));
  EXPECT_THROW(DescribeTrial(pair, off, &scene), Error);  // side by side, it would be shown off the photo
}

TEST(DescribeTrial, GridCardsSitBesideTheBoardAtTheirEdge) {
  calib::SceneCalib scene = ThesisScene();
  calib::SceneCalib::Section edge2 = scene.sections.front();  // edge 2 gets a measured section of its own
  edge2.edge = 2;
  edge2.midpoint_camera_mm = scene.ToCamera({87.5, 25, 0});
  edge2.r_px = 0.45;
  scene.sections.push_back(edge2);
  protocol::Protocol p = BallProtocol();
  p.content.type = protocol::ContentType::kGrid;
  const TrialScene near = DescribeTrial(p, PairTrial({{"edge", 2}}, "measured", "fitted"), &scene);
  const TrialScene far = DescribeTrial(p, PairTrial({{"edge", 11}}, "estimated", "fitted"), &scene);
  EXPECT_EQ(near.edge, 2);
  // Its own edge's measured value, beside the board on the edge's line.
  EXPECT_DOUBLE_EQ(near.side(Side::kLeft).r_px, 0.45);
  // Edge 11 has no measured section: "measured" there is refused, naming the side's field, not given edge 2's value.
  try {
    DescribeTrial(p, PairTrial({{"edge", 11}}, "measured", "fitted"), &scene);
    ADD_FAILURE() << "measured at an edge without a usable section was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    EXPECT_NE(std::string(e.what()).find("edge 11 (the nearest) has no usable measured section"), std::string::npos)
        << e.what();
  }
  EXPECT_GT(far.side(Side::kRight).r_px, near.side(Side::kRight).r_px + 1);  // fitted blur grows away from focus
  // A 4592 x 3056 photo fitted into a 1920 x 1080 window: 1080 / 3056 of a photo px per screen px, floored to
  // whole shown pixels (1622 of 1622.8); on the default monitor (37.84 px per degree) that is the arcmin.
  Presentation shown;
  shown.frame_width_px = 4592, shown.frame_height_px = 3056, shown.window_width_px = 1920, shown.window_height_px = 1080;
  shown.scale = scene::FitScale(4592, 3056, 1920, 1080);
  EXPECT_DOUBLE_EQ(shown.scale, 1622.0 / 4592.0);
  // What is recorded of it in photo px, screen px and arcmin: session's TrialVariables
  // (TrialVariables.GridTrialRecordsEachRadiusInPhotoPxScreenPxAndArcmin).
}

TEST(PlanOnScreen, PerPixelExactlyWhenTheObjectsDepthSpanReachesTheThresholdOnScreen) {
  // Grid cards at edge 2 with the fitted (depth-only) model on both sides: the span is the radius at the card's far
  // corners minus that at its near ones (z of the corners, the model evaluated there), times the screen scale.
  const calib::SceneCalib scene = ThesisScene();
  protocol::Protocol p = BallProtocol();
  p.content.type = protocol::ContentType::kGrid;
  TrialScene t = DescribeTrial(p, PairTrial({{"edge", 2}}, "fitted", "fitted"), &scene);
  Presentation shown;
  shown.scale = 0.5;
  const scene::VirtualObject card = scene::CardBesideBoard(scene.board, 2, true);
  auto r_at = [&](double y) {
    return calib::BlurAtPx(scene, calib::BlurSource::kFitted, scene.ToCamera({card.center_board_mm[0], y, 0}));
  };
  const double span = 0.5 * std::abs(r_at(50) - r_at(0));  // the card spans y 0..50 mm at edge 2
  ASSERT_GT(span, 0.05);
  p.content.depth_blur_threshold = span * 1.01;
  PlanOnScreen(p, scene, shown, &t);
  EXPECT_NEAR(t.r_span_screen_px, span, 1e-6 + 1e-3 * span);
  EXPECT_FALSE(t.per_pixel);
  EXPECT_FALSE(ObjectsAt(p, scene, t, 0)[0]->r_of_depth_px);
  p.content.depth_blur_threshold = span * 0.99;
  PlanOnScreen(p, scene, shown, &t);
  EXPECT_TRUE(t.per_pixel);
  const auto objects = ObjectsAt(p, scene, t, 0);
  ASSERT_TRUE(objects[0]->r_of_depth_px);
  // Per pixel, each depth gets the model's radius there; the centre's depth gets the one radius.
  const double z_centre = scene.ToCamera(card.center_board_mm)[2];
  EXPECT_NEAR(objects[0]->r_of_depth_px(z_centre), objects[0]->r_px, 1e-9);
  EXPECT_NEAR(objects[0]->r_of_depth_px(scene.ToCamera({card.center_board_mm[0], 50, 0})[2]), r_at(50), 1e-2);
  // In arcmin, converted by the profile: the same span is 0.5 x span screen px x arcmin per px.
  p.content.depth_blur_threshold_unit = protocol::ThresholdUnit::kArcmin;
  p.content.depth_blur_threshold = display::ArcminOfScreenPx(shown.profile, span) * 1.01;
  PlanOnScreen(p, scene, shown, &t);
  EXPECT_FALSE(t.per_pixel);
  p.content.depth_blur_threshold = display::ArcminOfScreenPx(shown.profile, span) * 0.99;
  PlanOnScreen(p, scene, shown, &t);
  EXPECT_TRUE(t.per_pixel);
  // Recorded as blur_plan per_pixel: TrialVariables.RecordsThePerPixelBlurPlan (session).
  // A procedure's gain on a side scales its radius at every depth, and so its span.
  t.side(Side::kLeft).gain = 3;
  PlanOnScreen(p, scene, shown, &t);
  EXPECT_NEAR(t.r_span_screen_px, 3 * span, 1e-6 + 3e-3 * span);
}

TEST(DescribeTrial, ARadiusGivenOnTheScreenIsTurnedIntoPhotoPxByThePresentation) {
  // 2 arcmin at 600 mm on the default monitor (0.2768 mm a px): 2 x 600 x tan(1 arcmin) / 0.2768 = 1.2614 screen
  // px; at 0.5 screen px per photo px, 2.5228 photo px. 1.5 screen px is 3 photo px.
  const calib::SceneCalib scene = ThesisScene();
  protocol::Protocol p = BallProtocol();
  p.content.type = protocol::ContentType::kGrid;
  Presentation shown;
  shown.scale = 0.5;
  const TrialScene t = DescribeTrial(p, PairTrial({{"edge", 3}}, Json{{"arcmin", 2}}, Json{{"screen_px", 1.5}}),
                                     &scene, &shown);
  const double pitch = 531.4 / 1920, screen = 2 * 600 * std::tan(M_PI / 180 / 60) / pitch;
  EXPECT_NEAR(t.side(Side::kLeft).r_px, screen / 0.5, 1e-3);
  EXPECT_NEAR(t.side(Side::kRight).r_px, 3.0, 1e-12);
  EXPECT_NEAR(shown.Arcmin(t.side(Side::kLeft).r_px), 2.0, 1e-3);
  try {
    DescribeTrial(p, PairTrial({{"edge", 3}}, Json{{"arcmin", 2}}, "none"), &scene);
    ADD_FAILURE() << "an arcmin radius without a display was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    EXPECT_NE(std::string(e.what()).find("needs the display"), std::string::npos) << e.what();
  }
}

// Placement in millimetres: a card's centre at (x, y) on the board where the levels say, a ball's x per side and its
// run in mm; edges checked against the calibrated board's own count; a place outside the photo refused.
TEST(DescribeTrial, PlacesInMillimetresAndChecksTheBoardAndThePhoto) {
  const calib::SceneCalib scene = ThesisScene();
  protocol::Protocol p = BallProtocol();
  p.content.type = protocol::ContentType::kGrid;
  const TrialScene card = DescribeTrial(p, PairTrial({{"y_mm", 60}, {"left_x_mm", -40}, {"right_x_mm", 230}},
                                                     "fitted", "fitted"), &scene);
  const auto cards = ObjectsAt(p, scene, card, 0);
  EXPECT_EQ(cards[0]->object.center_board_mm, cv::Vec3d(-40, 60, 0));
  EXPECT_EQ(cards[1]->object.center_board_mm, cv::Vec3d(230, 60, 0));
  EXPECT_NEAR(card.side(Side::kLeft).r_px,
              calib::BlurAtPx(scene, calib::BlurSource::kFitted, scene.ToCamera({-40, 60, 0})), 1e-9);
  p.content.type = protocol::ContentType::kBall;
  const TrialScene ball = DescribeTrial(p, PairTrial({{"from_y_mm", 10}, {"to_y_mm", 110}, {"speed_cm_s", 2},
                                                      {"left_x_mm", 50}}, "fitted", "none"), &scene);
  EXPECT_DOUBLE_EQ(ball.MotionS(), 5.0);  // 100 mm at 20 mm/s
  EXPECT_EQ(ObjectsAt(p, scene, ball, 0)[0]->object.center_board_mm, cv::Vec3d(50, 10, 10));
  EXPECT_EQ(ObjectsAt(p, scene, ball, 5)[1]->object.center_board_mm, cv::Vec3d(4.5 * 25, 110, 10));  // section 5
  try {
    DescribeTrial(p, PairTrial({{"edge", 12}}, "fitted", "none"), &scene);
    ADD_FAILURE() << "edge 12 of a board with 11 edges was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("edge 12 is not on the calibrated board (7 x 10 squares: edges 1-11"),
              std::string::npos) << e.what();
  }
  p.content.type = protocol::ContentType::kGrid;
  try {
    DescribeTrial(p, PairTrial({{"y_mm", 60}, {"right_x_mm", 5000}}, "fitted", "fitted"), &scene);
    ADD_FAILURE() << "a card 5 m off the board was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("the right grid at (5000, 60) mm on the board lies outside the 1148 x 764 "
                                         "photo"), std::string::npos) << e.what();
  }
}

// The record's depth of an object is the calibration's geometry: ThesisScene's camera looks along
// f = (0, cos 38, -sin 38) in the board frame from 440 mm before the board's centre (87.5, 125, 0), so a point P lies
// at u = 440 + (P - centre) . f, and its image (no distortion; fy = f / pitch) sits fy (P - c) . down / u below the
// principal point, down = (0, -sin 38, -cos 38) the camera's y. Edge 1 lies at 440 - 125 cos 38 = 341.5 mm, edge 11
// at 538.5 mm (the thesis's 342 to 527 mm).
TEST(DescribeTrial, AnObjectsDepthIsTheCalibrationsGeometryAtItsEdge) {
  const calib::SceneCalib scene = ThesisScene();
  protocol::Protocol p = BallProtocol();
  p.content.type = protocol::ContentType::kGrid;
  const double a = 38 * M_PI / 180;
  const cv::Vec3d forward(0, std::cos(a), -std::sin(a)), down(0, -std::sin(a), -std::cos(a)), centre(87.5, 125, 0);
  const double fy = 21 / (23.4 / 1148);  // the thesis's 21 mm lens on a 23.4 mm sensor, 1148 px across
  for (const int edge : {1, 6, 11}) {
    const TrialScene t = DescribeTrial(p, PairTrial({{"edge", edge}, {"left_x_mm", -40}, {"right_x_mm", 230}},
                                                    "fitted", "fitted"), &scene);
    for (const double x : {-40.0, 230.0}) {
      const cv::Vec3d from_centre = cv::Vec3d(x, (edge - 1) * 25.0, 0) - centre;
      const double u = 440 + from_centre.dot(forward);
      EXPECT_NEAR(x < 0 ? t.side(Side::kLeft).u_mm : t.side(Side::kRight).u_mm, u, 1e-6)
          << "edge " << edge << " x " << x;
      EXPECT_NEAR(x < 0 ? t.side(Side::kLeft).below_axis_px : t.side(Side::kRight).below_axis_px,
                  fy * from_centre.dot(down) / u, 1e-6)
          << "edge " << edge << " x " << x;
    }
    if (edge == 1 || edge == 11) {
      EXPECT_NEAR(t.side(Side::kLeft).u_mm, 440 + (edge == 1 ? -125 : 125) * std::cos(a), 1e-6);
    }
  }
  // A ball resting at edge 9 on the board's section 3: its centre 10 mm above the board.
  const TrialScene ball = DescribeTrial(BallProtocol(), PairTrial({{"edge", 9}}, "fitted", "fitted"), &scene);
  const cv::Vec3d ball_centre = ObjectsAt(BallProtocol(), scene, ball, 0)[0]->object.center_board_mm;
  EXPECT_NEAR(ball_centre[1], 200, 1e-9);
  EXPECT_NEAR(ball.side(Side::kLeft).u_mm, 440 + (ball_centre - centre).dot(forward), 1e-6);
}

TEST(DescribeTrial, MissingLevelOrCalibrationIsAnInputErrorNamingTheField) {
  const calib::SceneCalib scene = ThesisScene();
  protocol::Protocol p = BallProtocol();
  p.content.type = protocol::ContentType::kGrid;
  protocol::Block block;
  block.name = "task2";
  block.factors_pointer = "/blocks/1/factors";
  p.blocks.push_back(block);
  try {
    DescribeTrial(p, PairTrial({{"distance_m", 1}}, "measured", "fitted"), &scene);
    ADD_FAILURE() << "a grid without an edge was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    EXPECT_NE(std::string(e.what()).find("balls.json: /blocks/1/factors: a grid needs an integer level edge or a y_mm (trial 0, "
                                         "block task2)"), std::string::npos) << e.what();
  }
  EXPECT_THROW(DescribeTrial(p, PairTrial({{"edge", 2}}, "measured", "fitted"), nullptr), Error);
}

// An interval of the right side shows all that side shows (source, radius, gain, floor, streak, depth) at the left
// object's place (its x) and as large as the left one on screen.
TEST(IntervalScene, ShowsTheRightSideAtTheLeftObjectsPlace) {
  TrialScene t;
  SideShown& left = t.side(Side::kLeft);
  left.source = calib::BlurSource::kMeasured, left.x_mm = -30, left.size_deg = 2, left.r_px = 1;
  SideShown& right = t.side(Side::kRight);
  right.source = calib::BlurSource::kFitted, right.x_mm = 200, right.size_deg = 3, right.r_px = 4, right.gain = 2;
  right.floor_sigma_px = 0.5, right.motion_px = {1, -1}, right.u_mm = 420, right.below_axis_px = 12;
  const TrialScene second = IntervalScene(t, true);
  EXPECT_TRUE(second.left_only);
  const SideShown& shown = second.side(Side::kLeft);
  EXPECT_EQ(shown.source, calib::BlurSource::kFitted);
  EXPECT_EQ(shown.r_px, 4);
  EXPECT_EQ(shown.gain, 2);
  EXPECT_EQ(shown.floor_sigma_px, 0.5);
  EXPECT_EQ(shown.motion_px, cv::Vec2d(1, -1));
  EXPECT_EQ(shown.u_mm, 420);
  EXPECT_EQ(shown.below_axis_px, 12);
  EXPECT_EQ(shown.x_mm, -30);
  EXPECT_EQ(shown.size_deg, 2);
  const TrialScene first = IntervalScene(t, false);
  EXPECT_EQ(first.side(Side::kLeft).source, calib::BlurSource::kMeasured);
  EXPECT_EQ(first.side(Side::kLeft).r_px, 1);
}

}  // namespace
}  // namespace blurcue::stimulus
