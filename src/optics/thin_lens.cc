#include "optics/thin_lens.h"

#include <cmath>
#include <limits>
#include <sstream>

#include "core/error.h"

namespace blurcue::optics {
namespace {

std::string Mm(double v) {
  std::ostringstream s;
  s << v << " mm";
  return s.str();
}

void RequireBeyondFocalLength(const Lens& lens, double u_mm, const char* name) {
  if (!(u_mm > lens.focal_length_mm))
    throw Error(ErrorKind::kDomain, std::string(name) + " = " + Mm(u_mm) + " is not beyond the focal length f = " +
                                        Mm(lens.focal_length_mm) + ": a thin lens forms no real image there");
}

// 1 - f/u = f / v: written this way every formula stays finite for a point or a focus at infinity.
double InverseMagnification(const Lens& lens, double u_mm) { return 1 - lens.focal_length_mm / u_mm; }

// v0 / v for a point at u with focus at u0: u0 (u - f) / (u (u0 - f)).
double ImageDistanceRatio(const Lens& lens, double focus_mm, double u_mm) {
  return InverseMagnification(lens, u_mm) / InverseMagnification(lens, focus_mm);
}

}  // namespace

Lens Lens::FromCamera(const Camera& camera) {
  return {camera.focal_length_mm, camera.ApertureMm(), camera.PixelPitchMm()};
}

double SignedBlurRadiusPx(const Lens& lens, double focus_mm, double u_mm) {
  RequireBeyondFocalLength(lens, u_mm, "u");
  RequireBeyondFocalLength(lens, focus_mm, "focus distance");
  // Similar triangles (eq. 3.4): 2R / D = (v0 - v) / v = v0/v - 1, signed.
  const double radius_mm = lens.aperture_mm / 2 * (ImageDistanceRatio(lens, focus_mm, u_mm) - 1);
  return radius_mm / lens.pixel_pitch_mm;
}

double BlurRadiusPx(const Lens& lens, double focus_mm, double u_mm) {
  return std::abs(SignedBlurRadiusPx(lens, focus_mm, u_mm));
}

double Eq37SignedPx(const Lens& lens, double u1_mm, double r1_signed_px, double u2_mm) {
  RequireBeyondFocalLength(lens, u1_mm, "u1");
  RequireBeyondFocalLength(lens, u2_mm, "u2");
  const double D = lens.aperture_mm, sigma = lens.pixel_pitch_mm;
  // u1 (u2 - f) / (u2 (u1 - f)), the published ratio, in a form that holds at infinity too.
  const double ratio = InverseMagnification(lens, u2_mm) / InverseMagnification(lens, u1_mm);
  return (ratio * (2 * r1_signed_px * sigma + D) - D) / (2 * sigma);
}

double Eq37Px(const Lens& lens, double u1_mm, double r1_px, double u2_mm) {
  if (!(r1_px >= 0)) {
    std::ostringstream s;
    s << "r1 = " << r1_px << " px: eq. 3.7 takes an unsigned reference radius (use the signed form)";
    throw Error(ErrorKind::kDomain, s.str());
  }
  const double r2 = Eq37SignedPx(lens, u1_mm, r1_px, u2_mm);
  if (r2 < 0) {
    std::ostringstream s;
    s << "u2 = " << Mm(u2_mm) << " is nearer than the focus plane implied by r1 = " << r1_px << " px at u1 = "
      << Mm(u1_mm) << " (" << Mm(FocusFromReferenceMm(lens, u1_mm, r1_px))
      << "); eq. 3.7 as published assumes both points beyond focus: use the signed form";
    throw Error(ErrorKind::kDomain, s.str());
  }
  return r2;
}

double FocusFromReferenceMm(const Lens& lens, double u1_mm, double r1_signed_px) {
  RequireBeyondFocalLength(lens, u1_mm, "u1");
  const double f = lens.focal_length_mm;
  // v0 / v1 = (2 R1 + D) / D  ->  v0, then u0 = f v0 / (v0 - f).
  const double v1 = f / InverseMagnification(lens, u1_mm);
  const double v0 = v1 * (2 * r1_signed_px * lens.pixel_pitch_mm + lens.aperture_mm) / lens.aperture_mm;
  const double eps = 1e-12 * f;
  if (std::abs(v0 - f) <= eps) return std::numeric_limits<double>::infinity();
  if (v0 < f) {
    std::ostringstream s;
    s << "r1 = " << r1_signed_px << " px at u1 = " << Mm(u1_mm)
      << " is more blur in front of focus than this lens makes even focused at infinity";
    throw Error(ErrorKind::kDomain, s.str());
  }
  return f * v0 / (v0 - f);
}

}  // namespace blurcue::optics
