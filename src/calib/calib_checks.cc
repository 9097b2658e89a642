#include "calib/calib_checks.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "calib/scene_blur.h"
#include "core/error.h"

namespace blurcue::calib {
namespace {

// The side of a board square where a section lies (photo px): the larger of its length along the edge and the gap to
// the parallel edge beside it (twice its window's half width).
double SquareSidePx(const SectionResult& s) {
  return std::max(std::hypot(s.segment.b.x - s.segment.a.x, s.segment.b.y - s.segment.a.y),
                  2 * s.segment.half_window_px);
}

std::string Fixed(double v, int digits) {
  char text[48];
  std::snprintf(text, sizeof text, "%.*f", digits, v);
  return text;
}

// Where a refusal points: camera.json's focal length when the pose says the camera is not the photo's, else the
// photo; `why` is the rest of the line.
[[noreturn]] void Refuse(const CalibResult& result, const std::string& camera_file,
                         const std::string& photo_file, const std::string& why) {
  if (result.pose.reprojection_error_px > kPoseSuspectPx)
    throw InputError(camera_file + ": /focal_length_mm",
                     PoseSuspectText(result, photo_file) + "; " + why +
                         ": is this camera.json the photo's (focal length, sensor size, dist_coeffs)? nothing written");
  throw InputError(photo_file, why + "; nothing written");
}

// The first radius the calibration states that is over twice the side of a square where it is read: "" when none.
std::string AbsurdRadius(const CalibResult& result) {
  auto over = [](double r, double side) { return !(r <= 2 * side); };
  auto text = [](const std::string& what, double r, double side) {
    return what + " is " + Fixed(r, 1) + " px where a square of the board spans " + Fixed(side, 0) +
           " px: a blur over twice that leaves the board grey, so no section could have measured it";
  };
  // The reference edge (eq. 3.7's anchor): the mean side of its squares.
  const EdgeResult& ref = result.edges[size_t(result.reference_edge - 1)];
  double side = 0;
  for (const auto& s : ref.sections) side += SquareSidePx(s) / double(ref.sections.size());
  if (!ref.sections.empty() && over(result.reference_r_px, side))
    return text("reference edge " + std::to_string(result.reference_edge) + "'s blur r", result.reference_r_px, side);
  for (const auto& e : result.edges)
    for (const auto& s : e.sections) {
      const std::string where = "edge " + std::to_string(s.edge) + " section " + std::to_string(s.section);
      if (s.fit.ok && over(s.fit.r_px, SquareSidePx(s)))
        return text(where + "'s measured blur", s.fit.r_px, SquareSidePx(s));
      if (over(s.r_fitted_px, SquareSidePx(s)))
        return text("the lens model's blur at " + where, s.r_fitted_px, SquareSidePx(s));
    }
  return "";
}

}  // namespace

std::string PoseSuspectText(const CalibResult& result, const std::string& photo_file) {
  return "is " + Num(result.camera.focal_length_mm) + " mm, and with it the board's corners fit the pose only to " +
         Fixed(result.pose.reprojection_error_px, 2) + " px" + (photo_file.empty() ? "" : " in " + photo_file) +
         " (a photo of this camera fits to well under 1 px)";
}

double ApertureRatio(const CalibResult& result, const Camera& camera) {
  return result.model.aperture_mm / camera.ApertureMm();
}

bool ApertureFarFromNominal(const CalibResult& result, const Camera& camera) {
  const double ratio = ApertureRatio(result, camera);
  return !(ratio >= 1 / kApertureWarnFactor && ratio <= kApertureWarnFactor);
}

void RefuseAbsurdCalibration(const CalibResult& result, const std::string& camera_file,
                             const std::string& photo_file) {
  if (const std::string absurd = AbsurdRadius(result); !absurd.empty())
    Refuse(result, camera_file, photo_file, absurd);
  // The profiles themselves: the PSF family that fits the limited sections best leaves residuals far over the pixels'
  // noise (chi-square per point ~ 1 where it explains them): no blurred edge is there to measure.
  const double chi2 = result.phase.chi2_per_point;
  if (chi2 > kMaxChi2PerPoint)
    Refuse(result, camera_file, photo_file,
           "the board's edges do not fit a blurred edge: the best of the PSF families leaves residuals " +
               Fixed(std::sqrt(chi2), 0) + " x the pixels' noise (chi-square per point " + Fixed(chi2, 0) +
               ", over " + Num(kMaxChi2PerPoint) + "; the suite's scenes read under 160, JPEGs of quality 90 among "
               "them): compression (JPEG blocks), motion, or a board that is not the one given");
  // The sections' blurs together: one thin lens leaves many of them far off (outliers of its robust fit).
  const optics::FittedModel& m = result.model;
  if (m.samples_used > 0 && m.outliers > kMaxOutlierShare * m.samples_used)
    Refuse(result, camera_file, photo_file,
           "the blur of " + std::to_string(m.outliers) + " of the " + std::to_string(m.samples_used) +
               " sections the lens model is fitted to is far from it (outliers; over a quarter): the sections' "
               "blurs do not follow one thin lens (compression, motion, a board not flat, or sections off the "
               "board's edges)");
  // A sharpening after sampling on a photo with every edge blurred 2 px or more (ReadPhaseFamilies): its lobes show
  // in the profiles, but no edge is sharp enough to pin its strength apart from the lens's blur.
  if (const PhaseChoice::Wide& w = result.phase.wide; !w.sharpening.empty() && w.moved_rel > kMaxWideSharpeningMove)
    Refuse(result, camera_file, photo_file,
           "the board's edges fit " + w.sharpening + " better than the optics alone (chi-square " + Fixed(w.chi2_sharpening, 0) + " against " + Fixed(w.chi2_optics, 0) + " over " +
               std::to_string(w.sections) + " sections, in units of their noise), which moves their readings by " +
               Fixed(100 * w.moved_rel, 1) + " % (median; at least), and with every edge blurred 2 px or more "
               "nothing in the photo pins the sharpening apart from the lens: each blur read would be the two "
               "together. Turn the camera's sharpening off (or take raw), or focus nearer the board so that some "
               "edges blur under 2 px");
  // What is written must be what every reader takes (render, run, validate read calib.json through
  // SceneCalibFromJson): a fit that lands outside the readers' ranges (all edges at one depth: an aperture of 2.5 m)
  // is refused here, naming the field, not by the next command.
  try {
    SceneCalibFromJson(CalibToJson(result), "");
  } catch (const Error& e) {
    const std::string what = e.what();
    Refuse(result, camera_file, photo_file,
           "the calibration would not be one blurcue can use (" + what + ")" +
               (what.rfind("/model/", 0) == 0 ? ": the board's edges may not span enough depths to fit a lens "
                                                "(photograph the board at a slant, not face on)"
                                              : ""));
  }
}

}  // namespace blurcue::calib
