#pragma once
// A display profile: what a lab keeps per monitor (PsychoPy's Monitor Center, Psychtoolbox's screen set-up) so that
// a stimulus can be stated in physical units. Screen pixels <-> millimetres <-> degrees of visual angle at the
// viewing distance, and the display's transfer function (drive level <-> luminance).
//
// File format (every field optional but `width_px`/`height_px` go together; defaults in DefaultProfile()):
//   { "name": "lab 1, Dell U2412M",
//     "width_px": 1920, "height_px": 1200, "width_mm": 518.4, "height_mm": 324.0,
//     "distance_mm": 600, "refresh_hz": 60,
//     "transfer": {"kind": "srgb"} | {"kind": "gamma", "gamma": 2.2}
//               | {"kind": "measured", "points": [[0, 0.4], [0.25, 6.1], [0.5, 27], [0.75, 64], [1, 118]]} }
// "measured" points are [drive level 0..1, luminance cd/m^2] from a photometer; they are fitted like PsychoPy's
// gamma calibration (its eq. 1): L(v) = a + k v^gamma.
#include <filesystem>
#include <string>
#include <vector>

#include "core/json_io.h"

namespace blurcue::display {

enum class TransferKind { kSrgb, kGamma, kMeasured };

// The resolutions a display profile accepts (width_px, height_px): no participant's display is smaller or larger.
inline constexpr int kMinWidthPx = 320, kMaxWidthPx = 16384, kMinHeightPx = 200, kMaxHeightPx = 16384;

struct LuminancePoint {
  double level = 0;   // drive level, 0..1
  double cd_m2 = 0;   // measured luminance
};

// L(v) = a + k v^gamma (cd/m^2 for "measured"; relative, a = 0 and k = 1, for "gamma").
struct GammaFit {
  double a = 0, k = 1, gamma = 2.2;
  double rms_cd_m2 = 0;  // residual of the fit over the measured points
};

struct Transfer {
  TransferKind kind = TransferKind::kSrgb;
  GammaFit fit;                        // kGamma: gamma only; kMeasured: fitted from `points`
  std::vector<LuminancePoint> points;  // kMeasured
};

struct Profile {
  std::string name = "default (24-inch 16:9 at 60 cm)";
  std::filesystem::path file;  // empty for the default
  int width_px = 1920, height_px = 1080;
  double width_mm = 531.4, height_mm = 298.9;
  double distance_mm = 600;
  double refresh_hz = 60;
  Transfer transfer;
};

// A 24-inch 16:9 monitor (1920 x 1080, 531.4 x 298.9 mm) seen from 60 cm at 60 Hz with an sRGB transfer.
Profile DefaultProfile();

// Every problem of `json` at once ("FILE: /pointer: what, got VALUE"), empty when it is a valid profile.
std::vector<std::string> ValidateProfile(const Json& json, const std::filesystem::path& file);
// Parses and validates; throws one Error(kInput) listing every problem.
Profile ParseProfile(const Json& json, const std::filesystem::path& file);
Profile LoadProfile(const std::filesystem::path& file);

// The profile as recorded with a session: every field, the transfer with its fitted parameters.
Json ToJson(const Profile& profile);

// Least-squares fit of L(v) = a + k v^gamma to measured points (gamma searched in [1, 4], a and k in closed form
// for each gamma). Throws Error(kInput) with fewer than 3 points or a flat curve.
GammaFit FitGamma(const std::vector<LuminancePoint>& points);

// Geometry at the centre of the screen.
double MmPerPx(const Profile& profile);
// Screen pixels per degree of visual angle (the 1 degree centred on the line of sight).
double PxPerDeg(const Profile& profile);
// The visual angle of an extent of `px` screen pixels centred on the line of sight, in arcmin (exact, not the
// small-angle line: 2 atan(s / 2d)).
double ArcminOfScreenPx(const Profile& profile, double px);
// Its inverse: how many screen pixels subtend `arcmin`.
double ScreenPxOfArcmin(const Profile& profile, double arcmin);

// The transfer function: the drive level (0..1) that shows relative luminance `linear` (0..1 of the display's
// range), and back. sRGB uses the IEC 61966-2-1 curve; "gamma" and "measured" use the fit.
double DriveLevel(const Transfer& transfer, double linear);
double RelativeLuminance(const Transfer& transfer, double level);

std::string ToString(TransferKind kind);

}  // namespace blurcue::display
