// calib.json read as calibrate writes it (scene_blur.cc's SceneCalibFromJson, calib_whole.cc): every field checked,
// hand edits that the readers would ignore or that contradict the file refused, naming the file and the field.
#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "calib/calib_test_util.h"
#include "calib/scene_blur.h"
#include "core/error.h"

namespace blurcue::calib {
namespace {

// SceneCalibFromJson refuses `j` with Error(kInput) whose message is exactly `expected`.
void ExpectCalibRefused(const Json& j, const std::string& expected) {
  try {
    SceneCalibFromJson(j, "calib.json: ");
    ADD_FAILURE() << expected;
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    EXPECT_EQ(std::string(e.what()), expected);
  }
}

// An edge or a section listed twice would be averaged with its copy or stand in for a missing one: refused, named.
TEST(SceneCalib, EdgeOrSectionListedTwiceIsRefused) {
  const Calibration& r = Calibrated(Blurry());
  Json twice_edge = CalibToJson(r.result);
  twice_edge["edges"][1]["index"] = 1;
  Json twice_section = CalibToJson(r.result);
  twice_section["edges"][2]["sections"][4]["index"] = 2;
  for (const auto& [j, expected] : {std::pair{twice_edge, "calib.json: /edges/1/index: edge 1 is listed twice (also at /edges/0)"},
                                    {twice_section, "calib.json: /edges/2/sections/4/index: section 2 of edge 3 is listed twice (also at /sections/1)"}})
    ExpectCalibRefused(j, expected);
}

TEST(SceneCalib, BadFieldIsNamed) {
  const Calibration& r = Calibrated(Thesis());
  Json j = CalibToJson(r.result);
  j["pose"]["tvec"] = {1, 2};
  try {
    SceneCalibFromJson(j, "calib.json: ");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("calib.json: /pose/tvec: must be an array of 3 numbers"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(ParseBlurSource("blurry", nullptr), Error);
}

// model.undetermined (calibrate's depths where the lens model is not determined within 5 %) is read: the fitted
// source inside them gets a note naming the file and the field, outside them and other sources none; a hand edit
// that would move or hide them is refused, named, as is a calibration that kept them in their earlier place.
TEST(SceneCalib, UndeterminedDepthsAreReadAndNoted) {
  const Calibration& r = Calibrated(Thesis());
  Json j = CalibToJson(r.result);
  j["model"]["undetermined"] = {{"u_mm", {400.0, 420.0}}, {"worst_se_rel", 0.12}, {"why", "w"}};
  const SceneCalib s = SceneCalibFromJson(j, "calib.json: ");
  EXPECT_EQ(UndeterminedNote(s, BlurSource::kFitted, 410),
            "the fitted blur at 410 mm is the lens model's estimate, not a result within 5 %: the model is not "
            "determined within 5 % at 400-420 mm (its error up to 12 %; why: calib.json /model/undetermined)");
  EXPECT_EQ(UndeterminedNote(s, BlurSource::kFitted, 421), "");
  EXPECT_EQ(UndeterminedNote(s, BlurSource::kEstimated, 410), "");
  j["model"]["undetermined"] = nullptr;
  EXPECT_EQ(UndeterminedNote(SceneCalibFromJson(j, "calib.json: "), BlurSource::kFitted, 410), "");
  j["model"]["undetermined"] = {{"u_mm", {420.0, 400.0}}, {"worst_se_rel", 0.12}};
  ExpectCalibRefused(j, "calib.json: /model/undetermined/u_mm: must be [near, far] depths in mm, beyond the focal "
                        "length (21 mm), near <= far, got [420.0,400.0]");
  j["model"]["undetermined"] = {{"u_mm", {1.0, 5.0}}, {"worst_se_rel", 0.12}};  // nearer than the focal length
  ExpectCalibRefused(j, "calib.json: /model/undetermined/u_mm: must be [near, far] depths in mm, beyond the focal "
                        "length (21 mm), near <= far, got [1.0,5.0]");
  // Named depths are where the error exceeds 5 %: a smaller one contradicts them; a misspelt field or a reason that
  // is not words would be ignored.
  j["model"]["undetermined"] = {{"u_mm", {400.0, 420.0}}, {"worst_se_rel", 0.01}};
  ExpectCalibRefused(j, "calib.json: /model/undetermined/worst_se_rel: must be in [0.05, 1e+06] (a share, over 0.05 "
                        "where depths are named), got 0.01");
  j["model"]["undetermined"] = {{"u_mm", {400.0, 420.0}}, {"worst_se_rel", 0.12}, {"u_mmm", 1}};
  ExpectCalibRefused(j, "calib.json: /model/undetermined/u_mmm: is not a field of a blurcue calibration (did you mean "
                        "u_mm?)");
  j["model"]["undetermined"] = {{"u_mm", {400.0, 420.0}}, {"worst_se_rel", 0.12}, {"why", 5}};
  ExpectCalibRefused(j, "calib.json: /model/undetermined/why: must be the reason in words (a string), got 5");
  j["model"]["undetermined"] = {{"u_mm", {400.0, 420.0}}};
  ExpectCalibRefused(j, "calib.json: /model/undetermined/worst_se_rel: is required but missing");
  j["model"]["undetermined"] = nullptr;
  j["phase_check"]["model_undetermined"] = {{"u_mm", {400.0, 420.0}}, {"worst_se_rel", 0.12}, {"why", "w"}};
  ExpectCalibRefused(j, "calib.json: /phase_check/model_undetermined: is now read from /model/undetermined (a "
                        "calibration written before kept it here, where its depths would go unsaid): calibrate the "
                        "photo again, or move the field there");
  j["phase_check"]["model_undetermined"] = nullptr;  // an earlier calibration that named none
  EXPECT_EQ(UndeterminedNote(SceneCalibFromJson(j, "calib.json: "), BlurSource::kFitted, 410), "");
  j["phase_check"]["model_undeterminned"] = {{"u_mm", {400.0, 420.0}}};  // misspelt, it would slip past the rule
  ExpectCalibRefused(j, "calib.json: /phase_check/model_undeterminned: is not a field of a blurcue calibration (did "
                        "you mean model_undetermined?)");
  j["phase_check"].erase("model_undeterminned");
  j["phase_check"] = Json::array();  // a hand edit that would hide the depths
  ExpectCalibRefused(j, "calib.json: /phase_check: must be an object, got []");
}

// The model block says which model predicts: its kind is one of the two, the floor model states its floor (a missing
// one was read as 0: the objects drawn without the scene's floor), the thin lens has none (a floor beside it was
// drawn), the focus lies beyond the focal length, and a key calibrate does not write is a hand edit the reader would
// ignore. Each refused, naming the field.
TEST(SceneCalib, ModelBlockIsReadAsWritten) {
  const Calibration& r = Calibrated(Thesis());
  const Json written = CalibToJson(r.result);
  auto refused = [&](const std::function<void(Json&)>& edit, const std::string& expected) {
    Json j = written;
    j["model"]["kind"] = "thin_lens+floor", j["model"]["floor_px"] = 0.7, j["model"]["floor_determined"] = true;
    EXPECT_NO_THROW(SceneCalibFromJson(j, "calib.json: "));
    edit(j);
    ExpectCalibRefused(j, expected);
  };
  refused([](Json& j) { j["model"]["kind"] = 5; },
          "calib.json: /model/kind: must be \"thin_lens\" or \"thin_lens+floor\", got 5");
  refused([](Json& j) { j["model"]["kind"] = "thin_lens+flor"; },
          "calib.json: /model/kind: must be \"thin_lens\" or \"thin_lens+floor\", got \"thin_lens+flor\" (did you "
          "mean thin_lens+floor?)");
  refused([](Json& j) { j["model"].erase("floor_px"); }, "calib.json: /model/floor_px: is required but missing");
  refused([](Json& j) { j["model"]["kind"] = "thin_lens"; },
          "calib.json: /model/floor_px: must be 0 for model kind \"thin_lens\" (no floor), got 0.7; a floor needs kind "
          "\"thin_lens+floor\"");
  refused([](Json& j) { j["model"]["floor_determined"] = "yes"; },
          "calib.json: /model/floor_determined: must be true or false, got \"yes\"");
  refused([](Json& j) { j["model"]["focus_mm"] = 21; },
          "calib.json: /model/focus_mm: must be beyond the camera's focal length (21 mm): a thin lens forms no real "
          "image nearer, got 21");
  refused([](Json& j) { j["model"]["flor_px"] = 1; },
          "calib.json: /model/flor_px: is not a field of a blurcue calibration (did you mean floor_px?)");
  refused([](Json& j) { j["edges"][0]["sections"][0]["ok"] = 1; },
          "calib.json: /edges/0/sections/0/ok: must be true or false, got 1");
  // The smaller objects' fields as written, and a pose with the board in front of the lens (one behind it drew an
  // object at -286 mm, exit 0).
  refused([](Json& j) { j["board"]["colz"] = 7; },
          "calib.json: /board/colz: is not a field of a blurcue calibration (did you mean cols?)");
  refused([](Json& j) { j["pose"]["rvecc"] = 1; },
          "calib.json: /pose/rvecc: is not a field of a blurcue calibration (did you mean rvec?)");
  refused([](Json& j) { j["timing_ms"]["detekt"] = 1; },
          "calib.json: /timing_ms/detekt: is not a field of a blurcue calibration (did you mean detect?)");
  refused([](Json& j) { j["pose"]["rvec"] = {0, 0, 0}, j["pose"]["tvec"] = {0, 0, -300}; },
          "calib.json: /pose: must put the whole board in front of the lens (beyond its focal length), got rvec "
          "[0,0,0], tvec [0,0,-300]");
  refused([](Json& j) { j["version"] = 99; },
          "calib.json: /version: must be 1 (this blurcue reads calibrations of format version 1), got 99");
  // As written, each kind reads back with its floor.
  Json thin = written;
  thin["model"]["kind"] = "thin_lens", thin["model"]["floor_px"] = 0;
  EXPECT_EQ(SceneCalibFromJson(thin, "calib.json: ").model.floor_px, 0);
}

// A calibration is read as a whole (calib_whole.h): fields each in range but not calibrate's together are refused,
// naming the file and the field. One edit of a written calib.json per check; the file as written reads.
void ExpectCalibRefusedAt(const Json& j, const std::string& start) {
  try {
    SceneCalibFromJson(j, "calib.json: ");
    ADD_FAILURE() << "read, though it should be refused with " << start;
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    EXPECT_EQ(std::string(e.what()).rfind(start, 0), 0u) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
  }
}

const Json& WrittenThesisCalib() {
  static const Json j = CalibToJson(Calibrated(Thesis()).result);
  return j;
}

TEST(SceneCalibWhole, TheFileAsWrittenReads) { EXPECT_NO_THROW(SceneCalibFromJson(WrittenThesisCalib(), "calib.json: ")); }

TEST(SceneCalibWhole, BoardColumnsMustBeTheSectionsListed) {
  Json j = WrittenThesisCalib();
  j["board"]["cols"] = 8;  // the card beside edge k moved by a square's share: 67 px
  ExpectCalibRefusedAt(j, "calib.json: /edges/0/sections: 7 sections but the board has 8 columns");
}

TEST(SceneCalibWhole, BoardRowsMustBeTheEdgesListed) {
  Json j = WrittenThesisCalib();
  j["board"]["rows"] = 11;
  ExpectCalibRefusedAt(j, "calib.json: /edges: lists 11 edges but the board of 11 rows has 12");
}

TEST(SceneCalibWhole, RadiusUnitsMustBeWhatCalibrateWrites) {
  Json j = WrittenThesisCalib();
  j["r_units"] = "mm";
  ExpectCalibRefusedAt(j, "calib.json: /r_units: must be what blurcue calibrate writes for a camera without "
                          "dist_coeffs");
}

TEST(SceneCalibWhole, DepthsMustBePositiveAndFinite) {
  Json j = WrittenThesisCalib();
  j["edges"][3]["sections"][2]["u_mm"] = -5;
  ExpectCalibRefusedAt(j, "calib.json: /edges/3/sections/2/u_mm: must be a depth in (0, 1e+06] mm");
  j = WrittenThesisCalib();
  j["edges"][4]["u_mm"] = -5;
  ExpectCalibRefusedAt(j, "calib.json: /edges/4/u_mm: must be a depth in (0, 1e+06] mm");
}

TEST(SceneCalibWhole, SectionDepthMustBeItsMidpoints) {
  Json j = WrittenThesisCalib();
  j["edges"][3]["sections"][2]["u_mm"] = j["edges"][3]["sections"][2]["u_mm"].get<double>() + 10;
  ExpectCalibRefusedAt(j, "calib.json: /edges/3/sections/2/u_mm: must be the depth of the section's midpoint_camera_mm");
}

TEST(SceneCalibWhole, ImagePointsMustBeInsideTheImage) {
  Json j = WrittenThesisCalib();
  ASSERT_TRUE(j["edges"][5]["sections"][3]["ok"].get<bool>());
  j["edges"][5]["sections"][3]["image_px"][1][0] = 1e308;
  ExpectCalibRefusedAt(j, "calib.json: /edges/5/sections/3/image_px/1: must be inside the");
  j = WrittenThesisCalib();
  j["edges"][5]["sections"][3]["image_px"] = {1, 2};
  ExpectCalibRefusedAt(j, "calib.json: /edges/5/sections/3/image_px: must be the section's two ends");
}

}  // namespace
}  // namespace blurcue::calib
