#pragma once
// Thin-lens defocus (thesis chapter 3.3). Knows nothing of images: depths in mm along the optical axis (camera z),
// blur radii r in pixels, r = the blur-circle radius R / pixel pitch (DESIGN.md: for a disc PSF r = R).
#include "core/camera.h"

namespace blurcue::optics {

// The largest blur radius anything renders or accepts as a fixed radius, px. A disc of radius r costs (2 r + 2)^2
// taps a pixel (a million at 500 px) and a Gaussian 3 r taps a pass; no stimulus of a photo's size needs more,
// and a NaN or 1e9 radius would otherwise crash a CPU blur or hang a GPU one.
constexpr double kMaxBlurRadiusPx = 500;

struct Lens {
  double focal_length_mm = 0;  // f
  double aperture_mm = 0;      // D = f / N
  double pixel_pitch_mm = 0;   // the thesis's sigma, mm per pixel

  static Lens FromCamera(const Camera& camera);
};

// Signed blur-circle radius in pixels of a point at depth u_mm when the lens is focused at focus_mm
// (focus_mm may be +infinity). Positive beyond the focus plane, negative nearer than it, zero on it:
//   R = (D f / 2) (u - u0) / (u (u0 - f)),   r = R / pitch.
// Throws Error(kDomain) when u <= f or focus <= f (no real image).
double SignedBlurRadiusPx(const Lens& lens, double focus_mm, double u_mm);

// |SignedBlurRadiusPx|.
double BlurRadiusPx(const Lens& lens, double focus_mm, double u_mm);

// The thesis's eq. 3.7 exactly as published: from a reference (u1, r1) to u2, assuming both points lie beyond
// the focus plane:  r2 = [u1 (u2 - f) / (u2 (u1 - f)) (2 r1 sigma + D) - D] / (2 sigma).
// Throws Error(kDomain) for u1 <= f or u2 <= f (u1 = f divides by zero), r1 < 0, and when u2 is nearer than
// the focus plane implied by (u1, r1) (the published form would return a negative radius there).
double Eq37Px(const Lens& lens, double u1_mm, double r1_px, double u2_mm);

// The signed general form of eq. 3.7: r1_signed < 0 says the reference is nearer than focus. Returns the signed
// radius at u2, valid on both sides of focus (the magnitude is the blur radius).
double Eq37SignedPx(const Lens& lens, double u1_mm, double r1_signed_px, double u2_mm);

// Focus distance implied by a reference point: solves SignedBlurRadiusPx(lens, u0, u1) = r1_signed for u0.
// Returns +infinity when the reference says focus is at infinity; throws Error(kDomain) when no focus
// distance beyond f can produce that radius (e.g. |r1| larger than D f / (2 pitch (u1 - f)) nearer than focus).
double FocusFromReferenceMm(const Lens& lens, double u1_mm, double r1_signed_px);

}  // namespace blurcue::optics
