#include "protocol/protocol.h"
#include "blurcue/source_dir.h"

#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "core/error.h"
#include "protocol/protocol_test_util.h"
#include "protocol/trials.h"

namespace blurcue::protocol {
namespace {

using namespace test;  // NOLINT: the helpers every test here uses

TEST(ProtocolValidate, ProblemStartsWithFileAndPointer) {
  Json j = Valid();
  j["version"] = 0;
  const std::string p = OnlyProblem(j);
  EXPECT_EQ(p, (SceneFolder() / "p.json").string() + ": /version: must be an integer in [1, 1000000], got 0");
}

TEST(ProtocolValidate, WrongTypeNamesPointer) {
  Json j = Valid();
  j["blocks"][0]["repetitions"] = "two";
  EXPECT_TRUE(Contains(OnlyProblem(j), ": /blocks/0/repetitions: must be an integer in [1, 10000] repetitions, got \"two\"")) << OnlyProblem(j);
}

TEST(ProtocolValidate, UnknownKeyNamesPointerAndNearestKey) {
  Json j = Valid();
  j["blocks"][1]["factros"] = j["blocks"][1]["factors"];
  j["blocks"][1].erase("factors");
  const auto problems = Problems(j);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_TRUE(Contains(problems[0], ": /blocks/1/factros: unknown key (did you mean \"factors\"?)")) << problems[0];
  EXPECT_TRUE(Contains(problems[1], ": /blocks/1/factors: is required (here or at /factors; or a conditions table) "
                                    "but missing")) << problems[1];
}

TEST(ProtocolValidate, MissingFieldNamesPointer) {
  Json j = Valid();
  j["content"].erase("type");
  EXPECT_TRUE(Contains(OnlyProblem(j), ": /content/type: is required but missing")) << OnlyProblem(j);
}

TEST(ProtocolValidate, NonPositiveSpeedRejected) {
  Json j = Valid();
  j["blocks"][0]["factors"]["pattern"][1]["speed_cm_s"] = 0;
  EXPECT_TRUE(Contains(OnlyProblem(j), ": /blocks/0/factors/pattern/1/speed_cm_s: a speed must be a number in [0.1, 100] cm/s, got 0"))
      << OnlyProblem(j);
}

TEST(ProtocolValidate, SectionOutsideTheBoardRejected) {
  Json j = Valid();
  j["blocks"][1]["factors"]["section"][2] = 101;
  EXPECT_TRUE(Contains(OnlyProblem(j), ": /blocks/1/factors/section/2: a section (edge s to s + 1) must be an integer "
                                       "in [1, 100], got 101")) << OnlyProblem(j);
}

TEST(ProtocolValidate, EdgeOutsideAnyBoardRejected) {
  Json j = Valid();
  j["blocks"][1]["factors"] = {{"edge", {1, 102}}};
  j["blocks"][1]["sides"] = {{"left", "measured"}, {"right", "estimated"}};
  EXPECT_TRUE(Contains(OnlyProblem(j), ": /blocks/1/factors/edge/1: an edge must be an integer in [1, 101], got 102"))
      << OnlyProblem(j);
}

// With the calibrated board known (7 x 10 squares: edges 1-11, sections 1-10 between them), every level past it is a problem of
// the one pass, beside one past any board: edges 0 and 12 and section 11 at once (edge 12 used to be refused alone,
// by the trial list, once edge 0 was fixed).
TEST(ProtocolValidate, EveryLevelPastTheCalibratedBoardIsNamedAtOnce) {
  Json j = Valid();
  j["blocks"][1]["factors"] = {{"edge", {0, 5, 8, 11, 12}}};
  j["blocks"][1]["sides"] = {{"left", "measured"}, {"right", "estimated"}};
  j["blocks"][0]["factors"]["section"] = {1, 10, 11};
  ValidateOptions board;
  board.board_cols = 7, board.board_rows = 10;
  const auto problems = Validate(j, SceneFolder() / "p.json", board);
  const std::string of_board = ", the calibrated board's (7 x 10 squares: edges 1-11, sections 1-10 between them), got ";
  ASSERT_EQ(problems.size(), 3u) << ::testing::PrintToString(problems);
  EXPECT_TRUE(Contains(problems[0], ": /blocks/0/factors/section/2: a section (edge s to s + 1) must be an integer in "
                                    "[1, 10]" + of_board + "11")) << problems[0];
  EXPECT_TRUE(Contains(problems[1], ": /blocks/1/factors/edge/0: an edge must be an integer in [1, 11]" + of_board + "0"))
      << problems[1];
  EXPECT_TRUE(Contains(problems[2], ": /blocks/1/factors/edge/4: an edge must be an integer in [1, 11]" + of_board + "12"))
      << problems[2];
  // Without the board, only the level past any board is.
  j["blocks"][0]["factors"].erase("section");
  EXPECT_TRUE(Contains(OnlyProblem(j), ": /blocks/1/factors/edge/0: an edge must be an integer in [1, 101], got 0"));
}

TEST(ProtocolValidate, UnknownBlurSourceRejected) {
  Json j = Valid();
  j["blocks"][0]["factors"]["pattern"][0]["right"] = "blurry";
  EXPECT_TRUE(Contains(OnlyProblem(j), ": /blocks/0/factors/pattern/0/right: a blur source must be none, measured, "
                                       "measured_section, estimated, fitted, a radius in [0, 100] photo px, {\"screen_px\": r} with r in [0, 100] "
                       "or {\"arcmin\": r} with r in [0, 600], got \"blurry\"")) << OnlyProblem(j);
}

TEST(ProtocolValidate, EmptyFactorRejected) {
  Json j = Valid();
  j["blocks"][1]["factors"]["section"] = Json::array();
  EXPECT_TRUE(Contains(OnlyProblem(j), ": /blocks/1/factors/section: must list at least one level, got []"))
      << OnlyProblem(j);
}

TEST(ProtocolValidate, MissingFileRejected) {
  Json j = Valid();
  j["scene"]["calib"] = "no-such-calib.json";
  EXPECT_TRUE(Contains(OnlyProblem(j), ": /scene/calib: no such file: ")) << OnlyProblem(j);
  EXPECT_TRUE(Contains(OnlyProblem(j), "got \"no-such-calib.json\"")) << OnlyProblem(j);
}

TEST(ProtocolValidate, MissingFileAcceptedWithoutFileChecks) {
  Json j = Valid();
  j["scene"]["calib"] = "no-such-calib.json";
  EXPECT_TRUE(Problems(j, false).empty());
}

// A depth-matching protocol with a photo of the real picture per distance.
Json WithRealPhotos(const std::string& pattern) {
  const fs::path dir = SceneFolder() / "photos";
  fs::create_directories(dir);
  for (const char* name : {"face-0.4m.png", "face-1.5m.png"}) std::ofstream(dir / name) << "x";
  return Json::parse(R"({
    "name": "dm", "version": 1,
    "content": {"type": "picture", "image": "scene/scene.png", "real_photos": ")" + pattern + R"("},
    "task": "adjustment", "adjust": {"levels": [2, 4, 8]}, "factors": {"distance_m": [0.4, 1.5]}
  })");
}

// Every field a depth matching would not read is refused: keys of another task, a scene photo when its real photos
// are shown, a calibration (a picture's real blur comes from content.real_camera).
TEST(ProtocolValidate, DepthMatchingRefusesWhatItWouldNotRead) {
  Json adjust = WithRealPhotos("photos/face-{distance_m}m.png");
  for (const char* key : {"left", "right", "cant_tell"}) {
    adjust["responses"] = {{key, "Return"}};
    ExpectProblem(adjust, "/responses/" + std::string(key) + ": is for the task forced_choice, which no block has");
  }
  Json scene = WithRealPhotos("photos/face-{distance_m}m.png");
  scene["scene"] = {{"background", "scene/scene.png"}};
  ExpectProblem(scene, "/scene: is not shown: with content.real_photos the lower half shows the real photo");
  Json calib = WithRealPhotos("photos/face-{distance_m}m.png");
  calib["content"].erase("real_photos");
  calib["scene"] = {{"background", "scene/scene.png"}, {"calib", "scene/scene.png"}};
  ExpectProblem(calib, "/scene/calib: is not read by a picture");
}

TEST(ProtocolValidate, RealPhotosFoundPerDistance) {
  const Json j = WithRealPhotos("photos/face-{distance_m}m.png");
  EXPECT_TRUE(Problems(j).empty()) << OnlyProblem(j);
  const Protocol p = ParseProtocol(j, SceneFolder() / "p.json");
  EXPECT_EQ(RealPhotoFor(p.content, 0.4), SceneFolder() / "photos" / "face-0.4m.png");
  EXPECT_EQ(RealPhotoFor(p.content, 1.5).filename(), "face-1.5m.png");
}

TEST(ProtocolValidate, RealPhotosMissingOrWithoutPlaceholderRejected) {
  Json j = WithRealPhotos("photos/face-{distance_m}m.png");
  j["factors"]["distance_m"].push_back(2.5);
  EXPECT_TRUE(Contains(OnlyProblem(j), ": /content/real_photos: no photo for distance_m 2.5: ")) << OnlyProblem(j);
  EXPECT_TRUE(Contains(OnlyProblem(j), "face-2.5m.png")) << OnlyProblem(j);
  const Json k = WithRealPhotos("photos/face.png");
  EXPECT_TRUE(Contains(OnlyProblem(k), ": /content/real_photos: must contain {distance_m}")) << OnlyProblem(k);
}

// content.real_camera: the camera (read and validated) and focus of the real photos; refused without real_photos, with
// a camera file that is not one, a focus that is not a distance, or a field it does not know.
TEST(ProtocolValidate, RealCameraReadOrRejectedNamingItsField) {
  std::ofstream(SceneFolder() / "camera.json") << R"({"focal_length_mm": 21, "f_number": 5.6, "sensor_width_mm": 23.4,
    "sensor_height_mm": 15.6, "image_width_px": 1148, "image_height_px": 764})";
  std::ofstream(SceneFolder() / "not-a-camera.json") << R"({"focal_length_mm": -1})";
  Json j = WithRealPhotos("photos/face-{distance_m}m.png");
  j["content"]["real_camera"] = {{"camera", "camera.json"}, {"focus_m", 1.5}};
  EXPECT_TRUE(Problems(j).empty()) << OnlyProblem(j);
  const Protocol p = ParseProtocol(j, SceneFolder() / "p.json");
  ASSERT_TRUE(p.content.real_camera.has_value());
  EXPECT_EQ(p.content.real_camera->image_width_px, 1148);
  EXPECT_DOUBLE_EQ(p.content.real_focus_m, 1.5);
  const std::pair<Json, std::string> cases[] = {
      {{{"camera", "camera.json"}, {"focus_m", -1}},
       ": /content/real_camera/focus_m: must be a number in [0.01, 1000] m"},
      {{{"camera", "camera.json"}, {"focus_m", "1"}}, ": /content/real_camera/focus_m: must be a number"},
      {{{"camera", "camera.json"}}, ": /content/real_camera/focus_m: is required"},
      {{{"camera", "not-a-camera.json"}, {"focus_m", 1}}, ": /content/real_camera/camera: "},
      {{{"camera", "."}, {"focus_m", 1}}, ": /content/real_camera/camera: is a folder"},
      {{{"camera", "camera.json"}, {"focus_m", 1}, {"aperture", 2}}, ": /content/real_camera/aperture: "},
  };
  for (const auto& [real, text] : cases) {
    Json k = j;
    k["content"]["real_camera"] = real;
    EXPECT_TRUE(Contains(OnlyProblem(k), text)) << real << ": " << OnlyProblem(k);
  }
  Json none = j;
  none["content"].erase("real_photos");
  none["scene"] = {{"background", "scene/scene.png"}};  // without real photos the lower half shows the scene
  none["factors"] = {{"distance_m", {0.4}}};
  EXPECT_TRUE(Contains(OnlyProblem(none), ": /content/real_camera: describes the camera of content.real_photos"))
      << OnlyProblem(none);
}

TEST(ProtocolValidate, ComparisonWithoutSidesRejected) {
  Json j = Valid();
  j["blocks"][1]["factors"] = {{"section", {1, 2}}};
  EXPECT_TRUE(Contains(OnlyProblem(j), ": /blocks/1: needs what is shown left and right")) << OnlyProblem(j);
}

TEST(ProtocolValidate, DuplicateResponseKeysRejected) {
  Json j = Valid();
  j["responses"] = {{"left", "A"}, {"right", "A"}};
  EXPECT_TRUE(Contains(OnlyProblem(j), ": /responses/right: is the same key as /responses/left, got \"A\""))
      << OnlyProblem(j);
}

TEST(ProtocolValidate, InheritedProblemReportedOnce) {
  Json j = Valid();
  j["repetitions"] = -1;  // both blocks inherit it
  EXPECT_TRUE(Contains(OnlyProblem(j), ": /repetitions: must be an integer in [1, 10000] repetitions, got -1")) << OnlyProblem(j);
}

TEST(ProtocolValidate, SeveralProblemsThrownTogether) {
  Json j = Valid();
  j["name"] = 7;
  j["scene"]["background"] = "missing.png";
  j["blocks"][0]["factors"]["pattern"] = Json::array();
  j["display"] = {{"width_px", -5}};
  try {
    ParseProtocol(j, SceneFolder() / "p.json");
    FAIL() << "no exception";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    const std::string m = e.what();
    EXPECT_TRUE(Contains(m, "/name: must be a string, got 7\n")) << m;
    EXPECT_TRUE(Contains(m, "/scene/background: no such file")) << m;
    EXPECT_TRUE(Contains(m, "/blocks/0/factors/pattern: must list at least one level")) << m;
    EXPECT_TRUE(Contains(m, "/display/width_px: must be an integer in [320, 3840] px, got -5")) << m;
    EXPECT_TRUE(Contains(m, "(4 problems)")) << m;
  }
}

TEST(ProtocolValidate, SpeedTooSlowToEverArriveRejectedWithItsUnit) {
  Json j = Valid();
  j["blocks"][0]["factors"]["pattern"][0]["speed_cm_s"] = 1e-300;
  EXPECT_TRUE(Contains(OnlyProblem(j), "/blocks/0/factors/pattern/0/speed_cm_s: a speed must be a number in "
                                       "[0.1, 100] cm/s, got 1e-300")) << OnlyProblem(j);
}

TEST(ProtocolValidate, InterTrialIntervalBeyondAMinuteRejected) {
  Json j = Valid();
  j["timing"] = {{"inter_trial_ms", 1e308}, {"stimulus_ms", 5}};
  const auto problems = Problems(j);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_TRUE(Contains(problems[0], "/timing/stimulus_ms: must be a duration in [10, 60000] ms or \"until_response\", "
                                    "got 5")) << problems[0];
  EXPECT_TRUE(Contains(problems[1], "/timing/inter_trial_ms: must be a number in [0, 60000] ms, got 1e+308"))
      << problems[1];
}

TEST(ProtocolValidate, FixedRadiusAndBallSizeHaveRanges) {
  Json j = Valid();
  j["blocks"][0]["factors"]["pattern"][0]["left"] = 1e6;
  j["content"]["radius_mm"] = 0.001;
  const auto problems = Problems(j);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_TRUE(Contains(problems[0], "/content/radius_mm: must be a number in [1, 150] mm, got 0.001")) << problems[0];
  EXPECT_TRUE(Contains(problems[1], "/blocks/0/factors/pattern/0/left: a blur source must be")) << problems[1];
}

TEST(ProtocolValidate, ExposureIsCheckedAndNamedWithDidYouMean) {
  Json j = Valid();
  j["content"]["exposure_ms"] = 40;
  EXPECT_TRUE(Problems(j).empty());
  EXPECT_EQ(ParseProtocol(j, SceneFolder() / "p.json").content.exposure_ms, 40);
  j["content"]["exposure_ms"] = -1;
  auto problems = Problems(j);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_TRUE(Contains(problems[0], "/content/exposure_ms: must be a number in [0, 1000] ms, got -1")) << problems[0];
  j["content"].erase("exposure_ms");
  j["content"]["exposure"] = 40;
  problems = Problems(j);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_TRUE(Contains(problems[0], "exposure_ms")) << problems[0];
}

TEST(ProtocolValidate, TrialCountOverTheCapRejectedNamingTheCap) {
  Json j = Valid();
  Json factors = Json::object();
  for (int f = 0; f < 8; ++f) {
    Json levels = Json::array();
    for (int l = 0; l < 30; ++l) levels.push_back(l);
    factors["label_f" + std::to_string(f)] = levels;
  }
  factors["pattern"] = j["blocks"][0]["factors"]["pattern"];
  j["blocks"][0]["factors"] = factors;
  const std::string p = OnlyProblem(j);
  EXPECT_TRUE(Contains(p, "/blocks/0/factors: the session would have 2624400000006 trials (30 label_f0 x ")) << p;
  EXPECT_TRUE(Contains(p, "a session may have at most 10000 trials, practice included")) << p;
}

TEST(ProtocolValidate, TrialCountBeyondSixtyFourBitsIsStillRefused) {
  Json j = Valid();
  Json factors = Json::object();
  for (int f = 0; f < 15; ++f) {
    Json levels = Json::array();
    for (int l = 0; l < 1000; ++l) levels.push_back(l);
    factors["label_f" + std::to_string(f)] = levels;  // 1000^15 = 1e45 trials
  }
  factors["pattern"] = j["blocks"][0]["factors"]["pattern"];
  j["blocks"][0]["factors"] = factors;
  EXPECT_TRUE(Contains(OnlyProblem(j), "a session may have at most 10000 trials")) << OnlyProblem(j);
  j["repetitions"] = 10000;  // a small crossing, repeated past the cap
  j["blocks"][0]["factors"] = {{"pattern", Valid()["blocks"][0]["factors"]["pattern"]}};
  EXPECT_TRUE(Contains(OnlyProblem(j), "the session would have 100000 trials")) << OnlyProblem(j);
}

// Over the cap, the message counts what SessionTrials counts - a practice criterion's max_repeats runs, a procedure's
// trials - and spells out the blocks that make the total, the biggest first. It used to add one run of each block
// (5445 < 10000 for the refused 10395) and spell out the block with the most trials per run.
TEST(ProtocolValidate, TrialCountOverTheCapCountsCriterionRunsAndNamesTheBlocksThatMakeIt) {
  Json j = Valid();
  j["counterbalance"] = "none";
  Json levels = Json::array();
  for (int l = 0; l < 45; ++l) levels.push_back(l);
  const Json pattern = {Valid()["blocks"][0]["factors"]["pattern"][0]};
  j["blocks"] = Json::array({
      {{"name", "warm-up"}, {"practice", true}, {"criterion", {{"correct", 0.8}, {"max_repeats", 11}}},
       {"factors", {{"pattern", pattern}, {"label_f", levels}}}, {"repetitions", 11}},  // 495 a run
      {{"name", "main"}, {"factors", {{"pattern", pattern}, {"label_f", levels}}}, {"repetitions", 110}}});  // 4950
  std::string p = OnlyProblem(j);
  EXPECT_TRUE(Contains(p, "/blocks/0/factors: the session would have up to 10395 trials (11 runs (criterion "
                          "max_repeats) x 45 label_f x 1 pattern x 11 repetitions = 5445 in block warm-up + 45 "
                          "label_f x 1 pattern x 110 repetitions = 4950 in block main); a session may have at most "
                          "10000 trials")) << p;
  // The block with the most trials per run is not the one that makes most of the total: the criterion's is named
  // first, and its pointer given.
  j["blocks"][1]["repetitions"] = 200;  // 9000 a run, once
  j["blocks"][0]["repetitions"] = 2;    // 90 a run, up to 11 times: 990
  EXPECT_TRUE(Problems(j).empty()) << Problems(j).front();  // 9990
  j["blocks"][0]["criterion"]["max_repeats"] = 20;  // 1800 + 9000
  p = OnlyProblem(j);
  EXPECT_TRUE(Contains(p, "/blocks/1/factors: the session would have up to 10800 trials (45 label_f x 1 pattern x "
                          "200 repetitions = 9000 in block main + 20 runs (criterion max_repeats) x 45 label_f x 1 "
                          "pattern x 2 repetitions = 1800 in block warm-up)")) << p;
  // The practice drawn from a block is added to it.
  j = Valid();
  levels.erase(levels.begin());
  levels.push_back(45);  // sections 1..45
  j["practice"] = {{"count", 4}, {"block", "task2"}};
  j["blocks"][1]["factors"]["section"] = levels;
  j["blocks"][1]["repetitions"] = 120;  // 45 x 120 x 2 = 10800, + 4 practice
  p = OnlyProblem(j);
  EXPECT_TRUE(Contains(p, "/blocks/1/factors: the session would have 10808 trials (1 pattern x 45 section x 120 "
                          "repetitions x 2 (swap_copies) + 4 practice = 10804 in block task2 + 2 pattern x 1 "
                          "repetitions x 2 (swap_copies) = 4 in block task1)")) << p;
  // A procedure's block counts its trials per crossing (they were counted as its repetitions: 11).
  j = Json::parse(R"({
    "name": "adaptive", "version": 1,
    "scene": {"background": "scene/scene.png", "calib": "calib.json"},
    "content": {"type": "grid"}, "task": "forced_choice",
    "blocks": [{"name": "stairs", "factors": {"edge": [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11]},
                "procedure": {"type": "staircase", "variable": "relative_difference", "reference": "fitted",
                              "trials": 1000, "start": 1, "min": 0.05, "max": 2, "steps": [0.4, 0.2]}}]
  })");
  p = OnlyProblem(j);
  EXPECT_TRUE(Contains(p, "/blocks/0/factors: the session would have 11000 trials (11 edge x 1000 trials (procedure) = "
                          "11000 in block stairs)")) << p;
}

TEST(ProtocolValidate, TooManyLevelsRejectedBeforeComparingThem) {
  Json j = Valid();
  Json levels = Json::array();
  for (int l = 0; l < 200000; ++l) levels.push_back(1);  // pairwise repeat checks would take minutes
  j["blocks"][1]["factors"]["section"] = levels;
  EXPECT_TRUE(Contains(OnlyProblem(j), "/blocks/1/factors/section: may list at most 1000 levels, got 200000"));
}

TEST(ProtocolValidate, ProblemsBeyondFiftyAreCounted) {
  Json j = Valid();
  for (int k = 0; k < 5000; ++k) j["extra" + std::to_string(k)] = k;
  const auto problems = Problems(j);
  ASSERT_EQ(problems.size(), 51u);
  EXPECT_TRUE(Contains(problems.back(), "p.json: 4950 more problems not listed")) << problems.back();
}

TEST(ProtocolValidate, ContentAndTaskMustFit) {
  Json j = Valid();
  j["blocks"][1]["task"] = "adjustment";
  j["blocks"][1]["adjust"] = {{"levels", {2, 4}}};
  EXPECT_TRUE(Contains(OnlyProblem(j), "/blocks/1/task: must be forced_choice for a ball")) << OnlyProblem(j);
}

TEST(ProtocolValidate, GridWithoutEdgeRejected) {
  Json j = Valid();
  j["content"] = {{"type", "grid"}};
  j["blocks"].erase(1);
  // The block's pattern levels carry a speed (a ball's) and no edge: both are said.
  const auto problems = Problems(j);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_TRUE(Contains(problems[0], "/blocks/0/factors/pattern: a grid does not use speed_cm_s")) << problems[0];
  EXPECT_TRUE(Contains(problems[1], "/blocks/0/factors: a grid stands at an edge")) << problems[1];
}

TEST(ProtocolValidate, MorePracticeThanTheDesignHasRejected) {
  Json j = Valid();
  j["practice"] = {{"count", 7}, {"block", "task2"}};
  EXPECT_TRUE(Contains(OnlyProblem(j), "/practice/count: asks for 7 practice trials but block task2 has only 6"))
      << OnlyProblem(j);
}

TEST(ProtocolValidate, FolderOrDeviceWhereAFileBelongsRejected) {
  Json j = Valid();
  j["scene"]["calib"] = ".";
  j["scene"]["background"] = "/dev/zero";
  const auto problems = Problems(j);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_TRUE(Contains(problems[0], "/scene/background: is not a regular file (a device, FIFO or socket): /dev/zero"))
      << problems[0];
  EXPECT_TRUE(Contains(problems[1], "/scene/calib: is a folder, not a file: ")) << problems[1];
}

TEST(ProtocolValidate, ControlCharactersInNamesAndPathsRejected) {
  Json j = Valid();
  j["name"] = "two\nlines";
  j["scene"]["background"] = std::string("scene/scene.png\0junk", 20);
  const auto problems = Problems(j);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_TRUE(Contains(problems[0], "/name: must not contain control characters")) << problems[0];
  EXPECT_TRUE(Contains(problems[1], "/scene/background: must not contain control characters")) << problems[1];
}

TEST(ProtocolValidate, KeyWithALineBreakIsNamedOnOneLine) {
  Json j = Valid();
  j["bad\nkey"] = 1;
  const std::string p = OnlyProblem(j);
  EXPECT_EQ(p.find('\n'), std::string::npos) << p;
  EXPECT_TRUE(Contains(p, "/bad\\u000akey: unknown key")) << p;
}

TEST(ProtocolValidate, RepeatedLevelNamesItsFirstOccurrence) {
  Json j = Valid();
  j["blocks"][1]["factors"]["label_size"] = {1, 2, 1.0, 3, 2};
  const auto problems = Problems(j);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_TRUE(Contains(problems[0], "/blocks/1/factors/label_size/2: repeats the level at /blocks/1/factors/label_size/0 (a factor lists each of its levels once; repetitions sets how often each is shown), got 1.0")) << problems[0];
  EXPECT_TRUE(Contains(problems[1], "/blocks/1/factors/label_size/4: repeats the level at /blocks/1/factors/label_size/1 (")) << problems[1];
}

TEST(ProtocolValidate, ObjectLevelOfAValueFactorRejected) {
  Json j = Valid();
  j["blocks"][1]["factors"]["section"][1] = Json::object();  // would show section "{}" as the whole run
  EXPECT_TRUE(Contains(OnlyProblem(j), "/blocks/1/factors/section/1: a section (edge s to s + 1) must be an integer "
                                       "in [1, 100], got {}")) << OnlyProblem(j);
}

TEST(ProtocolValidate, LongUnicodeValueIsQuotedCutAtACharacter) {
  Json j = Valid();
  std::string name;
  for (int i = 0; i < 1000; ++i) name += "\u6f22";  // three bytes each: a cut at 80 bytes falls inside one
  j["name"] = name;
  const std::string p = OnlyProblem(j);
  EXPECT_TRUE(Contains(p, "/name: must be at most 100 characters, got 1000")) << p;
  j["name"] = 1;
  j["unknown"] = name;
  const auto problems = Problems(j);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_TRUE(Contains(problems[0], "/unknown: unknown key")) << problems[0];
  EXPECT_TRUE(Contains(problems[0], "...")) << problems[0];
}

TEST(ProtocolValidate, NotAnObjectRejected) {
  EXPECT_TRUE(Contains(OnlyProblem(Json::array()), ": /: must be an object, got []"));
}

// The four studies of the thesis, as shipped. Counts per participant (practice trials apart):
//   pre-research: 27 distances x 1 = 27 adjustment trials (22 cut-offs in a fresh order each), + 1 practice;
//   test 1: 11 edges = 11 (measured vs estimated, sides by participant parity), + 2 practice;
//   test 2 and 3: task 1 6 patterns x 2 (swapped copy) = 12; task 2 3 patterns x 10 sections x 2 = 60; + 2 practice.
struct Shipped {
  const char* file;
  size_t practice, main;
};

class ShippedProtocol : public testing::TestWithParam<Shipped> {};

TEST_P(ShippedProtocol, ParsesAndHasTheThesisTrialCount) {
  const fs::path file = fs::path(BLURCUE_SOURCE_DIR) / "protocols" / GetParam().file;
  const Protocol p = LoadProtocol(file, ValidateOptions{false});
  const auto trials = BuildTrials(p, "P1", 1);
  size_t practice = 0;
  for (const auto& t : trials) practice += t.practice;
  EXPECT_EQ(practice, GetParam().practice);
  EXPECT_EQ(trials.size() - practice, GetParam().main);
}

INSTANTIATE_TEST_SUITE_P(Thesis, ShippedProtocol,
                         testing::Values(Shipped{"pre-research-depth-matching.json", 1, 27},
                                         Shipped{"test1-static-grids.json", 2, 11},
                                         Shipped{"test2-moving-balls.json", 2, 72},
                                         Shipped{"test3-no-board.json", 2, 72}));

TEST(ShippedProtocols, TestThreeShowsTheBoardFreePhoto) {
  const fs::path dir = fs::path(BLURCUE_SOURCE_DIR) / "protocols";
  EXPECT_EQ(LoadProtocol(dir / "test3-no-board.json", {false}).scene.show, ScenePhoto::kBoardFree);
  EXPECT_EQ(LoadProtocol(dir / "test2-moving-balls.json", {false}).scene.show, ScenePhoto::kBackground);
}

TEST(ShippedProtocols, SceneFilesResolveToTheDemoOutput) {
  const fs::path dir = fs::path(BLURCUE_SOURCE_DIR) / "protocols";
  const Protocol p = LoadProtocol(dir / "test2-moving-balls.json", {false});
  EXPECT_EQ(p.scene.background, (dir / "../results/demo/scene/scene.png").lexically_normal());
  EXPECT_EQ(p.scene.calib, (dir / "../results/demo/calib.json").lexically_normal());
}

// After the parser a factor's levels, a block's sides and a procedure's reference are typed values, each as the file
// wrote it: nothing after protocol/ reads the protocol's JSON for them.
TEST(ProtocolTyped, FactorLevelsSidesAndReferenceAreTypedAsWritten) {
  Json j = test::Valid();
  j["blocks"][1]["factors"]["section"] = Json::parse("[1, 3]");
  j["blocks"].push_back(Json::parse(R"({"name": "fixed", "factors": {"edge": [4]}, "counterbalance": "none",
                                        "sides": {"left": {"screen_px": 0.5}, "right": 2.0}})"));
  j["blocks"].push_back(Json::parse(R"({"name": "quest", "factors": {"speed_cm_s": [1.8]}, "counterbalance": "none",
      "procedure": {"type": "quest_plus", "variable": "difference_arcmin", "reference": {"arcmin": 1.5},
                    "trials": 4, "stimuli": [0, 1], "threshold": [0.5, 1], "slope": [2], "lapse": [0.02]}})"));
  const Protocol p = ParseProtocol(j, test::SceneFolder() / "p.json");
  ASSERT_EQ(p.blocks.size(), 4u);
  // An object level keeps its keys in name order, each value of its kind.
  const Level& pattern = p.blocks[0].factors[0].levels[1];
  EXPECT_EQ(pattern.factor, "pattern");
  ASSERT_TRUE(pattern.object);
  EXPECT_EQ(pattern.Field("id")->kind, LevelValue::Kind::kInteger);
  EXPECT_EQ(pattern.Field("speed_cm_s")->kind, LevelValue::Kind::kReal);
  EXPECT_EQ(pattern.Field("speed_cm_s")->number, 1.8);
  EXPECT_EQ(pattern.Field("left")->text, "estimated");
  ASSERT_EQ(p.blocks[1].factors.size(), 2u);  // pattern, section: in name order
  EXPECT_EQ(p.blocks[1].factors[1].name, "section");
  EXPECT_EQ(p.blocks[1].factors[1].levels[1].unit, "");
  EXPECT_EQ(p.blocks[1].factors[1].levels[1].value.text, "3");
  EXPECT_FALSE(p.blocks[0].sides);  // the pattern's levels carry the sides
  // A block's sides: the radius on the screen and the one in photo px written 2.0 (a real, not the integer 2).
  ASSERT_TRUE(p.blocks[2].sides);
  EXPECT_FALSE(p.blocks[2].sides->object);
  ASSERT_TRUE(p.blocks[2].sides->left && p.blocks[2].sides->right);
  EXPECT_EQ(p.blocks[2].sides->left->source, BlurSource::kFixed);
  EXPECT_EQ(p.blocks[2].sides->left->unit, RadiusUnit::kScreenPx);
  EXPECT_EQ(p.blocks[2].sides->left->radius.number, 0.5);
  EXPECT_EQ(p.blocks[2].sides->right->unit, RadiusUnit::kPhotoPx);
  EXPECT_EQ(p.blocks[2].sides->right->radius.kind, LevelValue::Kind::kReal);
  EXPECT_EQ(p.blocks[2].sides->right->radius.text, "2.0");
  // The procedure's reference, and both sides of its trials show it.
  ASSERT_TRUE(p.blocks[3].procedure);
  const BlurSpec& reference = p.blocks[3].procedure->reference;
  EXPECT_EQ(reference.source, BlurSource::kFixed);
  EXPECT_EQ(reference.unit, RadiusUnit::kArcmin);
  EXPECT_EQ(reference.radius.number, 1.5);
  for (const Trial& t : BuildTrials(p, "P1", 1)) {
    if (t.block == "fixed") {
      EXPECT_EQ(SideText(t.left), R"({"screen_px":0.5})");
      EXPECT_EQ(SideText(t.right), "2.0");
    }
    if (t.block == "quest") {
      EXPECT_TRUE(t.left == reference && t.right == reference);
    }
  }
}

// The single layout's {"object": SOURCE}: one object, shown as the left side and recorded on both.
TEST(ProtocolTyped, AnObjectSideIsBothSides) {
  Json j = test::Valid();
  j["layout"] = "single";
  j["task"] = "yes_no";
  j["counterbalance"] = "none";
  j["responses"] = Json::parse(R"({"yes": "Y", "no": "N"})");
  j["blocks"] = Json::parse(R"([{"name": "one", "factors": {"edge": [2]}, "sides": {"object": "fitted"}}])");
  const Protocol p = ParseProtocol(j, test::SceneFolder() / "p.json");
  ASSERT_TRUE(p.blocks[0].sides);
  EXPECT_TRUE(p.blocks[0].sides->object);
  ASSERT_TRUE(p.blocks[0].sides->left && p.blocks[0].sides->right);
  EXPECT_EQ(p.blocks[0].sides->left->source, BlurSource::kFitted);
  EXPECT_EQ(p.blocks[0].sides->right->source, BlurSource::kFitted);
}

// A level object's value that is neither a number nor a string (true, null) was refused as "a level must be a
// number or a string, got null", naming neither the file nor the field (issue 39): it is a problem with its pointer.
TEST(ProtocolValidate, ALevelValueOfTrueOrNullIsNamedByFileAndPointer) {
  Json j = Valid();
  j["blocks"][0]["factors"]["pattern"][0]["id"] = nullptr;
  j["blocks"][0]["factors"]["pattern"][1]["speed_cm_s"] = true;
  const std::vector<std::string> problems = Problems(j);
  ASSERT_EQ(problems.size(), 2u);
  const std::string file = (SceneFolder() / "p.json").string();
  EXPECT_EQ(problems[0], file + ": /blocks/0/factors/pattern/0/id: must be a number or a string, got null");
  EXPECT_EQ(problems[1], file + ": /blocks/0/factors/pattern/1/speed_cm_s: must be a number or a string, got true");
}

}  // namespace
}  // namespace blurcue::protocol
