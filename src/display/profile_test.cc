#include "display/profile.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "core/error.h"

namespace blurcue::display {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string ProblemsOf(const Json& json) {
  std::string text;
  for (const auto& p : ValidateProfile(json, "lab.json")) text += p + "\n";
  return text;
}

bool Contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// 1 degree at 60 cm is 2 * 600 * tan(0.5 deg) = 10.4721 mm; the default monitor's pitch is 531.4 / 1920 mm.
TEST(Profile, PixelsPerDegreeFollowTheGeometry) {
  const Profile p = DefaultProfile();
  const double expected = 2 * 600 * std::tan(0.5 * kPi / 180) / (531.4 / 1920);
  EXPECT_NEAR(PxPerDeg(p), expected, 1e-9);
  EXPECT_NEAR(PxPerDeg(p), 37.84, 0.01);
  // PsychoPy's small-angle deg2pix (deg * distance * pi / 180 / pitch) agrees within 0.01 % at 1 degree.
  EXPECT_NEAR(PxPerDeg(p) / (600 * kPi / 180 / (531.4 / 1920)), 1, 1e-4);
  EXPECT_NEAR(ArcminOfScreenPx(p, PxPerDeg(p)), 60, 1e-9);
}

TEST(Profile, ArcminAndScreenPixelsAreInverses) {
  Profile p = DefaultProfile();
  p.distance_mm = 450;
  for (double px : {0.1, 1.0, 4.0, 37.0, 500.0}) EXPECT_NEAR(ScreenPxOfArcmin(p, ArcminOfScreenPx(p, px)), px, 1e-9);
  // Far from the line of sight the small-angle line overstates: 1000 px at 45 cm is 2 atan(138.4 / 450).
  EXPECT_NEAR(ArcminOfScreenPx(p, 1000), 2 * std::atan(0.5 * 1000 * 531.4 / 1920 / 450) * 180 / kPi * 60, 1e-9);
}

// docs/display.md's worked example: the thesis's 4 px on a 4592 x 3056 photo fitted into a 1920 x 1080 window (shown
// 1622 px wide) on the default monitor: 1.413 screen px, 2.241 arcmin.
TEST(Profile, WorkedExampleOfTheReadme) {
  const Profile p = DefaultProfile();
  const double screen_px = 4 * 1622.0 / 4592.0;
  EXPECT_NEAR(screen_px, 1.413, 0.001);
  EXPECT_NEAR(ArcminOfScreenPx(p, screen_px), 2.241, 0.001);
}

TEST(Profile, SrgbTransferIsTheStandardCurve) {
  Transfer t;
  EXPECT_NEAR(RelativeLuminance(t, 0.5), 0.214041, 1e-6);  // IEC 61966-2-1
  EXPECT_NEAR(RelativeLuminance(t, 0.04), 0.04 / 12.92, 1e-12);
  for (double v : {0.0, 0.01, 0.2, 0.5, 0.9, 1.0}) EXPECT_NEAR(DriveLevel(t, RelativeLuminance(t, v)), v, 1e-9);
}

// Points drawn from L = 0.4 + 117.6 v^2.35 are fitted back exactly; with 1 % photometer noise, closely.
TEST(Profile, GammaFitRecoversAKnownDisplay) {
  std::vector<LuminancePoint> points;
  for (int i = 0; i <= 8; ++i) {
    const double v = i / 8.0;
    points.push_back({v, 0.4 + 117.6 * std::pow(v, 2.35)});
  }
  GammaFit fit = FitGamma(points);
  EXPECT_NEAR(fit.gamma, 2.35, 1e-4);
  EXPECT_NEAR(fit.a, 0.4, 1e-3);
  EXPECT_NEAR(fit.k, 117.6, 1e-2);
  EXPECT_LT(fit.rms_cd_m2, 1e-3);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0, 0.01);
  for (auto& p : points) p.cd_m2 *= 1 + noise(rng);
  fit = FitGamma(points);
  EXPECT_NEAR(fit.gamma, 2.35, 0.05);
  EXPECT_NEAR(fit.k, 117.6, 2);
  Transfer t;
  t.kind = TransferKind::kMeasured;
  t.fit = fit;
  EXPECT_NEAR(RelativeLuminance(t, DriveLevel(t, 0.18)), 0.18, 1e-9);
  EXPECT_THROW(FitGamma({{0, 5}, {0.5, 5}, {1, 5}}), Error);
  EXPECT_THROW(FitGamma({{0, 5}, {1, 50}}), Error);
}

TEST(Profile, ParsesAFileAndRecordsEveryField) {
  const Json json = Json::parse(R"({"name": "lab 1", "width_px": 2560, "height_px": 1440, "width_mm": 596.7,
      "height_mm": 335.7, "distance_mm": 700, "refresh_hz": 120,
      "transfer": {"kind": "measured", "points": [[0, 0.5], [0.25, 4.68], [0.5, 24.6], [0.75, 61.5], [1, 120.5]]}})");
  const Profile p = ParseProfile(json, "lab1.json");
  EXPECT_EQ(p.width_px, 2560);
  EXPECT_EQ(p.refresh_hz, 120);
  EXPECT_EQ(p.transfer.kind, TransferKind::kMeasured);
  EXPECT_NEAR(p.transfer.fit.gamma, 2.4, 0.1);
  const Json recorded = ToJson(p);
  EXPECT_EQ(recorded["name"], "lab 1");
  EXPECT_NEAR(recorded["px_per_deg"].get<double>(), PxPerDeg(p), 1e-12);
  EXPECT_TRUE(recorded["transfer"].contains("fit"));
  // The default's name says what it is; a file without a name is named by its stem.
  EXPECT_EQ(ParseProfile(Json::object(), "monitors/booth-2.json").name, "booth-2");
}

TEST(Profile, EveryProblemAtOnceWithFilePointerAndValue) {
  const std::string text = ProblemsOf(Json::parse(R"({"width_px": 1920.5, "height_px": 1080, "width_mm": 1e308,
      "height_mm": 300, "distance_mm": -1, "refresh_hz": "60", "viewing_distance": 60,
      "transfer": {"kind": "gamma"}})"));
  EXPECT_TRUE(Contains(text, "lab.json: /width_px: must be a whole number of px, got 1920.5")) << text;
  EXPECT_TRUE(Contains(text, "lab.json: /width_mm: must be in [50, 20000] mm, got 1e+308")) << text;
  EXPECT_TRUE(Contains(text, "lab.json: /distance_mm: must be in [100, 20000] mm, got -1")) << text;
  EXPECT_TRUE(Contains(text, "lab.json: /refresh_hz: must be a number of Hz, got \"60\"")) << text;
  EXPECT_TRUE(Contains(text, "lab.json: /viewing_distance: unknown key")) << text;
  EXPECT_TRUE(Contains(text, "lab.json: /transfer/gamma: is required for a gamma transfer")) << text;
}

// A profile's name is recorded with every session and printed: one line of at most 100 bytes, as a protocol's name.
// A 100,000-character name, or one with a newline or an escape, used to be taken and printed raw.
TEST(Profile, NameIsOneLineOfAtMost100Characters) {
  EXPECT_EQ(ParseProfile({{"name", std::string(100, 'x')}}, "lab.json").name, std::string(100, 'x'));
  EXPECT_EQ(ParseProfile({{"name", "booth 1, Zoë's room"}}, "lab.json").name, "booth 1, Zoë's room");
  const std::string longer = ProblemsOf({{"name", std::string(100000, 'x')}});
  EXPECT_TRUE(Contains(longer, "lab.json: /name: must be at most 100 characters, got 'xxx")) << longer;
  EXPECT_TRUE(Contains(longer, "...' (100000 characters)\n")) << longer;
  EXPECT_LT(longer.size(), 200u);
  for (const char* name : {"booth\n1", "booth\x1b[2J", "tab\there"}) {
    const std::string text = ProblemsOf({{"name", name}});
    EXPECT_TRUE(Contains(text, "lab.json: /name: must not contain control characters")) << text;
    EXPECT_EQ(text.find('\n'), text.size() - 1) << text;  // one line: the value is escaped
    EXPECT_THROW(ParseProfile({{"name", name}}, "lab.json"), Error);
  }
}

TEST(Profile, InconsistentOrPartialSizesAreRefused) {
  EXPECT_TRUE(Contains(ProblemsOf({{"width_px", 1920}, {"height_px", 1080}, {"width_mm", 531.4}, {"height_mm", 400}}),
                       "not square"));
  EXPECT_TRUE(Contains(ProblemsOf({{"width_px", 1920}}), "/height_px: is required with the other resolution field"));
  EXPECT_TRUE(Contains(ProblemsOf({{"transfer", {{"kind", "measured"}, {"points", {{0, 1}, {0.5, 2}, {0.4, 3}}}}}}),
                       "/transfer/points/2: drive levels must rise within [0, 1]"));
  EXPECT_TRUE(Contains(ProblemsOf({{"transfer", {{"kind", "srgb"}, {"gamma", 2.2}}}}),
                       "/transfer/gamma: is not a field of a srgb transfer"));
  EXPECT_TRUE(Contains(ProblemsOf(Json::array()), "a display profile must be a JSON object"));
  EXPECT_THROW(ParseProfile({{"distance_mm", 0}}, "x.json"), Error);
}

}  // namespace
}  // namespace blurcue::display
