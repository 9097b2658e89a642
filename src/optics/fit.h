#pragma once
// A thin-lens model fitted to many measured (u, r) pairs, so an estimate need not hang on one reference edge.
#include <string>
#include <vector>

#include "optics/thin_lens.h"

namespace blurcue::optics {

struct BlurSample {
  double u_mm = 0;
  double r_px = 0;      // measured blur radius (unsigned)
  double weight = 1.0;  // e.g. the measurement's confidence; 0 drops the sample
};

struct FitOptions {
  // Huber threshold in px for the robust loss (residuals beyond it count linearly, not squared).
  double huber_px = 0.5;
  // Also fit a blur floor r0 added in quadrature, r = sqrt(r_thin_lens^2 + r0^2) (residual optics blur that the
  // thin lens does not explain). Kept only when it lowers the leave-one-out error: model no more than needed.
  bool allow_floor = true;
};

struct FittedModel {
  double focus_mm = 0;     // u0, may be +infinity
  double aperture_mm = 0;  // effective D (the thin lens's D when the optics are ideal)
  double floor_px = 0;     // r0, 0 when the simpler model was kept
  double rms_px = 0;       // robust fit residual
  double loo_rms_px = 0;   // leave-one-out prediction error of the kept model
  int samples_used = 0;    // with weight > 0
  int outliers = 0;        // samples whose residual exceeds 3 huber_px at the optimum
  std::string kind;        // "thin_lens" or "thin_lens+floor"
  // Both candidates' errors on the same (inlier) samples, whichever was kept: in-sample and leave-one-out rms, px.
  // The floor model's are NaN where it was not fitted (fewer than 10 samples, or allow_floor off).
  double thin_rms_px = 0, thin_loo_rms_px = 0;
  double floor_rms_px = 0, floor_loo_rms_px = 0;
  double floor_candidate_px = 0;  // the floor the floor model found (kept or not)
  // The floors the sections cannot tell apart from the floor model's (its predictions within 0.5 % rms after
  // refitting focus and aperture), px; NaN where the floor model was not fitted.
  double floor_lo_px = 0, floor_hi_px = 0;
  // The kept floor is pinned by the sections: that range spans at most max(0.1 px, 20 % of it). False for the thin
  // lens alone (no floor kept) and where focus off the board leaves the floor free (a wide range).
  bool floor_determined = false;
  // A sharpening after sampling that cancels more than the floor's whole second moment (r^2 units, px^2, <= 0): the
  // part beyond the floor, taken from the thin lens's too, so the photo's blur is sqrt(max(0, thin^2 + floor^2 +
  // cancel_px2)) (calib's WithFilter; calib.json model.cancel_px2). 0 for every photo whose floor it leaves.
  double cancel_px2 = 0;

  // Predicted unsigned radius at depth u (px), with the lens's f and pitch.
  double PredictPx(const Lens& lens, double u_mm) const;
};

// The floors lo..hi fit alike: they pin floor_px when the range spans at most max(0.1 px, 20 % of it) (FittedModel's
// floor_determined).
bool FloorRangePinned(double lo, double hi, double floor_px);

// Whether the model's floor_px is a result: the thin lens alone (floor 0) or a floor the sections pin.
bool FloorPinned(const FittedModel& m);

// The floor in words for a summary line: "floor 0.70 px (a std of 0.35 px)" (the floor is a radius, 2 x its
// Gaussian's std, as every r_px), "floor 0 px (thin lens alone)" (with "floors 0.00-3.58 px fit alike: not
// determined" where the floor model's range is wide) or, where the sections do not pin the floor model's,
// "floor not determined (0.99-1.86 px fit alike)".
std::string FloorText(const FittedModel& m);

// How FitThinLens chooses between its two candidates, in words (calib.json's model.choice.rule).
extern const char* const kModelChoiceRule;

// Robust least squares over (focus, aperture[, floor]). Throws Error(kNotFound) with fewer than 3 usable samples
// or samples all at one depth.
FittedModel FitThinLens(const Lens& lens, const std::vector<BlurSample>& samples, const FitOptions& options = {});

}  // namespace blurcue::optics
