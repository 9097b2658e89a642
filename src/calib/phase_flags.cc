#include "calib/phase_flags.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "calib/family_esf.h"
#include "calib/phase_check.h"
#include "core/error.h"

#include <opencv2/core.hpp>

namespace blurcue::calib {
namespace {

// A section read with the optics alone whose standard error (ModelFit::r_se_px) exceeds this share of its reading is
// flagged (FlagUnsureAtItsPhase): at 2 % the measured p90 of 15 floor-0.2 scenes fell from 4.5-11.4 % to 2.8-5.3 %.
constexpr double kMaxRelSe = 0.02;
// A section off the line through its edge's others by more than this is flagged (FlagOffTheirEdge): the spread above
// (0.03 px, 6 % flagged a correct section of a physical disc x 0.2 px floor scene, 0.035 px off its edge's line).
constexpr double kEdgeLinePx = 0.04, kEdgeLineRel = 0.08;

// Where the chosen family sharpens (taps' variance v < 0), a section reads r = sqrt(r_optics^2 + 4 v) (on a turned
// edge too: the taps along the other axis are in the family's optics reading): the optics' reading, in ideal px.
double OpticsPx(double r_photo_px, double stretch, double v) {
  return std::sqrt(std::max(0.0, r_photo_px * r_photo_px - 4 * v)) / stretch;
}

// The model of the optics (fitted to OpticsPx) as a model of the photo's blur, r^2 = D^2 a^2 + floor^2 + 4 v: the same
// focus and aperture, the floor and its range through the filter (4 v is in photo px: exact without distortion, as
// the floor of a model fitted to r itself was). Where the filter cancels more than the optics' floor near focus the
// photo's floor is 0 and not determined.
optics::FittedModel WithFilter(optics::FittedModel m, double v) {
  auto through = [v](double x) { return std::isfinite(x) ? std::sqrt(std::max(0.0, x * x + 4 * v)) : x; };
  const bool cancelled = m.floor_px * m.floor_px + 4 * v <= 0;
  // Beyond the floor the sharpening cancels the thin lens's blur too (a mask of 0.7 over 0.8 px, 1.34 px of it, over a
  // lens with no floor: taken from the floor alone, the model drew the optics' blur, 1.57 px for a true 0.82 px).
  m.cancel_px2 = cancelled ? m.floor_px * m.floor_px + 4 * v : 0;
  m.floor_px = through(m.floor_px);
  m.floor_candidate_px = through(m.floor_candidate_px);
  m.floor_lo_px = through(m.floor_lo_px), m.floor_hi_px = through(m.floor_hi_px);
  m.floor_determined = m.kind == "thin_lens+floor" && !cancelled &&
                       optics::FloorRangePinned(m.floor_lo_px, m.floor_hi_px, m.floor_px);
  return m;
}

}  // namespace

// Under a pixel with the optics alone an edge near a pixel centre leaves its blur to the next pixels' tails: the
// families agree, yet the reading scatters with the noise (floor std 0.2 px, noise 0.0025: edges 7-8 of 16 scenes read
// 10-20 % off, their standard errors 3-30 % where the other edges' were 0.5-2 %). Such a section is flagged; it joins
// the lens fit at its reading, as a cancelled one does (the fit pools them), and the model predicts it.
bool FlagUnsureAtItsPhase(SectionResult* s) {
  const double r = s->fit.r_px;
  if (!s->phase.limited || !(s->fit.r_se_px > kMaxRelSe * r)) return false;  // few phases only
  char why[400];
  if (std::isfinite(s->fit.r_se_px))
    std::snprintf(why, sizeof why,
                  "with blur under a pixel (%.2f px) and its edge %.2f px past a pixel centre, the profile pins its "
                  "blur to +-%.0f %% only (standard error; near a pixel centre only the next pixels see the blur), more "
                  "than %.0f %%; it joins the lens fit, which pools such sections, and is predicted by it",
                  r, s->phase.phase_px, 100 * s->fit.r_se_px / r, 100 * kMaxRelSe);
  else
    std::snprintf(why, sizeof why,
                  "its reading (%.2f px, edge %.2f px past a pixel centre) is not determined by the profile: near 0 "
                  "its samples barely change with the blur (no standard error bounds it); it joins the lens fit, "
                  "which pools such sections, and is predicted by it",
                  r, s->phase.phase_px);
  s->fit.ok = false;
  s->fit.flags.push_back("phase_limited");
  s->fit.phase_why = why;
  // It joins the fit at its reading: near 0 the profile bounds the blur from above only (a sharp step), which the
  // pooled fit uses (left out, the tests' scene focused on edge 1 had its model read 0.33 px there for a true 0, not
  // 0.21 px). Its range: +-2 standard errors, or where none bounds it the families' range (ChoosePhaseFamily's).
  s->phase.joins_fit = true;
  if (std::isfinite(s->fit.r_se_px))
    s->phase.range_lo_px = std::max(0.0, r - 2 * s->fit.r_se_px), s->phase.range_hi_px = r + 2 * s->fit.r_se_px;
  return true;
}

// Blur changes smoothly along an edge (with its depth): an unflagged limited section whose reading lies more than
// max(kEdgeLinePx, kEdgeLineRel) off the line (r against depth) through its edge's other unflagged limited sections (4 or
// more) is flagged. Where an edge lies within about 0.1 px of a pixel centre its profile is a handful of samples and
// the noise trades the optics' shape against its width section by section: under a Gaussian of 0.35 px on the sampled
// image, edge 7's seven sections of one true blur (0.62 px) read 0.58-0.70 px under the family that fits, the
// reading's spread among families 0.03 px (the bench's section off the rule unflagged, +12.5 %). Returns how many.
int FlagOffTheirEdge(CalibResult& result) {
  int flagged = 0;
  for (auto& edge : result.edges) {
    std::vector<SectionResult*> sections;
    for (auto& s : edge.sections)
      if (s.fit.ok && s.phase.limited) sections.push_back(&s);
    if (sections.size() < 5) continue;
    std::vector<std::pair<SectionResult*, double>> off;
    for (SectionResult* s : sections) {
      double n = 0, su = 0, sr = 0, suu = 0, sur = 0;
      for (const SectionResult* o : sections)
        if (o != s) n += 1, su += o->u_mm, sr += o->fit.r_px, suu += o->u_mm * o->u_mm, sur += o->u_mm * o->fit.r_px;
      const double var_u = suu / n - (su / n) * (su / n);
      const double slope = var_u > 1e-6 ? (sur / n - su / n * sr / n) / var_u : 0;  // 1e-6 mm^2: a level edge
      const double line = sr / n + slope * (s->u_mm - su / n);
      if (std::abs(s->fit.r_px - line) > std::max(kEdgeLinePx, kEdgeLineRel * s->fit.r_px)) off.emplace_back(s, line);
    }
    for (auto& [s, line] : off) {  // after every section was held to the others as read
      char why[360];
      std::snprintf(why, sizeof why,
                    "its reading (%.2f px) lies %.2f px off the line through its edge's other %zu sections sampled at "
                    "the same few phases (%.2f px here), more than max(%.2f px, %.0f %%): the profile's few samples let "
                    "the noise trade the optics' shape against its width; the lens fit predicts it",
                    s->fit.r_px, std::abs(s->fit.r_px - line), sections.size() - 1, line, kEdgeLinePx,
                    100 * kEdgeLineRel);
      s->fit.ok = false;
      s->fit.flags.push_back("phase_limited");
      s->fit.phase_why = why;
      s->phase.range_lo_px = std::min({s->phase.range_lo_px, s->fit.r_px, line});
      s->phase.range_hi_px = std::max({s->phase.range_hi_px, s->fit.r_px, line});
      ++flagged;
    }
  }
  return flagged;
}

// Where the chosen family sharpens, the model is fitted to the optics' readings (OpticsPx) and the filter added back
// (WithFilter): near focus a mask of amount 0.7 over 0.6 px left 0.12-0.2 px of a 1.0 px optical blur, where an error
// e in the optics' reading moves the reading by r_optics / r x e (5-8 x). Fitted to r itself, as every other photo's,
// the sections there counted as surely as the optics' own, the model read the floor from them and missed p90 5 % on
// 4 of 6 seeds (4.0-13.8 %); in the optics' terms the floor is the lens's (1.0 px) and the sections weigh as they read.
optics::FittedModel FitModelWithinPhaseRanges(const CalibResult& result, const optics::Lens& lens,
                                              const optics::FitOptions& options, int* held,
                                              optics::FittedModel* optics_model) {
  const double v = std::min(0.0, result.phase.variance_px2);
  const std::vector<optics::BlurSample> usable = ModelSamples(result, v);  // the optics' readings (OpticsPx)
  std::vector<const SectionResult*> limited;
  for (const auto& edge : result.edges)
    for (const auto& s : edge.sections)
      if (!s.fit.phase_why.empty() && !s.phase.joins_fit && s.phase.range_hi_px > 0) limited.push_back(&s);
  optics::FittedModel model = optics::FitThinLens(lens, usable, options);
  std::vector<double> bound(limited.size(), -1);  // where a section holds the model (-1: nowhere)
  for (int round = 0; round < 5 && !limited.empty(); ++round) {
    bool moved = false;
    for (size_t i = 0; i < limited.size(); ++i) {
      const SectionResult& s = *limited[i];
      const double optics = model.PredictPx(lens, s.u_mm) * s.stretch;
      const double predicted = std::sqrt(std::max(0.0, optics * optics + 4 * v));
      // Once held, a section stays held (the refit moves the model into its range), at the range's middle: the value
      // that commits least to any one of the families that fit alike (its nearer end biased the model towards the
      // unflagged sections' side: 0.75 px predicted for a true 0.86 px on a JPEG scene focused on edge 1).
      const bool outside = predicted < s.phase.range_lo_px || predicted > s.phase.range_hi_px;
      const double end = bound[i] >= 0 ? bound[i] : outside ? 0.5 * (s.phase.range_lo_px + s.phase.range_hi_px) : -1.0;
      if (end != bound[i]) bound[i] = end, moved = true;
    }
    if (!moved) break;
    std::vector<optics::BlurSample> samples = usable;
    for (size_t i = 0; i < limited.size(); ++i)
      if (bound[i] >= 0) samples.push_back({limited[i]->u_mm, OpticsPx(bound[i], limited[i]->stretch, v), 1.0});
    model = optics::FitThinLens(lens, samples, options);
  }
  if (held) *held = static_cast<int>(std::count_if(bound.begin(), bound.end(), [](double b) { return b >= 0; }));
  if (optics_model) *optics_model = model;
  return v < 0 ? WithFilter(model, v) : model;
}

namespace {

// Beyond this relative error the model's blur at a depth is "not determined within 5 %".
constexpr double kModelSeRel = 0.05;
// The readings' own systematic error in the optics' blur (one standard error), which their scatter about the model
// does not show: per edge +-0.5-0.7 % over 8 seeds (mask 0.7 over 0.6 px, noise 0.0025; noise-free -1.8 to +0.8 %),
// alike on an edge's sections and on neighbouring edges. Without it |error| / standard error had median 0.71-1.46,
// p90 2.7-2.9 (masks 0.7 over 0.6, 0.3 over 0.8, 0.25 over 0.9 px; seeds 1-6, tests/undetermined_coverage.py): far
// from focus the model erred 1-3 % with a standard error of 0.3-0.9 %. With 0.4 % there, p90 1.4-1.7 and 0-4.5 % of the
// sections beyond 2 (a normal's 1.64 and 4.6 %); 0.7 % overstated it (p90 0.9-1.2). Those with the plain sandwich;
// with CR3 (PropagateModelError) held out, seeds 27-36: masks p90 0.82-0.88, none beyond 2; no filter 1.35, 0 %;
// a Gaussian after sampling 1.67, 1.8 % (docs/independent-truth.md).
constexpr double kReadingRel = 0.004;
// Where most of an edge's sections in the fit or held by their bound (PhaseCheck::bound), kCancelledMin or more, read
// under kCancelledPx, the board has depths where the mask cancels the whole blur (one alone is the noise:
// mask 0.7 over 0.6 px, seed 2, the only one of edge 5's sections in the fit read 0 for a true 0.16 px, its neighbours
// 0.15-0.17 px; where the whole blur cancels, 4 edges' 28 sections read 0).
constexpr int kCancelledMin = 3;
// There the model rests on the other edges alone, those bounds holding it through their ranges (PhaseCheck::bound):
// the readings' own error is taken at kCancelledRel in place of kReadingRel, magnified by r_optics^2 / r^2. Fitted
// through the bounds as values it erred by 1-4 % in the optics' blur at every other depth (mask 0.35 over 0.9 px, focus
// 450 mm, seeds 1-6: +8.9 % at 0.72 px, +18 % at 0.48 px) and took 3 %, which named the whole board. As bounds, on
// seeds 1-6 (masks 0.35 over 0.9 px focus 450 mm, 0.5 over 0.8 px): 0.4 % named 396-508 and 377-500 mm with the
// model's p90 4.9 % and 3.6 % outside (|error| / standard error p90 1.84, 1.64); 1 % names 389-527 and 369-515 mm,
// p90 2.5 % and 3.3 % outside (p90 0.83, 0.79), none missing 5 %: 1 % keeps a margin.
constexpr double kCancelledRel = 0.01;

// d PredictPx(u) / d (focus, aperture[, floor]) by central differences; the floor where the model has one.
std::vector<double> ModelGradient(const optics::FittedModel& m, const optics::Lens& lens, double u_mm) {
  std::vector<double> g;
  auto diff = [&](double optics::FittedModel::*p, double h) {
    optics::FittedModel a = m, b = m;
    a.*p += h, b.*p -= h;
    g.push_back((a.PredictPx(lens, u_mm) - b.PredictPx(lens, u_mm)) / (2 * h));
  };
  // The focus's step a fraction of its distance beyond f: a fit that puts the focus just beyond f (a scene of 20 px
  // blur, bench measure's blur level) would step past it, where a thin lens forms no image.
  diff(&optics::FittedModel::focus_mm, 1e-5 * (m.focus_mm - lens.focal_length_mm));
  diff(&optics::FittedModel::aperture_mm, 1e-5 * m.aperture_mm);
  if (m.kind == "thin_lens+floor" && m.floor_px > 0) diff(&optics::FittedModel::floor_px, 1e-5 * m.floor_px);
  return g;
}

// The sentence that names the depths where the model is not determined (ModelUndetermined::why), and its cause: a mask
// that cancels the whole blur (`cancelled` sections read 0 px at cut_lo-cut_hi mm under v < 0), sections that read 0
// with no filter, or the error's parts (the mask's, or near focus the profiles' own).
std::string UndeterminedWhy(const ModelUndetermined& p, double v, int cancelled, double cut_lo, double cut_hi) {
  const std::string reach = "reaches " + p.Reach() + " there";
  char text[640];
  if (cancelled > 0 && v < 0)
    std::snprintf(text, sizeof text,
                  "the model's blur is not determined within %.0f %% at depths %.0f-%.0f mm: the sharpening after "
                  "sampling cancels the whole blur at %.0f-%.0f mm (%d sections read 0 px, a bound, not a value), and "
                  "a lens fitted beside them errs by a few %% in the optics' blur, which the sharpening magnifies "
                  "(its error %s); there r_fitted_px is the model's estimate, not a result within 5 %%",
                  100 * kModelSeRel, p.lo_mm, p.hi_mm, cut_lo, cut_hi, cancelled, reach.c_str());
  else if (cancelled > 0)  // no filter: edges sharp beyond what a profile shows (in focus, or no blur at all)
    std::snprintf(text, sizeof text,
                  "the model's blur is not determined within %.0f %% at depths %.0f-%.0f mm: %d sections at "
                  "%.0f-%.0f mm read 0 px, sharper than their profiles can tell apart, and the model's error %s; "
                  "there r_fitted_px is the model's estimate, not a result within 5 %%",
                  100 * kModelSeRel, p.lo_mm, p.hi_mm, cancelled, cut_lo, cut_hi, reach.c_str());
  else  // the error's parts and its cause: the mask's, or near focus the profiles' own
    std::snprintf(text, sizeof text,
                  "the model's blur is not determined within %.0f %% at depths %.0f-%.0f mm: its error (standard "
                  "error, the readings' own %.1f %%%s) %s (%s); there r_fitted_px is the model's estimate, not a result "
                  "within 5 %%",
                  100 * kModelSeRel, p.lo_mm, p.hi_mm, 100 * kReadingRel,
                  v < 0 ? " in the optics' blur and the masks that fit alike" : "", reach.c_str(),
                  v < 0 ? "the sharpening after sampling cancels most of the optics' blur, magnifying the optics' own "
                          "uncertainty"
                        : "near focus the blur is small and its profiles pin it least: a sharp step reads alike from 0 "
                          "to about 0.3 px");
  return text;
}

}  // namespace

// The covariance of the optics model's parameters from its readings' scatter about it, each edge's sections one sample
// (a cluster-robust sandwich: the sections of an edge share its depth and sub-pixel phase, and a noise-free scene's
// readings err alike along an edge, by up to 0.5 % of the optics' blur), the readings' own error added (kReadingRel,
// or kCancelledRel where the filter cancels the whole blur on an edge), then through r = sqrt(r_optics^2 + 4 v).
std::vector<ValleyModel> ValleyModels(const CalibResult& result, const optics::Lens& lens,
                                      const optics::FitOptions& options) {
  std::vector<ValleyModel> out;
  const PhaseChoice& p = result.phase;
  // Only where the mask refined between the families is the one chosen: the ends lie either side of it.
  if (!p.has_valley || p.families.empty() || p.chosen + 1 != p.families.size()) return out;
  for (int e = 0; e < 2; ++e) {
    CalibResult alt = result;
    alt.phase.variance_px2 = detail::TapsVariance(detail::FamilyTaps(p.valley[e]));
    for (auto& edge : alt.edges)
      for (auto& s : edge.sections)
        if (std::isfinite(s.phase.valley_r_px[e])) s.fit.r_px = s.phase.valley_r_px[e];
    ValleyModel v{{}, alt.phase.variance_px2};
    try {
      FitModelWithinPhaseRanges(alt, lens, options, nullptr, &v.optics);
    } catch (const Error&) {
      continue;  // too few sections under that mask: no term from it
    }
    out.push_back(v);
  }
  return out;
}

void PropagateModelError(CalibResult& result, const optics::Lens& lens, const optics::FittedModel& m,
                         const std::vector<ValleyModel>& valley) {
  const double v = std::min(0.0, result.phase.variance_px2);
  if (!std::isfinite(m.focus_mm) || !(m.aperture_mm > 0)) return;
  const int k = static_cast<int>(ModelGradient(m, lens, result.edges.at(0).sections.at(0).u_mm).size());
  cv::Mat_<double> a = cv::Mat_<double>::zeros(k, k), b = cv::Mat_<double>::zeros(k, k);
  // Each edge's gradients (a row per section in the fit) and residuals: the clusters of the sandwich below.
  std::vector<std::pair<cv::Mat_<double>, cv::Mat_<double>>> clusters;
  int cancelled = 0;  // sections read 0 on edges where most did
  double u_lo = 1e300, u_hi = -1e300, cut_lo = 1e300, cut_hi = -1e300;
  for (const auto& edge : result.edges) {
    cv::Mat_<double> jg(0, k), eg(0, 1);
    int in_fit = 0, zero = 0;
    double zero_lo = 1e300, zero_hi = -1e300;
    for (const auto& s : edge.sections) {
      u_lo = std::min(u_lo, s.u_mm), u_hi = std::max(u_hi, s.u_mm);
      if (!InModel(s) && !s.phase.bound) continue;
      ++in_fit;
      if (s.fit.r_px < kCancelledPx) ++zero, zero_lo = std::min(zero_lo, s.u_mm), zero_hi = std::max(zero_hi, s.u_mm);
      if (!InModel(s)) continue;  // a bound holds the model through its range, not in its scatter
      const cv::Mat_<double> j = cv::Mat_<double>(ModelGradient(m, lens, s.u_mm)).t();
      jg.push_back(j), eg.push_back(OpticsPx(s.fit.r_px, s.stretch, v) - m.PredictPx(lens, s.u_mm));
      a += j.t() * j;
    }
    if (!jg.empty()) clusters.emplace_back(jg, eg);
    if (zero >= kCancelledMin && 2 * zero > in_fit)
      cancelled += zero, cut_lo = std::min(cut_lo, zero_lo), cut_hi = std::max(cut_hi, zero_hi);
  }
  cv::Mat_<double> a_inv;
  if (static_cast<int>(clusters.size()) <= k || cv::invert(a, a_inv, cv::DECOMP_SVD) == 0) return;
  // CR3 (the jackknife's sandwich): each edge's residuals as they would be were the edge left out of the fit,
  // (I - H_gg)^-1 e_g. The plain sandwich's residuals are pulled toward an edge that leans on the fit (a far edge,
  // one of few beside focus), and with 11 edges it understated the error: |error| / standard error p90 1.95, 8.2 %
  // of the sections beyond 2 on a Gaussian of 0.45 px after sampling (seeds 27-36, tests/undetermined_coverage.py).
  for (const auto& [jg, eg] : clusters) {
    const cv::Mat_<double> h = cv::Mat_<double>::eye(jg.rows, jg.rows) - jg * a_inv * jg.t();
    cv::Mat_<double> left_out;
    if (!cv::solve(h, eg, left_out, cv::DECOMP_SVD)) return;
    const cv::Mat_<double> g = jg.t() * left_out;
    b += g * g.t();
  }
  const cv::Mat_<double> cov = a_inv * b * a_inv;
  const double floor_rel = cancelled > 0 ? kCancelledRel : kReadingRel;
  // The photo's blur at u and its error (photo px): the model's standard error and the readings' own (floor_rel of the
  // optics' blur) in quadrature.
  auto spread = [&](double u_mm, double stretch, double* r_px) {
    const double ideal = m.PredictPx(lens, u_mm), optics = ideal * stretch;
    *r_px = std::sqrt(std::max(0.0, optics * optics + 4 * v));
    const std::vector<double> j = ModelGradient(m, lens, u_mm);
    double var = (floor_rel * ideal) * (floor_rel * ideal);
    for (int r = 0; r < k; ++r)
      for (int c = 0; c < k; ++c) var += j[r] * cov(r, c) * j[c];
    // d r / d optics = optics / r, so r's relative error is r_optics^2 / r^2 times the optics' own; where the filter
    // cancels the whole blur, the error no longer is linear: r's own scale (the tests' 0.05 px) bounds it.
    const double se = optics * stretch / std::max(*r_px, 0.05) * std::sqrt(var);
    // The masks along the chosen one's valley that fit alike (ValleyModels): half the largest move of the blur under
    // them, as the ends lie about two standard errors out.
    double moved = 0;
    for (const ValleyModel& end : valley) {
      const double o = end.optics.PredictPx(lens, u_mm) * stretch;
      moved = std::max(moved, std::abs(std::sqrt(std::max(0.0, o * o + 4 * end.variance_px2)) - *r_px));
    }
    return std::hypot(se, moved / 2);
  };
  for (auto& edge : result.edges)
    for (auto& s : edge.sections) {
      double r;
      s.r_fitted_se_px = spread(s.u_mm, s.stretch, &r);
    }
  ModelUndetermined& p = result.undetermined;
  p = ModelUndetermined();
  bool found = false;
  for (int i = 0; i <= 200; ++i) {  // the board's depths, every 0.5 % of their span
    const double u = u_lo + (u_hi - u_lo) * i / 200.0;
    double r;
    const double rel = spread(u, 1.0, &r) / std::max(r, 0.05);
    p.worst_se_rel = std::max(p.worst_se_rel, rel);
    if (rel > kModelSeRel) {
      if (!found) p.lo_mm = u;
      p.hi_mm = u, found = true;
    }
  }
  if (!found) return;
  // An edge the depths reach is named whole: its sections lie within hundredths of a mm of each other, and a boundary
  // between them (the init example's edge 2: one of its seven inside) would leave the rest said determined.
  for (const auto& edge : result.edges) {
    double lo = 1e300, hi = -1e300;
    for (const auto& s : edge.sections) lo = std::min(lo, s.u_mm), hi = std::max(hi, s.u_mm);
    if (hi >= p.lo_mm && lo <= p.hi_mm) p.lo_mm = std::min(p.lo_mm, lo), p.hi_mm = std::max(p.hi_mm, hi);
  }
  p.why = UndeterminedWhy(p, v, cancelled, cut_lo, cut_hi);
}

bool HoldAsBound(SectionResult* s, double r, double v) {
  if (!(s->phase.joins_fit && v < 0 && r < kCancelledPx)) return false;
  s->phase.joins_fit = false, s->phase.bound = true;
  // 0 to the blur an error of kOpticsRel in the optics' second moment leaves.
  s->phase.range_lo_px = 0;
  s->phase.range_hi_px = std::sqrt(std::max(r * r, 2 * kOpticsRel * (r * r - 4 * v)));
  return true;
}

std::string TableWhy(double r, double r_table) {
  char why[400];
  std::snprintf(why, sizeof why,
                "on the board's outer edge the table beside it is not flat across the window (its texture): read with "
                "the table's slope taken, this section reads %.2f px against %.2f px, more than max(%.2f px, %.0f %%) "
                "apart; its blur is not identified; the lens fit predicts it",
                r_table, r, kSpreadPx, 100 * kSpreadRel);
  return why;
}

std::string PhaseWhy(const SectionResult& s, double lo, double hi, double r, double v, double moved, double nearest) {
  char why[480];
  const double target = std::max(kSpreadPx, kSpreadRel * r);
  if (hi - lo <= target && moved <= target)
    std::snprintf(why, sizeof why,
                  "its reading under the chosen PSF family (%.2f px) lies %.2f px outside the neighbouring families' "
                  "(from %.2f px), more than max(%.2f px, %.0f %%): the fit follows something in this profile "
                  "that no family explains (a JPEG block, a flaw); the lens fit predicts it",
                  r, std::abs(nearest - r), nearest, kSpreadPx, 100 * kSpreadRel);
  else if (hi - lo > target && s.phase.every_phase)
    std::snprintf(why, sizeof why,
                  "the PSF families that fit the board's profiles alike read %.2f-%.2f px here (edge sampled at every "
                  "phase): its blur is not identified; the lens fit predicts it",
                  lo, hi);
  else if (hi - lo > target)
    std::snprintf(why, sizeof why,
                  "the edge runs %.1f deg off the pixel axis, so its sub-pixel phase moves only %.2f px along the part "
                  "measured (edge %.2f px past a pixel centre), and the PSF families that fit the board's profiles "
                  "alike read %.2f-%.2f px here: its blur is not identified; the lens fit predicts it",
                  s.phase.axis_deg, s.phase.span_px, s.phase.phase_px, lo, hi);
  else if (s.phase.bound)
    std::snprintf(why, sizeof why,
                  "the photo was sharpened after sampling and here the mask cancels the optics' whole blur (read "
                  "%.2f px: the optics' blur is at most the mask's %.2f px, a bound, not a value); it is left out of the "
                  "lens fit, which predicts it, held within %.2f-%.2f px",
                  r, std::sqrt(-4 * v), s.phase.range_lo_px, s.phase.range_hi_px);
  else
    std::snprintf(why, sizeof why,
                  "the photo was sharpened after sampling and here the mask cancels %.0f %% of the optics' blur "
                  "(optics %.2f px, read %.2f px): a %.0f %% error in the optics' reading moves this one by %.2f px, "
                  "more than max(%.2f px, %.0f %%); it joins the lens fit, which pools such sections, and is predicted "
                  "by it",
                  100 * std::min(1.0, -4 * v / (r * r - 4 * v)), std::sqrt(r * r - 4 * v), r, 100 * kOpticsRel, moved,
                  kSpreadPx, 100 * kSpreadRel);
  return why;
}

bool FlagNoisyAtEveryPhase(SectionResult* s, size_t best, double target) {
  if (!s->phase.every_phase || best >= s->phase.families.size()) return false;
  const PhaseReading& f = s->phase.families[best];
  const double r = f.r_px, se = f.r_se_px;
  if (!(kSeSpan * se > target)) return false;  // NaN: not taken (a reading of 0)
  char why[420];
  std::snprintf(why, sizeof why,
                "its profile pins its blur (%.2f px) to +-%.0f %% only (standard error, from the spread of its pixels "
                "about the profile%s): %.0f standard errors are more than max(%.2f px, %.0f %%); it joins the lens fit, "
                "which pools such sections, and is predicted by it",
                r, 100 * se / std::max(r, 1e-9),
                std::isfinite(f.r_table_px) ? ", which on the board's outer edge takes in the table's texture" : "",
                kSeSpan, kSpreadPx, 100 * kSpreadRel);
  s->fit.ok = false;
  s->fit.flags.push_back("phase_limited");
  s->fit.phase_why = why;
  s->phase.joins_fit = true;
  s->phase.range_lo_px = std::min(s->phase.range_lo_px, std::max(0.0, r - kSeSpan * se));
  s->phase.range_hi_px = std::max(s->phase.range_hi_px, r + kSeSpan * se);
  return true;
}

int FlagOffTheLensFit(CalibResult& result) {
  if (result.phase.chosen == 0 || result.edges.empty()) return 0;
  int flagged = 0;
  const size_t last = result.edges.size() - 1;
  for (size_t e : {size_t(0), last}) {
    for (auto& s : result.edges[e].sections) {
      if (!s.fit.ok) continue;
      const double r = s.fit.r_px, m = s.r_fitted_px, se = std::max(0.0, s.r_fitted_se_px);
      const double target = std::max(kSpreadPx, kSpreadRel * r);
      if (!(std::abs(r - m) > target - se)) continue;
      char why[420];
      std::snprintf(why, sizeof why,
                    "on the board's outer edge, beside the table, its reading (%.2f px) lies %.2f px off the lens "
                    "fit's %.2f px (standard error %.2f px): more than max(%.2f px, %.0f %%) less that error; the "
                    "table's texture moves such a reading more than its own standard error says. It joins the lens "
                    "fit at its reading, which pools it, and is predicted by it",
                    r, std::abs(r - m), m, se, kSpreadPx, 100 * kSpreadRel);
      s.fit.ok = false;
      s.fit.flags.push_back("phase_limited");
      s.fit.phase_why = why;
      s.phase.joins_fit = true;
      const bool ranged = s.phase.range_hi_px > 0;  // a range the families that fit alike gave it
      s.phase.range_lo_px = ranged ? std::min({s.phase.range_lo_px, r, m}) : std::min(r, m);
      s.phase.range_hi_px = std::max({s.phase.range_hi_px, r, m});
      ++flagged;
    }
    if (last == 0) break;
  }
  if (flagged > 0) {
    result.phase.flagged += flagged;
    result.phase.summary += "; after the lens fit " + std::to_string(flagged) +
                            " more on the board's outer edge (beside the table) off its prediction by more than "
                            "max(0.04 px, 8 %) less its standard error";
  }
  return flagged;
}

std::string ChoiceSummary(const PhaseChoice& choice, size_t best, const std::array<int, 8>& flags, int wide) {
  const std::vector<PhaseFamily>& families = choice.families;
  int n_alike = 0, n_read = 0;
  for (const bool a : choice.alike) n_alike += a;
  for (const double c : choice.chi2) n_read += std::isfinite(c);
  char text[1300], ruled[120] = "";
  if (n_read < int(families.size()))
    std::snprintf(ruled, sizeof ruled, "; %zu ruled out on %zu sections at spread phases and not read on the rest",
                  families.size() - n_read, choice.choice_sections);
  std::snprintf(text, sizeof text,
                "%d sections with blur under %.0f px along the pixel rows or columns (and %d at every phase) read under "
                "%zu kinds of blur (the lens alone, or then a smoothing or sharpening of the pixels): the photo fits "
                "best as %s (%d of the kinds fit alike, chi-square per point %.2f, 1 where only the noise is left%s); %d "
                "flagged phase_limited (%d where the kinds that fit alike read apart, %d where masks along the chosen one's "
                "valley (one second moment, fitting alike) read apart, %d where the sharpening cancels "
                "most of the lens's blur, %d jumping between "
                "neighbouring kinds, %d off the line through their edge's other sections, %d too unsure near a pixel "
                "centre, %d on the board's outer edge moved by the table's slope, %d at every phase whose standard "
                "error leaves the target; each reading's range in calib.json); "
                "%d sections of %.0f px or more read with it too",
                choice.limited, kMaxBlurPx, choice.every_phase, families.size(), families[best].Name().c_str(), n_alike,
                choice.chi2_per_point, ruled, choice.flagged, flags[6], flags[7], flags[0], flags[1], flags[2], flags[3], flags[4],
                flags[5],
                wide,
                kMaxBlurPx);
  return text;
}

std::string ValleyWhy(double r, double lo, double hi) {
  char why[400];
  std::snprintf(why, sizeof why,
                "the mask fitted between the families is not pinned along its valley (masks of the same second moment "
                "and other stds fit the board's profiles alike) and those read %.2f-%.2f px here, more than max(%.2f "
                "px, %.0f %%) apart around %.2f px: it joins the lens fit at its reading (the valley's move is in the "
                "model's standard error)",
                lo, hi, kSpreadPx, 100 * kSpreadRel, r);
  return why;
}

}  // namespace blurcue::calib
