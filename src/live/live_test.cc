// The live view's GL-free parts: the one-slot mailbox drops and never queues, the planner draws what ar plans for the
// same frame (the causal streak), the log's summary against hand-worked numbers, INPUT's camera names.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>
#include <unistd.h>


#include "core/error.h"
#include "live/live_log.h"
#include "live/live_plan.h"
#include "live/mailbox.h"
#include "live/paced_source.h"
#include "optics/thin_lens.h"

namespace blurcue::live {
namespace {

LiveFrame Numbered(int index) {
  LiveFrame f;
  f.image = cv::Mat(2, 2, CV_8UC3, cv::Scalar::all(index));
  f.index = index;
  f.arrival = Clock::now();
  return f;
}

TEST(FrameMailbox, AFramePostedOverAnUntakenOneReplacesItAndCountsItDropped) {
  FrameMailbox box;
  LiveFrame a = Numbered(0), b = Numbered(1), c = Numbered(2), got;
  EXPECT_FALSE(box.Post(a));
  EXPECT_TRUE(box.Post(b));
  EXPECT_TRUE(box.Post(c));
  ASSERT_EQ(box.Take(got, std::chrono::milliseconds(0)), FrameMailbox::Got::kFrame);
  EXPECT_EQ(got.index, 2);  // the newest; 0 and 1 were dropped, never queued
  EXPECT_EQ(box.dropped(), 2);
  EXPECT_EQ(box.Take(got, std::chrono::milliseconds(1)), FrameMailbox::Got::kTimeout);
}

TEST(FrameMailbox, AFrameLeftWhenClosedIsStillTakenThenClosedIsSaid) {
  FrameMailbox box;
  LiveFrame a = Numbered(7), got;
  box.Post(a);
  box.Close("the video ended after 8 frames", false);
  LiveFrame late = Numbered(8);
  EXPECT_FALSE(box.Post(late));  // ignored once closed
  ASSERT_EQ(box.Take(got, std::chrono::milliseconds(0)), FrameMailbox::Got::kFrame);
  EXPECT_EQ(got.index, 7);
  EXPECT_EQ(box.Take(got, std::chrono::milliseconds(0)), FrameMailbox::Got::kClosed);
  EXPECT_EQ(box.why_closed(), "the video ended after 8 frames");
  EXPECT_FALSE(box.failed());
}

TEST(FrameMailbox, ATakerWaitingIsWokenByAPost) {
  FrameMailbox box;
  std::thread poster([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    LiveFrame f = Numbered(3);
    box.Post(f);
  });
  LiveFrame got;
  EXPECT_EQ(box.Take(got, std::chrono::milliseconds(5000)), FrameMailbox::Got::kFrame);
  EXPECT_EQ(got.index, 3);
  poster.join();
}

TEST(PacedSource, CameraNamesAreDevicesOrIndices) {
  EXPECT_EQ(CameraDevice("/dev/video2"), "/dev/video2");
  EXPECT_EQ(CameraDevice("0"), "/dev/video0");
  EXPECT_EQ(CameraDevice("take.avi"), "");
  EXPECT_EQ(CameraDevice("frames/frame-%04d.png"), "");
}

TEST(PacedSource, AMissingCameraIsAnInputErrorNamingTheDevice) {
  try {
    PacedSource source("/dev/video97", 0, 0);
    FAIL() << "opened a camera that is not there";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    EXPECT_NE(std::string(e.what()).find("/dev/video97: no camera there"), std::string::npos) << e.what();
  }
}

TEST(PacedSource, ACameraThatStopsDeliveringClosesTheMailboxWithOneLineNamingItAndTheFramesRead) {
  // The camera is a 5-frame video read through the reader a camera is read through: its end is a read that fails,
  // as a camera unplugged mid-run.
  const std::filesystem::path video =
      std::filesystem::temp_directory_path() / ("blurcue-live-camera-" + std::to_string(getpid()) + ".avi");
  {
    media::VideoWriter writer;
    ASSERT_TRUE(writer.Open(video.string(), media::Fourcc('M', 'J', 'P', 'G'), 30, cv::Size(64, 48)));
    for (int i = 0; i < 5; ++i) writer.Write(cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(40 * i)));
  }
  auto reader = std::make_unique<media::VideoReader>();
  ASSERT_TRUE(reader->Open(video.string()));
  PacedSource source("/dev/video42", std::move(reader), 0);
  EXPECT_TRUE(source.is_camera());
  FrameMailbox box;
  source.Start(&box, Clock::now());
  LiveFrame got;
  int taken = 0;
  FrameMailbox::Got status;
  while ((status = box.Take(got, std::chrono::milliseconds(5000))) == FrameMailbox::Got::kFrame) ++taken;
  source.Stop();
  std::filesystem::remove(video);
  ASSERT_EQ(status, FrameMailbox::Got::kClosed);
  EXPECT_EQ(taken + box.dropped(), 5);  // every frame delivered: taken, or replaced unseen
  EXPECT_TRUE(box.failed());
  EXPECT_EQ(box.why_closed(), "/dev/video42: the camera stopped delivering frames after 5 frames");
  ASSERT_TRUE(source.error().has_value());
  EXPECT_EQ(source.error()->kind(), ErrorKind::kInput);
  EXPECT_EQ(std::string(source.error()->what()).find('\n'), std::string::npos);  // one line
}

// A video of `frames` frames of 64 x 48 in FFV1 (lossless: every frame reads back as written), frame i grey 40 i.
std::filesystem::path GreyVideo(const std::string& name, int frames) {
  const std::filesystem::path video =
      std::filesystem::temp_directory_path() / ("blurcue-live-" + name + "-" + std::to_string(getpid()) + ".avi");
  media::VideoWriter writer;
  EXPECT_TRUE(writer.Open(video.string(), media::Fourcc('F', 'F', 'V', '1'), 30, cv::Size(64, 48)));
  for (int i = 0; i < frames; ++i) writer.Write(cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(40 * i)));
  return video;
}

// --preload: every frame decoded before the start, then delivered at its pace from memory, each the frame the
// decoder gives when decoding as it plays, and the end said as then.
TEST(PacedSource, APreloadedVideoDeliversEveryFrameAsDecodedAndEndsAsOneDecodedWhilePlayed) {
  const std::filesystem::path video = GreyVideo("preload", 5);
  PacedSource source(video.string(), 100, 0);
  source.Preload(cv::Size(64, 48));
  EXPECT_EQ(source.preloaded_frames(), 5);
  EXPECT_NEAR(source.preloaded_mb(), 5 * 64 * 48 * 3 * 1e-6, 1e-9);
  FrameMailbox box;
  source.Start(&box, Clock::now());
  LiveFrame got;
  std::vector<int> seen;
  FrameMailbox::Got status;
  while ((status = box.Take(got, std::chrono::milliseconds(5000))) == FrameMailbox::Got::kFrame) {
    seen.push_back(got.index);
    EXPECT_EQ(cv::mean(got.image)[0], 40 * got.index) << got.index;  // the frame's own pixels, not a recycled buffer's
  }
  source.Stop();
  std::filesystem::remove(video);
  ASSERT_EQ(status, FrameMailbox::Got::kClosed);
  EXPECT_EQ(int(seen.size()) + box.dropped(), 5);
  EXPECT_FALSE(box.failed());
  EXPECT_EQ(box.why_closed(), video.string() + " ended after 5 frames");
}

// More frames than the memory --preload may hold: one line naming INPUT and the --frames that fit, a usage error,
// before any frame is delivered; --frames within it preloads those.
TEST(PacedSource, APreloadBeyondItsMemoryIsOneUsageLineNamingTheFramesThatFit) {
  const std::filesystem::path video = GreyVideo("preload-cap", 5);
  const double frame_mb = 64 * 48 * 3 * 1e-6;
  try {
    PacedSource source(video.string(), 30, 0);
    source.Preload(cv::Size(64, 48), 3.5 * frame_mb);
    ADD_FAILURE() << "5 frames preloaded into room for 3";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kUsage);
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    EXPECT_NE(std::string(e.what()).find(video.string() + ": --preload would hold its 5 frames"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("give --frames 3"), std::string::npos) << e.what();
  }
  PacedSource three(video.string(), 30, 3);
  three.Preload(cv::Size(64, 48), 3.5 * frame_mb);
  EXPECT_EQ(three.preloaded_frames(), 3);
  std::filesystem::remove(video);
  EXPECT_THROW(PacedSource("/dev/video42", nullptr, 0).Preload(cv::Size(64, 48)), Error);  // a camera decodes its own frames
}

// An image sequence's frames are counted, so its size is known before a frame is decoded: the refusal comes at once,
// in round numbers (it came after decoding up to the limit - 12 s and 2 GB for 900 frames - and said "more than 761
// frames" and "2.63122 MB"). The files here are no images: decoding one would end the preload on a damaged frame
// instead, so the refusal shows it decoded none.
TEST(PacedSource, ASequenceTooLargeToPreloadIsRefusedBeforeAFrameIsDecoded) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("blurcue-live-sequence-" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  for (int i = 0; i < 900; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "frame-%04d.png", i);
    std::ofstream(dir / name) << "not a PNG";
  }
  const std::string pattern = (dir / "frame-%04d.png").string();
  const cv::Size size(1148, 764);  // 2.63 MB a frame: 760 fit in 2000 MB
  try {
    PacedSource source(pattern, 30, 0);
    source.Preload(size, 2000);
    ADD_FAILURE() << "900 frames of 2.6 MB preloaded into 2000 MB";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kUsage) << e.what();
    EXPECT_EQ(std::string(e.what()), pattern + ": --preload would hold its 900 frames decoded, 2.6 MB each (2368 MB): "
                                               "more than the 2000 MB it may hold (760 frames); give --frames 760, or "
                                               "leave --preload out");
  }
  // --frames within the limit: those are decoded (and the first is no image: the preload ends on it, as a damaged
  // frame ends it, with the error kept for the end of the run).
  PacedSource fits(pattern, 30, 760);
  EXPECT_NO_THROW(fits.CheckPreloadFits(size, 2000));
  fits.Preload(size, 2000);
  EXPECT_EQ(fits.preloaded_frames(), 0);
  std::filesystem::remove_all(dir);
}

// A board face-on at 500 mm moving -10 mm in x a frame, 30 frames a second (stimulus/tracked_take_test.cc's take).
calib::SceneCalib FaceOnLens() {
  calib::SceneCalib c;
  c.camera.focal_length_mm = 20, c.camera.f_number = 4, c.camera.sensor_width_mm = 20, c.camera.sensor_height_mm = 15;
  c.camera.image_width_px = 1000, c.camera.image_height_px = 750;
  c.model.focus_mm = 400, c.model.aperture_mm = 5, c.model.kind = "thin_lens";
  return c;
}

calib::BoardPose PoseAt(int i) {
  calib::BoardPose p;
  p.rvec = {0, 0, 0};
  p.tvec = {-10.0 * i, 0, 500};
  return p;
}

TEST(LivePlanner, DrawsWhatArPlansForTheLastFrameOfTheTakeSoFar) {
  std::vector<stimulus::PlacedObject> ball(1);
  ball[0].name = "ball1";
  ball[0].object = stimulus::BallAt(0, 0, 10);
  stimulus::TakeBlur blur;
  blur.source = BlurSource::kFitted;
  blur.exposure_ms = 15;
  LivePlanner planner(FaceOnLens(), ball, blur);
  stimulus::TrackedTake take;  // the frames so far, as ar would read them from a track folder
  for (int i = 0; i < 4; ++i) {
    const bool lost = i == 2;
    const std::optional<calib::BoardPose> pose = lost ? std::nullopt : std::optional(PoseAt(i));
    const auto status = lost ? track::FrameStatus::kLost : track::FrameStatus::kTracked;
    stimulus::TrackedFrame f;
    f.index = i, f.time_s = i / 30.0, f.status = status;
    if (pose) {
      f.calib = FaceOnLens();
      f.calib->rvec = pose->rvec, f.calib->tvec = pose->tvec;
    }
    take.frames.push_back(f);
    const stimulus::TrackedFramePlan live = planner.Plan(i, i / 30.0, status, pose);
    const stimulus::TrackedFramePlan ar = stimulus::PlanTrackedFrame(take, i, ball, blur);
    ASSERT_EQ(live.drawn.size(), ar.drawn.size()) << "frame " << i;
    for (size_t k = 0; k < ar.drawn.size(); ++k) {
      EXPECT_EQ(live.drawn[k].r_px, ar.drawn[k].r_px) << "frame " << i;
      EXPECT_EQ(live.drawn[k].depth_mm, ar.drawn[k].depth_mm);
      EXPECT_EQ(live.drawn[k].screen_px, ar.drawn[k].screen_px);
      // The take so far ends at this frame: ar's one-sided streak there is live's (from the last frame with a pose,
      // across the lost frame 2 for frame 3).
      EXPECT_NEAR(cv::norm(live.drawn[k].motion_px - ar.drawn[k].motion_px), 0, 1e-9) << "frame " << i;
    }
  }
}

// A frame's calibration in which only the sections of `edges` were measured, at depths 400 + 20 (edge - 1) + 2 section
// mm, their blur the thin lens's with focus 450 mm and aperture 5 mm; `flagged` (edge, section) measured unusable.
calib::CalibResult MeasuredEdges(const std::vector<int>& edges, std::pair<int, int> flagged = {0, 0}) {
  calib::CalibResult c;
  c.camera = FaceOnLens().camera;
  optics::Lens lens = optics::Lens::FromCamera(c.camera);
  lens.aperture_mm = 5;
  for (int e = 1; e <= 11; ++e) {
    calib::EdgeResult edge;
    edge.index = e;
    for (int k = 1; k <= 7; ++k) {
      calib::SectionResult sec;
      sec.edge = e, sec.section = k;
      sec.u_mm = 400 + 20 * (e - 1) + 2 * k;
      const bool measured = std::find(edges.begin(), edges.end(), e) != edges.end();
      sec.fit.ok = measured;
      if (measured) sec.fit.r_px = optics::BlurRadiusPx(lens, 450, sec.u_mm);
      if (flagged == std::pair(e, k)) sec.fit.ok = false, sec.fit.flags = {"poor_fit"};
      edge.sections.push_back(sec);
    }
    c.edges.push_back(edge);
  }
  return c;
}

TEST(LiveLens, FitsTheLensToTheLatestReadingOfEverySectionMeasuredSoFar) {
  LiveLens lens(FaceOnLens().camera);
  optics::FittedModel model;
  EXPECT_FALSE(lens.Update(MeasuredEdges({})));  // nothing measured: no fit
  EXPECT_FALSE(lens.Update(MeasuredEdges({1, 6})));  // two edges: too few depths for a model
  lens.Wait();
  EXPECT_FALSE(lens.TakeModel(&model));
  ASSERT_TRUE(lens.Update(MeasuredEdges({11})));  // three frames' subsets make one model: 21 readings
  lens.Wait();
  ASSERT_TRUE(lens.TakeModel(&model));
  EXPECT_EQ(lens.sections(), 21);
  EXPECT_NEAR(model.focus_mm, 450, 0.5);
  EXPECT_NEAR(model.aperture_mm, 5, 0.01);
  EXPECT_FALSE(lens.TakeModel(&model));  // taken once
  // A section measured again and flagged forgets its earlier reading; one not measured keeps it.
  ASSERT_TRUE(lens.Update(MeasuredEdges({}, {6, 3})));
  lens.Wait();
  ASSERT_TRUE(lens.TakeModel(&model));
  EXPECT_EQ(lens.sections(), 20);
  EXPECT_FALSE(lens.Update(MeasuredEdges({})));  // nothing new: no fit
  EXPECT_EQ(lens.sections(), 20);
}

TEST(LiveLens, NoFitStartsWhileTheLastOneIsNotTaken) {
  LiveLens lens(FaceOnLens().camera);
  ASSERT_TRUE(lens.Update(MeasuredEdges({1, 6, 11})));
  EXPECT_FALSE(lens.Update(MeasuredEdges({2})));  // its readings wait for the next fit
  lens.Wait();
  optics::FittedModel model;
  ASSERT_TRUE(lens.TakeModel(&model));
  EXPECT_EQ(lens.sections(), 21);
  ASSERT_TRUE(lens.Update(MeasuredEdges({})));  // edge 2's readings, kept, start the next fit
  lens.Wait();
  ASSERT_TRUE(lens.TakeModel(&model));
  EXPECT_EQ(lens.sections(), 28);
}

TEST(LivePlanner, MeasuredBlurNeedsSectionsLiveDoesNotMeasure) {
  EXPECT_THROW(RequireLiveSource(BlurSource::kMeasured, "--blur"), Error);
  EXPECT_NO_THROW(RequireLiveSource(BlurSource::kFitted, "--blur"));
}

TEST(LiveLog, SummaryCountsAndNearestRankLatencies) {
  std::vector<LiveRow> rows;
  for (int i = 0; i < 20; ++i) {
    LiveRow r;
    r.frame = i;
    r.arrival_s = i / 30.0;
    r.latency_ms = i + 1;  // 1 .. 20 ms
    r.display_s = r.arrival_s + r.latency_ms / 1000;
    r.status = i == 0 ? track::FrameStatus::kFound : track::FrameStatus::kTracked;
    rows.push_back(r);
  }
  const LiveSummary s = Summarize(rows, 1, "ended");
  EXPECT_EQ(s.shown, 20);
  EXPECT_EQ(s.found, 1);
  EXPECT_EQ(s.tracked, 19);
  EXPECT_EQ(s.median_latency_ms, 11);  // nearest rank of 0.5 x 19 = 9.5 -> the 11th value
  EXPECT_EQ(s.p95_latency_ms, 19);     // 0.95 x 19 = 18.05 -> the 19th
  EXPECT_EQ(s.max_latency_ms, 20);
  EXPECT_NE(SummaryLine(s).find("20 frames shown, 1 dropped (4.8 %)"), std::string::npos) << SummaryLine(s);
  EXPECT_EQ(SummaryLine(s).find("lens model"), std::string::npos) << SummaryLine(s);  // no --measure-sections
}

// The two rates are taken over one span, so the frames shown are a part of those delivered. A first frame slower
// than the rest (a full detection) made the shown rate, taken between the first and last display, the larger:
// 60 frames delivered at 30 a second, none dropped, read "30.6 frames a second shown of 30.0 delivered".
TEST(LiveLog, FramesShownASecondAreAPartOfThoseDelivered) {
  std::vector<LiveRow> rows;
  for (int i = 0; i < 60; ++i) {
    LiveRow r;
    r.frame = i;
    r.arrival_s = i / 30.0;
    r.latency_ms = i == 0 ? 60 : 20;
    r.display_s = r.arrival_s + r.latency_ms / 1000;
    rows.push_back(r);
  }
  LiveSummary s = Summarize(rows, 0, "ended");
  EXPECT_NEAR(s.delivered_fps, 30, 1e-9);
  EXPECT_NEAR(s.shown_fps, 30, 1e-9);  // none dropped: every frame delivered was shown
  EXPECT_NE(SummaryLine(s).find("30.0 frames a second shown of 30.0 delivered"), std::string::npos)
      << SummaryLine(s);
  // Every other frame dropped: half of them shown, whatever the latencies.
  std::vector<LiveRow> half;
  for (size_t i = 0; i < rows.size(); i += 2) half.push_back(rows[i]);
  half.back().latency_ms = 5, half.back().display_s = half.back().arrival_s + 0.005;
  s = Summarize(half, 29, "ended");
  EXPECT_NEAR(s.delivered_fps, 30, 1e-9);
  EXPECT_NEAR(s.shown_fps, 15, 1e-9);
}

// A run with --measure-sections says whether its lens model was ever fitted live (a take too short for 3 edges'
// readings drew with the given one throughout, and the summary used to say nothing of it).
// A run that showed no frame (a camera not there, Ctrl-C during the preload) gives no latency: the line says so and
// summary.json's times are null (they were 0.0 ms, which reads as a measurement).
TEST(LiveLog, NoFrameShownGivesNoLatency) {
  LiveSummary s = Summarize({}, 2, "interrupted (SIGINT)");
  EXPECT_EQ(SummaryLine(s), "no frames shown, 2 dropped: no latency to give");
  const Json j = SummaryJson(s);
  EXPECT_EQ(j["frames_shown"], 0);
  EXPECT_TRUE(j["median_latency_ms"].is_null());
  EXPECT_TRUE(j["p95_latency_ms"].is_null());
  EXPECT_TRUE(j["shown_fps"].is_null());
}

TEST(LiveLog, SummarySaysWhetherTheLensWasFittedLive) {
  std::vector<LiveRow> rows(2);
  for (LiveRow& r : rows) r.sections = 1;
  LiveSummary s = Summarize(rows, 0, "ended");
  EXPECT_EQ(s.lens_sections, 0);
  EXPECT_NE(SummaryLine(s).find("lens model never fitted live"), std::string::npos) << SummaryLine(s);
  EXPECT_EQ(SummaryJson(s)["lens_sections"], 0);
  rows.back().lens_sections = 3;
  s = Summarize(rows, 0, "ended");
  EXPECT_NE(SummaryLine(s).find("lens model fitted live to 3 readings"), std::string::npos) << SummaryLine(s);
  EXPECT_EQ(SummaryJson(s)["lens_sections"], 3);
}

// A preloaded run says so on its summary line and in summary.json: its latencies leave the decoding out.
TEST(LiveLog, SummarySaysWhenTheDecodingWasTakenOut) {
  std::vector<LiveRow> rows(2);
  LiveSummary s = Summarize(rows, 0, "ended");
  EXPECT_EQ(SummaryLine(s).find("--preload"), std::string::npos) << SummaryLine(s);
  EXPECT_EQ(SummaryJson(s)["preloaded_frames"], 0);
  s.preloaded_frames = 60;
  EXPECT_NE(SummaryLine(s).find("decoding taken out (--preload: 60 frames decoded before the start)"),
            std::string::npos) << SummaryLine(s);
  EXPECT_EQ(SummaryJson(s)["preloaded_frames"], 60);
}

TEST(LiveLog, ALostFrameHasAnEmptyPose) {
  LiveRow r;
  r.frame = 4;
  std::string csv;
  AppendLiveCsvRow(r, &csv);
  EXPECT_EQ(csv, "4,0.000000,lost,,,,,,,0.000,0.000,0.000000,0.000,0,0,0.000,0\n");
  EXPECT_EQ(LiveCsvHeader(),
            "frame,arrival_s,status,rvec_x,rvec_y,rvec_z,tvec_x_mm,tvec_y_mm,tvec_z_mm,track_ms,render_ms,display_s,"
            "latency_ms,dropped,sections,measure_ms,lens_sections\n");
}

}  // namespace
}  // namespace blurcue::live
