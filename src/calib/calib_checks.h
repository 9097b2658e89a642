#pragma once
// What `calibrate` refuses or states loudly about a measured photo beyond what Calibrate refuses: a blur no
// section of this photo could show (a camera.json whose focal length is not the photo's put every section off its
// edge), edges that no blurred edge explains (a JPEG of quality 1), and a fitted aperture far from the nominal one.
// docs/calibration.md says what each bound is and how it was chosen.
#include <string>

#include "calib/calibrate.h"
#include "core/camera.h"

namespace blurcue::calib {

// The fitted aperture over the camera's nominal one (f / N) beyond which calibrate warns: two thirds of a stop
// (2^(1/3) = 1.26 either way). A lens's marked f-numbers are rounded to a third of a stop; the suite's calibrations
// fit 0.876-1.038 x (docs/calibrate-checks.md).
inline constexpr double kApertureWarnFactor = 1.2599210498948732;

// The chosen PSF family's chi-square per profile point (phase check) above which no blurred edge explains the board's
// profiles: residuals 100 x the pixels' noise. The suite's 37 calibrations stay under 160 (a JPEG of quality 90 over
// a filter); a JPEG of quality 20 reads 45000, of quality 3 480000.
inline constexpr double kMaxChi2PerPoint = 1e4;

// The share of the lens fit's sections that may be its outliers (residual over 3 Huber widths) before the sections'
// blurs are said not to follow one thin lens: the suite's 37 calibrations have none; a focal length 1.7 x the
// photo's makes 58 %, a JPEG of quality 5 10 %.
inline constexpr double kMaxOutlierShare = 0.25;

// With every edge blurred 2 px or more, where a sharpening after sampling fits the profiles better than the lens alone
// (PhaseChoice::wide): the median move of the readings under it beyond which the photo is refused. A mask of 0.7 over
// 0.6 px focused at 5 m moved them 1.3 % and read 1.6 % high (kept); masks of amount 1-3 over 1-2 px moved them 4.8-6.2 %
// (a lower bound: the families stop at 0.7 over 1 px) and read 10 % to 2.5 px off.
inline constexpr double kMaxWideSharpeningMove = 0.03;

// Throws Error(kInput) with one line when the calibration is physically absurd for its photo or its edges fit no
// blurred edge: a radius (the reference edge's, a usable section's, the model's at a section) over twice the side of
// a board square where it is read (a blur that wide leaves the board grey: no section could have measured it), the
// chi-square per point over kMaxChi2PerPoint, or more than kMaxOutlierShare of the lens fit's sections its outliers.
// The line names `camera_file` and its focal length when the pose fits the corners worse than 1 px (the camera is
// then likelier not the photo's), `photo_file` otherwise.
void RefuseAbsurdCalibration(const CalibResult& result, const std::string& camera_file,
                             const std::string& photo_file);

// A pose fitting the board's corners worse than this is not this camera's (a photo of it fits to well under 1 px):
// refusals then name camera.json's focal length (RefuseAbsurdCalibration here, RequireThreeDepths in calibrate.cc).
inline constexpr double kPoseSuspectPx = 1;

// "is F mm, and with it the board's corners fit the pose only to E px in PHOTO (a photo of this camera fits to well
// under 1 px)": how such a refusal starts (`photo_file` empty: no "in PHOTO").
std::string PoseSuspectText(const CalibResult& result, const std::string& photo_file);

// The fitted aperture over the nominal (f / N of camera.json).
double ApertureRatio(const CalibResult& result, const Camera& camera);
// Whether ApertureRatio is beyond kApertureWarnFactor either way.
bool ApertureFarFromNominal(const CalibResult& result, const Camera& camera);

}  // namespace blurcue::calib
