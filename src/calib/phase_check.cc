#include "calib/phase_check.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <cstdio>
#include <functional>
#include <limits>

#include "calib/calibrate.h"
#include "calib/edge_esf.h"
#include "calib/edge_window.h"
#include "calib/family_esf.h"
#include "calib/phase_fit.h"
#include "calib/phase_profile.h"
#include "calib/phase_flags.h"
#include "core/error.h"

namespace blurcue::calib {
namespace {

using detail::FamilyProfile;
using detail::FamilyTaps;
using detail::ProjectTaps;
using detail::ProjectedTap;
using detail::TapsVariance;
using detail::Bin;
using detail::ProfileBins;
constexpr double kPi = 3.14159265358979323846;
// Phases: an edge whose sub-pixel position moves by a pixel or more along the part measured is sampled at every
// phase (the blur fit super-resolves its profile); under that, few phases.
constexpr double kMinSpanPx = 1.0;
// A section at every phase spreads its samples evenly across the edge: a 0.1 px bin holds a tenth of the length used
// (2 on the far sections of a board turned 45-60 deg). Held to 3 samples, as a level edge's bins are, such a section
// kept 11 of ~150 bins (edge 11 section 7 at 45 deg: 0.75 px for a true 0.85 px, every family alike) or fewer than 6
// (edge 5 section 7 at 60 deg: not read per family, its phase check empty, 0.61 px for 0.13 px unflagged); every bin
// with a sample is kept there (with 3, the interquartile mean is the plain mean anyway). Level edges keep 3.
constexpr size_t kLevelBinSamples = 3, kEveryPhaseBinSamples = 1;
// The pose puts an edge within a few hundredths of a pixel (synth scenes: 0.02-0.06 px); each family finds it within
// this of the pose's line. Fixed at the line, the pose's own error, not the family, would decide the fit.
constexpr double kPoseUncertaintyPx = 0.15;
// Families fit the sections alike when their chi-square over all limited sections is within kAlikeChi2 of the best's
// after scaling by the best's chi-square per point where it is above 1 (25: five standard errors of the one parameter
// that tells the families apart), or within kAlikeRel of it: a model error (a JPEG's blocks, an interpolation) grows
// every family's chi-square with the points, and then the noise no longer says what fits alike. 0.15: a JPEG of
// quality 90 put the true family at 1.14 x the best's; 0.25 took a 0.5 px Gaussian alike on physical optics.
constexpr double kAlikeChi2 = 25, kAlikeRel = 0.15;
// Sections every family is read on before the families that fit them far worse are ruled out (ReadPhaseFamilies).
constexpr size_t kChoiceSections = 12;
constexpr double kChoiceBins = 600;  // ... or fewer sections holding about this many profile points (ChoiceSections)

// How a section's profile lies across the pixels and the board: its normal's components (|n| larger, smaller; see
// ProjectTaps) and, on the board's outer edges, the side (+1: the normal's, -1: the other) that is the table.
struct Across {
  double w1 = 1, w2 = 0;
  int free_side = 0;  // 0: squares on both sides (or not known)
};

// FamilyResiduals on a board's outer edge: the levels, the step and the table's slope by least squares, the model
// low + step x m(x) + slope x max(0, side x) (x from the edge). The table beside the board is a photo's content, not
// print: synth's wood grain, stripes of 9 mm crossing a turned board's outer edge obliquely, left a ramp across edge 11
// section 4's window at 45 deg (the table 2 % of the step darker at the edge than 7 px out) and every family read
// 0.62 px for a true 0.52 px (0.53 px on the same scene with a flat table). The ramp is taken unblurred: its kink at
// the edge, blurred, moves the model by under 1e-3 of the step.
bool TableSlopeResiduals(const std::vector<Bin>& bins, const FamilyProfile& profile, double d0, int side,
                         std::vector<double>* res, double* step_out) {
  std::vector<double>& e = *res;
  cv::Matx33d a = cv::Matx33d::zeros();
  cv::Vec3d y(0, 0, 0);
  for (size_t i = 0; i < bins.size(); ++i) {
    const Bin& b = bins[i];
    const double m = profile(b.x - d0);
    e[i] = m;
    const cv::Vec3d f(1, m, std::max(0.0, side * (b.x - d0)));
    a += b.w * f * f.t();
    y += b.w * b.v * f;
  }
  cv::Vec3d c(0, 0, 0);
  if (!(a(2, 2) > 0)) a(2, 2) = 1;  // no bin on the table's side: the slope stays 0
  const bool ok = cv::determinant(a) > 1e-12 * a(0, 0) * a(1, 1) * a(2, 2) && cv::solve(a, y, c, cv::DECOMP_CHOLESKY);
  if (!ok) c = cv::Vec3d(0, 0, 0);
  for (size_t i = 0; i < bins.size(); ++i)
    e[i] = std::sqrt(bins[i].w) * (bins[i].v - c[0] - c[1] * e[i] - c[2] * std::max(0.0, side * (bins[i].x - d0)));
  if (step_out) *step_out = c[1];
  return ok;
}

// The family's profile at each bin (optics p = {r1, d0, phi}, then the family's taps `taps` projected across the
// edge: ProjectTaps), its two levels by least squares (solved again at every p: the levels are projected out, so the
// search is over the three shape parameters only); `res` gets sqrt(w) x (value - model) and `step` the step. False
// where the profile does not tell the levels apart (the step is then 0). On a board's outer edge the table's level
// may slope across the window: a third linear term, its slope from the edge outwards on the table's side (TableSlope).
bool FamilyResiduals(const std::vector<Bin>& bins, const std::vector<ProjectedTap>& taps, const double* p,
                     const Across& across, std::vector<double>* res, double* step_out = nullptr) {
  const FamilyProfile profile(std::max(p[0], 0.02), p[2], across.w1, across.w2, taps, bins.size());
  std::vector<double>& e = *res;
  e.resize(bins.size());
  if (across.free_side != 0) return TableSlopeResiduals(bins, profile, p[1], across.free_side, res, step_out);
  double s1 = 0, se = 0, see = 0, sv = 0, sev = 0;
  for (size_t i = 0; i < bins.size(); ++i) {
    const Bin& b = bins[i];
    const double m = profile(b.x - p[1]);
    e[i] = m;
    s1 += b.w, se += b.w * m, see += b.w * m * m, sv += b.w * b.v, sev += b.w * m * b.v;
  }
  const double det = s1 * see - se * se;
  const bool ok = det > 1e-12 * s1 * s1;
  const double step = ok ? (s1 * sev - se * sv) / det : 0, low = (sv - step * se) / s1;
  for (size_t i = 0; i < bins.size(); ++i) e[i] = std::sqrt(bins[i].w) * (bins[i].v - low - step * e[i]);
  if (step_out) *step_out = step;
  return ok;
}

double SumOfSquares(const std::vector<double>& r) {
  double s = 0;
  for (const double v : r) s += v * v;
  return s;
}

// Levenberg-Marquardt from p = {r1, d0, phi} on the family's residuals (the optics' radius, the edge's position
// within the pose's uncertainty, the optics' shape); returns the sum of squares at the p it leaves.
double RefineFamily(const std::vector<Bin>& bins, const std::vector<ProjectedTap>& taps, const Across& across,
                    double* p, bool hold_shape = false) {
  std::vector<double> res, trial, col[3];
  FamilyResiduals(bins, taps, p, across, &res);
  double best = SumOfSquares(res);
  const double lo[3] = {0, -kPoseUncertaintyPx, 0}, hi[3] = {1e9, kPoseUncertaintyPx, kPi / 2};
  const double h[3] = {1e-3, 1e-3, 2e-3};
  double lambda = 1e-2;
  for (int it = 0; it < 30; ++it) {
    // Forward differences (inward at a bound).
    double jtj[3][3] = {}, jtr[3] = {};
    for (int c = 0; c < 3; ++c) {
      if (c == 2 && hold_shape) {
        col[c].assign(res.size(), 0.0);
        continue;
      }
      double q[3] = {p[0], p[1], p[2]};
      const double hc = q[c] + h[c] > hi[c] ? -h[c] : h[c];
      q[c] += hc;
      FamilyResiduals(bins, taps, q, across, &col[c]);
      for (size_t i = 0; i < res.size(); ++i) col[c][i] = (col[c][i] - res[i]) / hc;
    }
    for (int a = 0; a < 3; ++a) {
      for (size_t i = 0; i < res.size(); ++i) jtr[a] += col[a][i] * res[i];
      for (int b = 0; b < 3; ++b)
        for (size_t i = 0; i < res.size(); ++i) jtj[a][b] += col[a][i] * col[b][i];
    }
    bool improved = false;
    for (int tries = 0; tries < 8 && !improved; ++tries) {
      cv::Matx33d m;
      cv::Vec3d g;
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) m(a, b) = jtj[a][b];
        m(a, a) += lambda * std::max(jtj[a][a], 1e-12) + (a == 2 && hold_shape ? 1.0 : 0.0);
        g[a] = -jtr[a];
      }
      cv::Vec3d delta;
      if (!cv::solve(m, g, delta, cv::DECOMP_CHOLESKY)) break;
      double q[3];
      for (int c = 0; c < 3; ++c) q[c] = std::clamp(p[c] + delta[c], lo[c], hi[c]);
      FamilyResiduals(bins, taps, q, across, &trial);
      const double v = SumOfSquares(trial);
      if (v < best) {
        improved = true;
        const double gain = best - v;
        best = v, res.swap(trial);
        for (int c = 0; c < 3; ++c) p[c] = q[c];
        lambda = std::max(1e-6, lambda * 0.3);
        if (gain < 1e-4 * best + 1e-15) it = 30;  // settled: a chi-square moving by 1e-4 of itself
      } else {
        lambda *= 10;
      }
    }
    if (!improved) break;
  }
  return best;
}

// The standard error of a family's reading r = sqrt(r1^2 + 4 V) at its best p = {r1, d0, phi} (`res` its residuals
// there): the noise through the inverse of J'J over the parameters the reading was fitted with (the shape too unless
// `held`), the levels profiled out. The section's noise is the spread within its bins, so on a board's outer edge it
// takes in the table's texture (the table beside the board varies along the edge, and a 0.1 px bin of a section at
// every phase holds pixels from a few places along it): there the readings' standard errors were 2-9 % of the reading
// (shape free), 3 times the inner edges'.
double ReadingSe(const std::vector<Bin>& bins, const std::vector<ProjectedTap>& taps, const Across& across,
                 const double* p, const std::vector<double>& res, bool held, double noise, double r) {
  const int n = held ? 2 : 3;
  std::vector<double> col[3];
  const double h[3] = {1e-3, 1e-3, 2e-3};
  for (int c = 0; c < n; ++c) {
    double q[3] = {p[0], p[1], p[2]};
    const double hc = c == 2 && q[2] + h[2] > kPi / 2 ? -h[2] : h[c];
    q[c] += hc;
    FamilyResiduals(bins, taps, q, across, &col[c]);
    for (size_t i = 0; i < res.size(); ++i) col[c][i] = (col[c][i] - res[i]) / hc;
  }
  cv::Matx33d m = cv::Matx33d::eye();  // the shape's row and column stay the identity where it was held
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) {
      m(a, b) = 0;
      for (size_t i = 0; i < res.size(); ++i) m(a, b) += col[a][i] * col[b][i];
    }
  cv::Matx33d inv;
  if (!(cv::invert(m, inv, cv::DECOMP_SVD) > 0) || !(inv(0, 0) >= 0)) return std::numeric_limits<double>::infinity();
  return std::max(p[0], 0.02) / r * noise * std::sqrt(inv(0, 0));  // dr/dr1 = r1 / r
}

// The optics' radius r1, the edge's position d0 (within the pose's uncertainty of the line the pose gives) and the
// optics' shape phi that fit best under one family: a grid for the radius at two shapes, the blur fit's and another
// (the sum of squares may have a shoulder where r1 meets the taps' own spread), then all three at once from the best
// node (RefineFamily). The three are correlated (a sharpening filter's overshoot trades against the optics' shape):
// turns of one-dimensional searches with the blur fit's shape settled on a ridge, 2-5 % short of the true reading with
// the true family on sharpened scenes (amount 0.5), so that a wrong family fitted better.
PhaseReading ReadFamilyAs(const std::vector<Bin>& bins, const PhaseFamily& family, double r_fit, double phi_fit,
                          const Across& across, double noise, bool one_shape, bool se = false) {
  const std::vector<double> taps1 = FamilyTaps(family);
  const std::vector<ProjectedTap> taps = ProjectTaps(taps1, across.w1, across.w2);
  std::vector<double> res;
  double p[3] = {0, 0, phi_fit}, best = std::numeric_limits<double>::infinity();
  const double top = std::max(2.5, 1.6 * r_fit), grid = top / 12;
  for (const double phi : {phi_fit, std::abs(phi_fit - kPi / 4) < 0.2 ? kPi / 2 : kPi / 4})
    for (int k = 0; k <= 12; ++k) {
      const double q[3] = {k * grid, 0, phi};
      FamilyResiduals(bins, taps, q, across, &res);
      if (const double v = SumOfSquares(res); v < best) best = v, p[0] = q[0], p[2] = q[2];
    }
  double sse = RefineFamily(bins, taps, across, p);
  // At r = 0 the profile's slope in r vanishes (its variance grows as r^2), so a refinement started there stays: on an
  // edge near a pixel centre the grid's best node was 0 and the optics alone read 0.00 px where the blur fit read
  // 0.42-0.51 px (true 0.43 px; floor 0.2 px), flagged as a jump and holding the model 7 % low. Started from the blur
  // fit's reading too, the better end is kept - for the optics alone only: restarted, filter families that had
  // stuck at 0 on an aliased take frame (supersample 1) came to fit alike and flagged a whole edge.
  if (!(family.sigma_px > 0) && p[0] < 0.05 && r_fit > 0.05) {
    double q[3] = {r_fit, 0, p[2]};
    if (const double v = RefineFamily(bins, taps, across, q); v < sse) sse = v, p[0] = q[0], p[1] = q[1], p[2] = q[2];
  }
  // Where the blur fit found the shape ambiguous under a pixel and read the size as a Gaussian (edge_blur.cc), the
  // family's optics under a pixel are read so too: a shape the profile cannot tell moved the optics-alone reading
  // 8-20 % off on physical optics, and it off its neighbouring families' readings (disc x 0.2 px floor).
  const bool held = one_shape && p[0] < kOneShapeBelowPx;
  if (held) {
    p[2] = kPi / 2;
    RefineFamily(bins, taps, across, p, /*hold_shape=*/true);
  }
  const double r1 = p[0], d0 = p[1];
  double step = 0;
  const bool ok = FamilyResiduals(bins, taps, p, across, &res, &step);
  sse = ok ? SumOfSquares(res) : std::numeric_limits<double>::infinity();
  double w = 0;
  for (const Bin& bin : bins) w += bin.w;
  PhaseReading out;
  // The filter is the taps on both axes (ProjectTaps): its variance across an edge of any direction is the taps' V, so
  // the whole is r1^2 + 4 V. (Read with the taps along the nearest axis alone, the other axis's share was left to
  // the optics' r1, an approximation that let edges only 25 deg off an axis be read per family.)
  out.r_px = std::sqrt(std::max(0.0, r1 * r1 + 4 * TapsVariance(taps1)));
  out.offset_px = d0;
  out.rms_rel = std::abs(step) > 1e-9 ? std::sqrt(sse / std::max(w, 1.0)) / std::abs(step) : 1e9;
  out.chi2 = sse / (noise * noise);
  if (se && ok && out.r_px > 0) out.r_se_px = ReadingSe(bins, taps, across, p, res, held, noise, out.r_px);
  return out;
}

// ReadFamilyAs with the two levels; on a board's outer edge (across.free_side) and where `table`, read again with the
// table's slope taken (TableSlopeResiduals) into r_table_px. Taken always, the slope's own noise moved correct
// readings as much as the ramps it took out (turned 60 deg: edge 11 section 6 0.48 -> 0.52 px for a true 0.46 px,
// edge 11 at 45 deg section 4 0.62 -> 0.56 px for 0.52 px): the two readings apart is the reading not identified.
PhaseReading ReadFamily(const std::vector<Bin>& bins, const PhaseFamily& family, double r_fit, double phi_fit,
                        const Across& across, double noise, bool one_shape, bool table = true) {
  const Across plain{across.w1, across.w2, 0};
  PhaseReading out = ReadFamilyAs(bins, family, r_fit, phi_fit, plain, noise, one_shape, /*se=*/table);
  if (table && across.free_side != 0)
    out.r_table_px = ReadFamilyAs(bins, family, r_fit, phi_fit, across, noise, one_shape).r_px;
  return out;
}

// A section's gate and profile (CheckPhase's first half): where `check.limited` comes back true, `profile` holds what
// its families are read on.
struct PhaseProfile {
  std::vector<Bin> bins;
  double phi = 0, r_fit = 0;
  Across across;
  bool one_shape = false;  // the blur fit read the size with the Gaussian shape (ambiguous under a pixel)
};

PhaseCheck GatePhase(const cv::Mat& linear, const EdgeSegment& segment, const ModelFit& fit,
                     const ModelFitOptions& options, PhaseProfile* profile) {
  PhaseCheck check;
  const EdgeFrame f = MakeEdgeFrame(segment);
  if (!(f.length > 1)) return check;
  const double ax = std::abs(f.t.x), ay = std::abs(f.t.y);
  check.axis_deg = std::atan2(std::min(ax, ay), std::max(ax, ay)) * 180 / kPi;
  check.span_px = std::clamp(options.along_fraction, 0.0, 1.0) * f.length * std::min(ax, ay);
  // Across the nearest axis: the edge's position at its midpoint between pixel centres (integers).
  const cv::Point2d mid = 0.5 * (segment.a + segment.b) + (std::isfinite(segment.bow_px) ? segment.bow_px : 0) * f.n;
  const double across = ax >= ay ? mid.y : mid.x;
  check.phase_px = across - std::floor(across);
  const bool few = check.span_px < kMinSpanPx;
  // At any angle: a family's taps act on both axes (ProjectTaps). Read along the nearest axis alone, edges more than
  // 25 deg off it were not read (physical boards turned 45 and 60 deg chose a Gaussian of 0.35 px that no photo had).
  if (!(fit.r_px > 0 && std::isfinite(fit.r_px))) return check;
  const double half = std::min(segment.half_window_px, 2 * fit.r_px + 6);
  const std::vector<Bin> bins = ProfileBins(linear, segment, options.along_fraction, half,
                                            few ? kLevelBinSamples : kEveryPhaseBinSamples, &check.noise);
  if (bins.size() < 6) return check;
  const bool wide = fit.r_px >= kMaxBlurPx;
  // A section of 2 px or more with printing spots keeps the blur fit's reading, which rejects them: the profile's
  // interquartile means do not where a spot covers a quarter of the part measured (edge 10 section 6 of a sharpened
  // scene with 20 flaws, two spots of 1.1 and 1.9 mm: 4.59 px under the chosen mask for a true 2.70 px; 3.11 px so).
  if (wide && std::find(fit.flags.begin(), fit.flags.end(), "flaw") != fit.flags.end()) return check;
  check.limited = few && !wide, check.every_phase = !few && !wide, check.wide = wide;
  check.bins = static_cast<int>(bins.size());
  // The optics' shape: the blur fit's (disc x Gaussian); rounded to the nearer pure shape, the misfit of a mixed one
  // made a post filter look better than the optics alone on physical optics.
  const double phi = std::atan2(2 * fit.floor_sigma_px, fit.disc_r_px);
  Across placed{std::max(std::abs(f.n.x), std::abs(f.n.y)), std::min(std::abs(f.n.x), std::abs(f.n.y)), 0};
  // A board's outer edge has a parallel board edge on one side only (calibrate.cc): the other is the table.
  if (segment.neighbours.size() == 1) {
    const NeighbourEdge& o = segment.neighbours[0];
    placed.free_side = f.n.dot(0.5 * (o.a + o.b) - 0.5 * (segment.a + segment.b)) > 0 ? -1 : 1;
  }
  *profile = {bins, phi, fit.r_px, placed,
              fit.shape_ambiguous && fit.r_px < kOneShapeBelowPx && fit.r_px >= kOneShapeFromPx};
  return check;
}

// A section's misfit: its best family's chi-square over its degrees of freedom plus `sd` standard deviations of a
// chi-square's own spread (sqrt(2 dof) each), where above 1 (a quasi-likelihood's dispersion, one per section).
double MisfitScale(const PhaseCheck& check, double sd) {
  double least = std::numeric_limits<double>::infinity();
  for (const PhaseReading& f : check.families)
    if (std::isfinite(f.chi2)) least = std::min(least, f.chi2);
  const int dof = std::max(1, check.bins - 3);
  return std::isfinite(least) ? std::max(1.0, least / (dof + sd * std::sqrt(2.0 * dof))) : 1.0;
}

// Each family's chi-square summed over `checks`, each section in units of its own misfit. A profile that no family
// explains (an aliased, point-sampled edge; a take's blur levels; a flaw) reads at 100-700 per point, and summed raw a
// few such sections outvote every clean one: on a physical synth-take frame (supersample 1, no filter after sampling,
// 244 per point) a Gaussian of 0.35 px beat the optics alone by 17 % raw. Whether the photo has a filter at all is
// asked with every section weighed from 1 x its dof (there the optics alone fits best, 2307 against 3623; the filtered
// scenes' filters win by 815-46000); which filter, with only misfit beyond 4 standard deviations of the noise weighed
// (weighed from 1 x dof, the noise alone moved the bench's mask of amount 0.7 to 0.3 over 0.8 px, model p90 21 %; the
// take frame weighed so chose a Gaussian of 0.31 px). A filter is taken only where one fits better than the optics
// alone by kAlikeChi2 in the first weighing (each section in its own noise units): on a physical board turned 60 deg
// a Gaussian of 0.35 px (taps 0.017, 0.966, 0.017) fitted 8185.0 against the optics alone's 8186.9 and was chosen,
// flagging a correct section. `best` is the family chosen so (0: the optics alone), `chi2` the weighing it is chosen by.
struct WeighedChi2 {
  std::vector<double> chi2, any;
  size_t best = 0;
};
WeighedChi2 WeighedTotals(const std::vector<const PhaseCheck*>& checks, size_t nf) {
  std::vector<double> any(nf, 0.0), which(nf, 0.0);
  for (const PhaseCheck* c : checks) {
    const double w_any = 1 / MisfitScale(*c, 0), w_which = 1 / MisfitScale(*c, 4);
    for (size_t f = 0; f < nf; ++f) any[f] += w_any * c->families[f].chi2, which[f] += w_which * c->families[f].chi2;
  }
  const bool filter = nf > 1 && *std::min_element(any.begin() + 1, any.end()) < any[0] - kAlikeChi2;
  WeighedChi2 out{filter ? which : any, any, 0};
  if (filter) out.best = std::min_element(which.begin(), which.end()) - which.begin();
  return out;
}

// How many sections every family is read on before the others are ruled out: kChoiceSections, or fewer where the
// profiles are long (a section at every phase: 0.1 px bins across its whole window, 100-160 points against a level
// edge's 12-18), so that they hold about kChoiceBins points and at least 4 sections. The refinement between the
// families reads the same sections about 30 times: on a board turned 20 deg under a filter, 12 such sections made
// calibrate 18.7 s (0.5 s before they were read at all).
size_t ChoiceSections(const std::vector<SectionResult*>& usable, const std::vector<size_t>& limited) {
  std::vector<int> bins;
  for (const size_t k : limited) bins.push_back(usable[k]->phase.bins);
  std::nth_element(bins.begin(), bins.begin() + bins.size() / 2, bins.end());
  const double median = std::max(1, bins[bins.size() / 2]);
  return std::clamp<size_t>(static_cast<size_t>(std::ceil(kChoiceBins / median)), 4, kChoiceSections);
}

// Reads the families marked in `read` (all when empty); the others are left unread: r_px NaN, chi2 infinity.
void ReadFamilies(const PhaseProfile& p, const std::vector<bool>& read, PhaseCheck* check) {
  const std::vector<PhaseFamily>& families = PhaseFamilies();
  check->families.clear();
  for (size_t c = 0; c < families.size(); ++c) {
    if (!read.empty() && !read[c]) {
      PhaseReading unread;
      unread.r_px = unread.offset_px = unread.rms_rel = std::numeric_limits<double>::quiet_NaN();
      unread.chi2 = std::numeric_limits<double>::infinity();
      check->families.push_back(unread);
      continue;
    }
    check->families.push_back(
        ReadFamily(p.bins, families[c], p.r_fit, p.phi, p.across, check->noise, p.one_shape));
  }
}

using Each = std::function<void(size_t, const std::function<void(size_t)>&)>;

// No section under 2 px: nothing to choose a family on, and none is chosen. A strong sharpening still shows in wide
// profiles (its lobes), and there every reading is the lens's and the mask's together, with nothing to pin the mask
// (the adversary's scene focused at 5 m under a mask of amount 1 over 2 px: every section 2.5 px off, exit 0).
// Asked as the choice asks whether a photo has a filter, on up to kChoiceSections of them spread over the board.
PhaseChoice::Wide AskWideForSharpening(const std::vector<SectionResult*>& usable, const std::vector<size_t>& wide,
                                       const std::vector<PhaseProfile>& profiles, const Each& each) {
  const size_t n = std::min(wide.size(), kChoiceSections);
  std::vector<PhaseCheck> read(n);
  each(n, [&](size_t i) {
    const size_t k = wide[(2 * i + 1) * wide.size() / (2 * n)];
    read[i] = usable[k]->phase;
    ReadFamilies(profiles[k], {}, &read[i]);
  });
  std::vector<const PhaseCheck*> checks;
  for (const PhaseCheck& c : read) checks.push_back(&c);
  const WeighedChi2 t = WeighedTotals(checks, PhaseFamilies().size());
  if (t.best != 0 && TapsVariance(FamilyTaps(PhaseFamilies()[t.best])) < 0) {
    std::vector<double> apart;  // how far the mask moves each reading from the lens's alone
    for (const PhaseCheck& c : read)
      if (const double r = c.families[0].r_px, m = c.families[t.best].r_px; std::isfinite(r) && std::isfinite(m))
        apart.push_back(std::abs(m - r) / std::max(r, 1e-9));
    if (apart.empty()) return {};
    std::nth_element(apart.begin(), apart.begin() + apart.size() / 2, apart.end());
    return {PhaseFamilies()[t.best].Name(), t.any[0], t.any[t.best], static_cast<int>(n), apart[apart.size() / 2]};
  }
  return {};
}

}  // namespace

PhaseCheck CheckPhase(const cv::Mat& linear, const EdgeSegment& segment, const ModelFit& fit,
                      const ModelFitOptions& options) {
  PhaseProfile profile;
  PhaseCheck check = GatePhase(linear, segment, fit, options, &profile);
  if (check.limited) ReadFamilies(profile, {}, &check);
  check.every_phase = check.wide = false;  // read by ReadPhaseFamilies only, with the photo's other sections
  return check;
}

// long: one reading plan on shared profiles (deciders, the rest, the refined mask and its valley, the wide).
void ReadPhaseFamilies(CalibResult& result, const cv::Mat& linear, const ModelFitOptions& options, bool parallel) {
  std::vector<SectionResult*> usable;
  for (auto& edge : result.edges)
    for (auto& s : edge.sections)
      if (s.fit.ok) usable.push_back(&s);
  std::vector<PhaseProfile> profiles(usable.size());
  auto each = [parallel](size_t n, const std::function<void(size_t)>& body) {
    auto range = [&](const cv::Range& r) {
      for (int k = r.start; k < r.end; ++k) body(static_cast<size_t>(k));
    };
    if (parallel && n > 1) cv::parallel_for_(cv::Range(0, int(n)), range, int(n));
    else range(cv::Range(0, int(n)));
  };
  each(usable.size(), [&](size_t k) { usable[k]->phase = GatePhase(linear, usable[k]->segment, usable[k]->fit,
                                                                   options, &profiles[k]); });
  std::vector<size_t> limited, wide;
  for (size_t k = 0; k < usable.size(); ++k)
    if (usable[k]->phase.limited || usable[k]->phase.every_phase) limited.push_back(k);
    else if (usable[k]->phase.wide) wide.push_back(k);
  if (limited.empty() && !wide.empty()) {
    result.phase.wide = AskWideForSharpening(usable, wide, profiles, each);
    return;
  }
  // The sections of 2 px or more, where a filter fitted the choice's sections best (fit_between appended it): read with
  // the families marked in `read` (all when empty) and the fitted one, for ChoosePhaseFamily to take the chosen one's
  // reading. They do not join the choice: at that blur the families read within 2-5 % of each other.
  auto read_wide = [&](const std::vector<bool>& read) {
    if (result.phase.families.size() <= PhaseFamilies().size()) return;
    const PhaseFamily& fitted = result.phase.families.back();
    each(wide.size(), [&](size_t i) {
      const PhaseProfile& p = profiles[wide[i]];
      PhaseCheck& check = usable[wide[i]]->phase;
      ReadFamilies(p, read, &check);
      check.families.push_back(ReadFamily(p.bins, fitted, p.r_fit, p.phi, p.across, check.noise, p.one_shape));
      for (int e = 0; e < 2 && result.phase.has_valley; ++e)
        check.valley_r_px[e] = ReadFamily(p.bins, result.phase.valley[e], p.r_fit, p.phi, p.across, check.noise,
                                          p.one_shape).r_px;
    });
  };
  // Few sections: every family on each, as CheckPhase. Otherwise the families are first read on kChoiceSections of
  // them at phases spread over the pixel (sorted by phase, evenly picked): the families those fit far worse than the
  // best (twice ChoosePhaseFamily's "alike" margins) are not read on the others. The rest of the choice is
  // ChoosePhaseFamily's over all of them, as before; the profiles' misfit of a ruled-out family only grows with more
  // sections, so it would not have been alike. On physical optics this reads 1-3 families on most sections, not 15.
  result.phase.families = PhaseFamilies();
  result.phase.choice_sections = 0;
  // Where the family that fits the sections `deciders` best is a filter, the filter between the families that fits
  // them best (RefinePhaseFamily: about 30 readings of each), read on every limited section as one family more.
  auto fit_between = [&](const std::vector<size_t>& deciders) {
    const size_t nf = PhaseFamilies().size();
    std::vector<const PhaseCheck*> checks;
    std::vector<double> weight;  // every section in its own units (WeighedTotals's first weighing)
    int points = 0;
    for (const size_t k : deciders)
      checks.push_back(&usable[k]->phase), weight.push_back(1 / MisfitScale(usable[k]->phase, 0)),
          points += usable[k]->phase.bins;
    const size_t best = WeighedTotals(checks, nf).best;
    if (best == 0) return;
    std::vector<double> chi2(deciders.size());
    auto total = [&](const PhaseFamily& family) {
      each(deciders.size(), [&](size_t i) {
        const PhaseProfile& p = profiles[deciders[i]];
        chi2[i] = weight[i] * ReadFamily(p.bins, family, p.r_fit, p.phi, p.across,
                                         usable[deciders[i]]->phase.noise, p.one_shape, /*table=*/false).chi2;
      });
      return std::accumulate(chi2.begin(), chi2.end(), 0.0);
    };
    const PhaseFamily fitted = RefinePhaseFamily(PhaseFamilies()[best], total);
    result.phase.families.push_back(fitted);
    // Its valley's ends within the margin the choice calls alike (ChoosePhaseFamily's, on these sections).
    const double at = total(fitted), dof = std::max(1, points - 3 * int(deciders.size()) - 1);
    const auto ends = ValleyEnds(fitted, total, std::max(kAlikeChi2 * std::max(1.0, at / dof), kAlikeRel * (at - dof)));
    result.phase.has_valley = fitted.sharpen > 0, result.phase.valley[0] = ends[0], result.phase.valley[1] = ends[1];
    each(limited.size(), [&](size_t i) {
      const PhaseProfile& p = profiles[limited[i]];
      PhaseCheck& check = usable[limited[i]]->phase;
      check.families.push_back(ReadFamily(p.bins, fitted, p.r_fit, p.phi, p.across, check.noise, p.one_shape));
      for (int e = 0; e < 2 && result.phase.has_valley; ++e)
        check.valley_r_px[e] = ReadFamily(p.bins, ends[e], p.r_fit, p.phi, p.across, check.noise, p.one_shape).r_px;
    });
  };
  if (limited.size() <= 2 * kChoiceSections) {
    each(limited.size(), [&](size_t i) { ReadFamilies(profiles[limited[i]], {}, &usable[limited[i]]->phase); });
    fit_between(limited);
    read_wide({});
    return;
  }
  std::vector<size_t> by_phase = limited;
  std::stable_sort(by_phase.begin(), by_phase.end(),
                   [&](size_t a, size_t b) { return usable[a]->phase.phase_px < usable[b]->phase.phase_px; });
  std::vector<bool> first(usable.size(), false);
  std::vector<size_t> chosen;
  const size_t n_choice = result.phase.choice_sections = ChoiceSections(usable, limited);
  for (size_t i = 0; i < n_choice; ++i) {
    const size_t k = by_phase[(2 * i + 1) * by_phase.size() / (2 * n_choice)];
    if (!first[k]) first[k] = true, chosen.push_back(k);
  }
  each(chosen.size(), [&](size_t i) { ReadFamilies(profiles[chosen[i]], {}, &usable[chosen[i]]->phase); });
  const size_t nf = PhaseFamilies().size();
  int points = 0;
  std::vector<const PhaseCheck*> checks;
  for (const size_t k : chosen) points += usable[k]->phase.bins, checks.push_back(&usable[k]->phase);
  const WeighedChi2 totals = WeighedTotals(checks, nf);
  const std::vector<double>& chi2 = totals.chi2;
  const size_t best = totals.best;
  const int dof = std::max(1, points - 3 * int(chosen.size()) - 1);
  const double scale = std::max(1.0, chi2[best] / dof), excess = std::max(0.0, chi2[best] - dof);
  std::vector<bool> read(nf);
  for (size_t c = 0; c < nf; ++c)
    read[c] = c == 0 || chi2[c] - chi2[best] <= 2 * std::max(kAlikeChi2 * scale, kAlikeRel * excess);
  // ChoosePhaseFamily's jump test reads the neighbours, on the few-phase sections only (a section at every phase
  // tells the families apart itself; its profile, 0.1 px bins across the whole window, costs ten a level edge's).
  std::vector<bool> read_few = read;
  for (const size_t c : PhaseNeighbours(best)) read_few[c] = true;
  // Where the optics alone fits the choice best, a section at every phase keeps the blur fit's reading (ChoosePhaseFamily
  // skips it): only the optics alone is read on it, for the choice's totals (a board turned 5 deg, physical optics:
  // measuring 0.35 s before such sections were read, 2.7 s reading every family alike on them).
  std::vector<bool> read_every = read;
  if (best == 0) read_every.assign(nf, false), read_every[0] = true;
  std::vector<size_t> rest;
  for (const size_t k : limited)
    if (!first[k]) rest.push_back(k);
  each(rest.size(), [&](size_t i) {
    PhaseCheck& check = usable[rest[i]]->phase;
    ReadFamilies(profiles[rest[i]], check.limited ? read_few : read_every, &check);
  });
  fit_between(chosen);
  read_wide(read_every);
}

namespace {

// Where the family sharpens (taps' variance V < 0) the reading is the optics' second moment less the mask's:
// r^2 = r1^2 - 4|V|. Where the mask cancels most of r1^2, an error of kOpticsRel in the optics' own reading moves r by
// r1^2 / r^2 times as much, relatively: that is how far (px) this section's reading could move for it. 0 for a
// family that does not sharpen (r >= r1: no amplification).
double CancellationPx(double r, double taps_variance) {
  if (!(taps_variance < 0)) return 0;
  const double r1_sq = r * r - 4 * taps_variance;
  return kOpticsRel * r1_sq / std::max(r, kOpticsFloorPx);
}

// A family whose optics read 0 (a Gaussian's reading is then sqrt(4 V), the taps' own spread; a mask's 0): it reads
// no lower, so it brackets nothing. Where the optics alone is chosen (physical optics) such a neighbour is not
// counted: it flagged correct sections, the optics alone at 0.41 px for a true 0.42 px between a 0.35 px Gaussian
// stuck at 0.36 px and a mask that cancelled everything (disc x 0.2 px floor: 5-12 of 77 on four scenes). Where a
// filter is chosen it still counts: on a JPEG over a 0.5 px Gaussian the one jump it shows (edge 7, 0.93 px for
// 1.06 px) is a true error that nothing else flags, and a 0.6 px Gaussian at its own floor keeps 6 correct sections
// flagged (docs/independent-truth.md).
bool AtOwnFloor(const PhaseFamily& family, double r_px) {
  return r_px <= std::sqrt(std::max(0.0, 4 * TapsVariance(FamilyTaps(family)))) + 1e-3;
}

// Sections of 2 px or more read with the families (ReadPhaseFamilies, where a filter fitted best): the chosen one's
// (`best` of `nf`) reading, unflagged (the families that fit alike read them within 2-5 %) unless the table's slope
// moves it (TableWhy; counted in `tabled`). Returns how many took it.
int TakeWideReadings(CalibResult& result, size_t best, size_t nf, int* tabled) {
  int wide = 0;
  for (auto& edge : result.edges)
    for (auto& s : edge.sections) {
      if (!(s.fit.ok && s.phase.wide && s.phase.families.size() == nf && std::isfinite(s.phase.families[best].r_px)))
        continue;
      const double r = s.fit.r_px = s.phase.families[best].r_px, r_table = s.phase.families[best].r_table_px;
      ++wide;
      if (!(std::abs(r_table - r) > std::max(kSpreadPx, kSpreadRel * r))) continue;  // NaN: not on the outer edge
      s.fit.ok = false;
      s.fit.flags.push_back("phase_limited");
      s.fit.phase_why = TableWhy(r, r_table);
      s.phase.range_lo_px = std::min(r, r_table), s.phase.range_hi_px = std::max(r, r_table);
      ++*tabled;
    }
  return wide;
}

// ChoosePhaseFamily's choice over the `limited` sections (`points` profile points in all): every family's chi-square,
// which fit alike, and the one chosen (choice.chi2, alike, chosen, chi2_per_point); returns the chosen.
size_t ChooseOverSections(const std::vector<SectionResult*>& limited, int points, PhaseChoice& choice) {
  const std::vector<PhaseFamily>& families = choice.families;
  // A filter on the sampled image is the whole photo's: each family's chi-square over every limited section. One
  // section's few phases leave the families alike; the edges' different phases tell them apart.
  // Each section weighed by its own misfit (MisfitScale); the raw sum is kept for the chosen family's chi-square per
  // point.
  std::vector<double> raw(families.size(), 0.0);
  std::vector<const PhaseCheck*> checks;
  for (const SectionResult* s : limited) {
    checks.push_back(&s->phase);
    for (size_t c = 0; c < families.size(); ++c) raw[c] += s->phase.families[c].chi2;
  }
  const WeighedChi2 totals = WeighedTotals(checks, families.size());
  choice.chi2 = totals.chi2;
  const std::vector<double>& any = totals.any;
  const size_t least = totals.best;
  const int dof = std::max(1, points - 3 * int(limited.size()) - 1);
  const double scale = std::max(1.0, choice.chi2[least] / dof);
  // Beyond the noise, a model error grows every family's chi-square with the points: then families within kAlikeRel
  // of the best's excess over its degrees of freedom fit alike too, that excess with every section in its own units
  // (WeighedTotals's first weighing: the misfit no section's own scale takes up). 15 % of the whole took a mask 4 %
  // worse alike on a board turned 3 deg (130-point profiles) and flagged 48 correct sections; of the second weighing's
  // excess, 3 of 22 families alike flagged 36 and left the model p90 at 31 %.
  const double excess = std::max(0.0, *std::min_element(any.begin(), any.end()) - dof);
  for (size_t c = 0; c < families.size(); ++c)
    choice.alike[c] = choice.chi2[c] - choice.chi2[least] <= std::max(kAlikeChi2 * scale, kAlikeRel * excess);
  // A filter fitted between the families is taken only where it fits better than every family beyond the noise: one
  // that only fits the noise (a Gaussian of 0.34 px on physical optics under a JPEG) leaves the family it came from,
  // or the optics alone, as the reading; the fitted one's readings still count in the alike spread.
  size_t best = least;
  if (families[least].fitted)
    for (size_t c = 0; c < families.size(); ++c)
      if (!families[c].fitted && choice.alike[c] && (families[best].fitted || choice.chi2[c] < choice.chi2[best])) best = c;
  choice.chosen = best;
  choice.chi2_per_point = raw[best] / dof;
  return best;
}

}  // namespace

PhaseChoice ChoosePhaseFamily(CalibResult& result) {
  PhaseChoice choice;
  const std::vector<PhaseFamily> families = result.phase.families.empty() ? PhaseFamilies() : result.phase.families;
  choice.families = families;
  choice.choice_sections = result.phase.choice_sections, choice.has_valley = result.phase.has_valley;
  choice.wide = result.phase.wide;
  std::copy(std::begin(result.phase.valley), std::end(result.phase.valley), choice.valley);
  std::vector<SectionResult*> limited;
  int points = 0;
  for (auto& edge : result.edges)
    for (auto& s : edge.sections)
      if (s.fit.ok && (s.phase.limited || s.phase.every_phase) && s.phase.families.size() == families.size()) {
        limited.push_back(&s);
        points += s.phase.bins;
        choice.limited += s.phase.limited;
        choice.every_phase += s.phase.every_phase;
      }
  choice.chi2.assign(families.size(), 0.0);
  choice.alike.assign(families.size(), false);
  if (limited.empty()) {
    choice.summary = "no usable section has blur under 2 px";
    if (!choice.wide.sharpening.empty()) {  // kept where it moves the readings little (calib_checks.h)
      char moved[96];
      std::snprintf(moved, sizeof moved, ", moving their readings by %.1f %% (median)", 100 * choice.wide.moved_rel);
      choice.summary += "; " + choice.wide.sharpening + " fits " + std::to_string(choice.wide.sections) +
                        " of the wider sections better than the optics alone" + moved;
    }
    return choice;
  }
  const size_t best = ChooseOverSections(limited, points, choice);
  const double v_best = TapsVariance(FamilyTaps(families[best]));
  choice.variance_px2 = v_best;
  int cancelled = 0, jumped = 0, unsure = 0, tabled = 0, noisy = 0, apart = 0, valleyed = 0;
  // A filter fitted between the families has no neighbours along one axis that bracket its reading.
  const std::vector<size_t> neighbours = best < PhaseFamilies().size() ? PhaseNeighbours(best) : std::vector<size_t>{};
  for (SectionResult* s : limited) {
    // A section at every phase is identified by its own profile: only the filter's reading (and its rules) reach it.
    if (s->phase.every_phase && best == 0) continue;
    double lo = 1e18, hi = -1e18;
    for (size_t c = 0; c < families.size(); ++c)
      if (choice.alike[c]) lo = std::min(lo, s->phase.families[c].r_px), hi = std::max(hi, s->phase.families[c].r_px);
    // The refined mask's valley ends (PhaseChoice::valley) fit the deciding sections alike too: a section at few
    // phases whose reading moves by more than the target between them is not identified (mask 0.35 over 0.9 px,
    // focus 450 mm, seeds 33 and 36: 3 sections on edge 3 read 10-13 % low, the ends 0.55-0.68 px about 0.63 px).
    // One at every phase pins the optics' shape with its own profile: on 40 boards turned 20-60 deg none was off
    // the rule without this, and it would have flagged 911 of them.
    double v_lo = lo, v_hi = hi;
    for (const double v : s->phase.valley_r_px)
      if (choice.has_valley && s->phase.limited && std::isfinite(v)) v_lo = std::min(v_lo, v), v_hi = std::max(v_hi, v);
    const double r = s->phase.families[best].r_px, moved = CancellationPx(r, v_best);
    // On the board's outer edge (where a filter is chosen): how far the table's slope moves the reading.
    const double r_table = s->phase.families[best].r_table_px;
    const double table = best != 0 && std::isfinite(r_table) ? std::abs(r_table - r) : 0;
    if (best != 0) s->fit.r_px = r;  // read with the chosen family
    // The chosen family's neighbours on either side (read on every section) bracket its reading where the reading
    // follows the filter's parameter smoothly; one that lies outside their readings by more than the target is the
    // fit following something in the profile that no family explains. (With one neighbour, nothing brackets it.)
    double n_lo = 1e18, n_hi = -1e18;
    int n_read = 0, n_blur = 0;
    for (const size_t c : neighbours)
      if (const double v = s->phase.families[c].r_px; std::isfinite(v) && !(best == 0 && AtOwnFloor(families[c], v)))
        n_lo = std::min(n_lo, v), n_hi = std::max(n_hi, v), ++n_read, n_blur += !(families[c].sharpen > 0);
    // The optics alone lies between the Gaussians and the masks: only one of each brackets it (two masks of other
    // stds, both on the sharpening side, flagged 6 correct sections of a physical disc x 0.2 px floor scene).
    const bool brackets = best == 0 ? n_blur >= 1 && n_read - n_blur >= 1 : n_read >= 2;
    const double jump = brackets ? std::max({0.0, n_lo - r, r - n_hi}) : 0;
    const double nearest = r < n_lo ? n_lo : n_hi;
    s->phase.range_lo_px = std::max(0.0, std::min({v_lo, r - moved, r - jump}));
    s->phase.range_hi_px = std::max({v_hi, r + moved, r + jump});
    const double target = std::max(kSpreadPx, kSpreadRel * r);
    const bool along = v_hi - v_lo > target && hi - lo <= target;  // apart along the valley alone
    if (table > target) {
      s->phase.range_lo_px = std::min(s->phase.range_lo_px, r_table);
      s->phase.range_hi_px = std::max(s->phase.range_hi_px, r_table);
    }
    if (hi - lo <= target && !along && moved <= target && jump <= target && table <= target) {
      if (best == 0 && FlagUnsureAtItsPhase(s)) ++choice.flagged, ++unsure;
      if (best != 0 && FlagNoisyAtEveryPhase(s, best, target)) ++choice.flagged, ++noisy;
      continue;
    }
    s->fit.ok = false;
    s->fit.flags.push_back("phase_limited");
    s->phase.joins_fit = hi - lo <= target && jump <= target && table <= target;  // the cancellation or valley alone
    HoldAsBound(s, r, v_best);
    s->fit.phase_why = table > target                                  ? TableWhy(r, r_table)
                       : along && moved <= target && jump <= target ? ValleyWhy(r, v_lo, v_hi)
                                                                    : PhaseWhy(*s, lo, hi, r, v_best, moved, nearest);
    ++choice.flagged;
    tabled += table > target;
    cancelled += hi - lo <= target && moved > target && table <= target;
    valleyed += along && moved <= target && jump <= target && table <= target;
    jumped += hi - lo <= target && moved <= target && jump > target && table <= target;
    apart += hi - lo > target && table <= target;
  }
  int wide_flagged = 0;
  const int wide = best != 0 ? TakeWideReadings(result, best, families.size(), &wide_flagged) : 0;
  tabled += wide_flagged, choice.flagged += wide_flagged;
  // Only where a filter after sampling was chosen: under the optics alone (physical optics) the blur fit's reading is
  // the one the physical scenes hold to median 2 %, p90 5 %, and a section 9 % high on a Gaussian x 0.2 px floor scene
  // would be flagged for noise the targets allow.
  const int off_edge = best != 0 ? FlagOffTheirEdge(result) : 0;
  choice.flagged += off_edge;
  choice.summary = ChoiceSummary(choice, best, {cancelled, jumped, off_edge, unsure, tabled, noisy, apart, valleyed}, wide);
  return choice;
}

}  // namespace blurcue::calib
