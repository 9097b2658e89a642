#include "optics/fit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "core/error.h"

namespace blurcue::optics {
namespace {

// Work in q = 1/u0 and p = 1/u ("diopters" per mm). The signed thin-lens radius is then
//   r = D f (q - p) / (2 pitch (1 - f q)),
// linear in D for a fixed q, and q runs over the bounded interval [0, 1/f) with q = 0 meaning focus at infinity,
// where a search over u0 itself would have to cover (f, infinity).
struct Data {
  std::vector<double> p, r, w;  // only samples with weight > 0
  double f = 0;
  double c0 = 0;     // f / (2 pitch)
  double q_max = 0;  // just below 1/f: focus a hair beyond the focal length
  size_t n() const { return p.size(); }
};

struct Params {
  double q = 0;  // 1 / focus
  double d = 0;  // aperture D, mm
  double t = 0;  // floor squared, px^2 (t, not r0: d model / d t = 1 / (2 m) does not vanish at t = 0)
};

// The share of the radius that depends on the sample: |r| = D * Shape.
double Shape(const Data& s, double q, size_t i) { return s.c0 * std::abs(q - s.p[i]) / (1 - s.f * q); }

double Model(const Data& s, const Params& m, bool floor, size_t i) {
  const double thin = m.d * Shape(s, m.q, i);
  return floor ? std::sqrt(thin * thin + m.t) : thin;
}

double Huber(double e, double c) {
  const double a = std::abs(e);
  return a <= c ? 0.5 * e * e : c * (a - 0.5 * c);
}

// IRLS weight of the Huber loss: 1 inside the threshold, c/|e| beyond (the residual then counts linearly).
double HuberWeight(double e, double c) {
  const double a = std::abs(e);
  return a <= c ? 1.0 : c / a;
}

double Loss(const Data& s, const std::vector<double>& w, const Params& m, bool floor, double c) {
  double sum = 0;
  for (size_t i = 0; i < s.n(); ++i)
    if (w[i] > 0) sum += w[i] * Huber(s.r[i] - Model(s, m, floor, i), c);
  return sum;
}

// Thin lens without floor at a fixed q: the model is D * a_i, linear in D, so D comes in closed form: weighted
// least squares to start, then Newton steps on the Huber estimating equation sum w a psi(r - D a) = 0. Huber's loss
// is piecewise quadratic, so Newton is exact once the set of samples inside the threshold stops changing; that
// takes a handful of steps where plain IRLS (the same fixed point) would crawl for dozens.
Params ProfileThin(const Data& s, const std::vector<double>& w, double q, double c, double* loss) {
  const double scale = s.c0 / (1 - s.f * q);
  double num = 0, den = 0;
  for (size_t i = 0; i < s.n(); ++i) {
    const double a = scale * std::abs(q - s.p[i]);
    num += w[i] * a * s.r[i];
    den += w[i] * a * a;
  }
  double d = den > 0 ? std::max(0.0, num / den) : 0.0;
  for (int it = 0; it < 30 && den > 0; ++it) {
    double psi = 0, curv = 0, irls_den = 0;
    for (size_t i = 0; i < s.n(); ++i) {
      const double a = scale * std::abs(q - s.p[i]);
      const double e = s.r[i] - d * a;
      if (std::abs(e) <= c) {
        psi += w[i] * a * e;
        curv += w[i] * a * a;
      } else {
        psi += w[i] * a * (e > 0 ? c : -c);
      }
      irls_den += w[i] * HuberWeight(e, c) * a * a;
    }
    // With every sample beyond the threshold the loss is piecewise linear; an IRLS step still moves the right way.
    const double step = psi / (curv > 0 ? curv : irls_den);
    const double next = std::max(0.0, d + step);
    const bool done = std::abs(next - d) <= 1e-12 * std::max(1.0, d);
    d = next;
    if (done) break;
  }
  *loss = 0;
  for (size_t i = 0; i < s.n(); ++i)
    if (w[i] > 0) *loss += w[i] * Huber(s.r[i] - d * scale * std::abs(q - s.p[i]), c);
  return {q, d, 0};
}

// Solves the k x k system a x = b (Gaussian elimination, partial pivoting). False when singular.
template <int K>
bool Solve(std::array<std::array<double, K>, K> a, std::array<double, K> b, std::array<double, K>* x) {
  for (int col = 0; col < K; ++col) {
    int piv = col;
    for (int r = col + 1; r < K; ++r)
      if (std::abs(a[r][col]) > std::abs(a[piv][col])) piv = r;
    if (!(std::abs(a[piv][col]) > 0)) return false;
    std::swap(a[piv], a[col]);
    std::swap(b[piv], b[col]);
    for (int r = col + 1; r < K; ++r) {
      const double m = a[r][col] / a[col][col];
      for (int k = col; k < K; ++k) a[r][k] -= m * a[col][k];
      b[r] -= m * b[col];
    }
  }
  for (int r = K - 1; r >= 0; --r) {
    double v = b[r];
    for (int k = r + 1; k < K; ++k) v -= a[r][k] * (*x)[k];
    (*x)[r] = v / a[r][r];
  }
  return true;
}

// Levenberg-Marquardt on the Huber loss (IRLS weights recomputed every step) over (q, D[, t]), q optionally held.
// Used for the floor model at a fixed q, to polish a searched optimum, and for the leave-one-out refits, which
// start at the full-data optimum and only have to follow it a short way.
// The floor model steps in D^2, not D, for the reason it uses t: d sqrt(D^2 a^2 + t) / d D = D a^2 / model vanishes
// at D = 0, so a step clamped to the bound D = 0 was a trap no later step left. The focus search warm-starts each
// q from its neighbour, so one such step (far from focus, where a flat floor fits best) carried D = 0 along the
// whole grid, through the true focus: on a take focused inside the board (floor std 0.35 px) the floor model never
// saw its basin and the thin lens alone settled on focus 249 mm, aperture 0.85 mm for a true 450 mm, 3.75 mm.
Params Refine(const Data& s, const std::vector<double>& w, Params m, bool floor, bool free_q, double c,
              int max_iter, bool hold_t = false) {
  // Unknowns in a fixed order: q, D (D^2 for the floor model), t; the mask says which take part.
  const std::array<bool, 3> use = {free_q, true, floor && !hold_t};
  double loss = Loss(s, w, m, floor, c);
  double lambda = 1e-3;
  for (int it = 0; it < max_iter; ++it) {
    std::array<std::array<double, 3>, 3> jtj{};
    std::array<double, 3> jte{};
    for (size_t i = 0; i < s.n(); ++i) {
      if (!(w[i] > 0)) continue;
      const double den = 1 - s.f * m.q;
      const double a = s.c0 * std::abs(m.q - s.p[i]) / den;
      const double sgn = m.q >= s.p[i] ? 1.0 : -1.0;
      const double da_dq = s.c0 * sgn * (1 - s.f * s.p[i]) / (den * den);
      std::array<double, 3> j{};
      double model;
      if (floor) {
        model = std::sqrt(m.d * m.d * a * a + m.t);
        const double inv = 1 / std::max(model, 1e-6);
        j = {m.d * m.d * a * da_dq * inv, 0.5 * a * a * inv, 0.5 * inv};
      } else {
        model = m.d * a;
        j = {m.d * da_dq, a, 0};
      }
      const double e = s.r[i] - model;
      const double wi = w[i] * HuberWeight(e, c);
      for (int r = 0; r < 3; ++r) {
        jte[r] += wi * j[r] * e;
        for (int k = 0; k < 3; ++k) jtj[r][k] += wi * j[r] * j[k];
      }
    }
    // Unknowns held fixed get an identity row so the 3x3 system stays solvable and their step is zero.
    for (int r = 0; r < 3; ++r)
      if (!use[r]) {
        for (int k = 0; k < 3; ++k) jtj[r][k] = jtj[k][r] = 0;
        jtj[r][r] = 1;
        jte[r] = 0;
      }
    bool improved = false;
    for (int attempt = 0; attempt < 6 && !improved; ++attempt) {
      auto a = jtj;
      for (int r = 0; r < 3; ++r) a[r][r] = jtj[r][r] > 0 ? jtj[r][r] * (1 + lambda) : 1;
      std::array<double, 3> step{};
      if (!Solve<3>(a, jte, &step)) return m;
      Params next = m;
      next.q = use[0] ? std::clamp(m.q + step[0], 0.0, s.q_max) : m.q;
      next.d = floor ? std::sqrt(std::max(0.0, m.d * m.d + step[1])) : std::max(0.0, m.d + step[1]);
      next.t = use[2] ? std::max(0.0, m.t + step[2]) : m.t;
      // The decrease the linearised model promises for the step actually taken (after the bounds); when even
      // that is nothing, the optimum (or a bound) is reached and further tries only burn time.
      const double taken_d = floor ? next.d * next.d - m.d * m.d : next.d - m.d;
      const std::array<double, 3> taken = {next.q - m.q, taken_d, next.t - m.t};
      double promised = 0;
      for (int r = 0; r < 3; ++r) {
        promised += taken[r] * jte[r];
        for (int k = 0; k < 3; ++k) promised -= 0.5 * taken[r] * jtj[r][k] * taken[k];
      }
      if (!(promised > 1e-12 * (loss + 1e-12))) return m;
      const double next_loss = Loss(s, w, next, floor, c);
      if (next_loss < loss) {
        const double gain = loss - next_loss;
        m = next;
        loss = next_loss;
        lambda = std::max(lambda / 10, 1e-9);
        improved = true;
        if (gain <= 1e-10 * loss) return m;
      } else {
        lambda *= 10;
      }
    }
    if (!improved) break;
  }
  return m;
}

// Thin lens with floor at a fixed q: (D, t) by Refine, warm-started from the neighbouring q.
Params ProfileFloor(const Data& s, const std::vector<double>& w, double q, double c, const Params& warm,
                    double* loss) {
  Params start = warm;
  start.q = q;
  const Params m = Refine(s, w, start, /*floor=*/true, /*free_q=*/false, c, 20);
  *loss = Loss(s, w, m, true, c);
  return m;
}

// Starting values for the floor model at q: r^2 = D^2 a^2 + t is linear in (D^2, t).
Params SquaresStart(const Data& s, const std::vector<double>& w, double q, double c) {
  double sw = 0, sa = 0, saa = 0, sr = 0, sar = 0;
  for (size_t i = 0; i < s.n(); ++i) {
    const double a2 = std::pow(Shape(s, q, i), 2), r2 = s.r[i] * s.r[i];
    sw += w[i], sa += w[i] * a2, saa += w[i] * a2 * a2, sr += w[i] * r2, sar += w[i] * a2 * r2;
  }
  const double det = sw * saa - sa * sa;
  double d2 = 0, t = 0;
  if (std::abs(det) > 0) {
    d2 = (sw * sar - sa * sr) / det;
    t = (saa * sr - sa * sar) / det;
  }
  double unused;
  Params m = ProfileThin(s, w, q, c, &unused);
  if (d2 > 0 && t > 0) m.d = std::sqrt(d2), m.t = t;
  return m;
}

// Global search over q: the loss is V-shaped wherever focus passes a sample (|.| in the model) and may have a
// minimum on either side of the samples, so a coarse grid over all of [0, 1/f) (dense where the samples are)
// finds the basin, golden-section search refines it, and the ends (q = 0: focus at infinity) are tried as such.
template <typename ProfileFn>
Params SearchFocus(const Data& s, int coarse, int dense, ProfileFn profile) {
  const auto [p_lo, p_hi] = std::minmax_element(s.p.begin(), s.p.end());
  const double span = *p_hi - *p_lo;
  std::vector<double> grid;
  for (int i = 0; i < coarse; ++i) grid.push_back(s.q_max * i / (coarse - 1));
  const double lo = std::max(0.0, *p_lo - 1.5 * span), hi = std::min(s.q_max, *p_hi + 1.5 * span);
  for (int i = 0; i < dense; ++i) grid.push_back(lo + (hi - lo) * i / (dense - 1));
  std::sort(grid.begin(), grid.end());
  grid.erase(std::unique(grid.begin(), grid.end()), grid.end());

  std::vector<double> loss(grid.size());
  std::vector<Params> fits(grid.size());
  for (size_t k = 0; k < grid.size(); ++k) {
    fits[k] = profile(grid[k], k == 0 ? nullptr : &fits[k - 1], &loss[k]);
  }
  const size_t best = std::min_element(loss.begin(), loss.end()) - loss.begin();
  double a = grid[best == 0 ? 0 : best - 1], b = grid[std::min(best + 1, grid.size() - 1)];
  Params best_fit = fits[best];
  double best_loss = loss[best];

  const double inv_phi = (std::sqrt(5.0) - 1) / 2;
  double x1 = b - inv_phi * (b - a), x2 = a + inv_phi * (b - a), l1, l2;
  Params f1 = profile(x1, &best_fit, &l1), f2 = profile(x2, &best_fit, &l2);
  // Loose: the joint refinement that follows (FitOne) finishes the job at a fraction of the cost.
  const double tol = 1e-7 * s.q_max;
  while (b - a > tol) {
    if (l1 <= l2) {
      b = x2, x2 = x1, l2 = l1, f2 = f1;
      x1 = b - inv_phi * (b - a);
      f1 = profile(x1, &f2, &l1);
    } else {
      a = x1, x1 = x2, l1 = l2, f1 = f2;
      x2 = a + inv_phi * (b - a);
      f2 = profile(x2, &f1, &l2);
    }
  }
  if (l1 < best_loss) best_fit = f1, best_loss = l1;
  if (l2 < best_loss) best_fit = f2, best_loss = l2;
  // Golden section never lands exactly on q = 0; a scene focused at infinity should say so.
  if (best_fit.q < 1e-3 * s.q_max) {
    double l0;
    const Params at_infinity = profile(0.0, &best_fit, &l0);
    if (l0 <= best_loss) best_fit = at_infinity;
  }
  return best_fit;
}

Params FitOne(const Data& s, const std::vector<double>& w, bool floor, double c) {
  Params m;
  if (!floor) {
    m = SearchFocus(s, 48, 96, [&](double q, const Params*, double* loss) { return ProfileThin(s, w, q, c, loss); });
  } else {
    // Each floor-model point costs an iterative (D, t) solve, and the floor rounds the V the grid must resolve,
    // so a coarser grid serves.
    m = SearchFocus(s, 24, 48, [&](double q, const Params* warm, double* loss) {
      return ProfileFloor(s, w, q, c, warm ? *warm : SquaresStart(s, w, q, c), loss);
    });
  }
  return Refine(s, w, m, floor, /*free_q=*/true, c, 50);
}

struct Residuals {
  std::vector<double> fit;  // at the full-data optimum
  std::vector<double> loo;  // predicting each sample from a fit without it
};

std::vector<double> FitResiduals(const Data& s, const Params& m, bool floor) {
  std::vector<double> e(s.n());
  for (size_t i = 0; i < s.n(); ++i) e[i] = s.r[i] - Model(s, m, floor, i);
  return e;
}

Residuals Evaluate(const Data& s, const Params& m, bool floor, double c) {
  Residuals res;
  res.fit = FitResiduals(s, m, floor);
  res.loo.resize(s.n());
  std::vector<double> w = s.w;
  for (size_t i = 0; i < s.n(); ++i) {
    // Refit from the full optimum: one sample moves the optimum only a little, so a local refit finds the
    // leave-one-out optimum in the same basin at a small fraction of a global search's cost.
    w[i] = 0;
    const Params held = Refine(s, w, m, floor, /*free_q=*/true, c, 30);
    res.loo[i] = s.r[i] - Model(s, held, floor, i);
    w[i] = s.w[i];
  }
  return res;
}

// The floors the board's radii cannot tell apart: every r0 whose best focus and aperture predict the sections within
// kFloorTolerance (relative rms) of the floor model's own predictions. A measurement accurate to about half a
// percent (docs/independent-truth.md) cannot choose among them. With focus off the board every section sits far
// from focus, where sqrt(D^2 a^2 + r0^2) changes with r0 almost as it does with a slightly other focus and aperture,
// and the range is wide; with focus on or inside the board the sections nearest it read the floor itself.
constexpr double kFloorTolerance = 0.005;
std::pair<double, double> FloorRange(const Data& s, const Params& best, double c) {
  const double r0 = std::sqrt(best.t);
  double r_min = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < s.n(); ++i)
    if (s.w[i] > 0) r_min = std::min(r_min, Model(s, best, true, i));
  auto off = [&](double floor_px) {
    Params m = best;
    m.t = floor_px * floor_px;
    m = Refine(s, s.w, m, /*floor=*/true, /*free_q=*/true, c, 50, /*hold_t=*/true);
    double sum = 0, sw = 0;
    for (size_t i = 0; i < s.n(); ++i) {
      if (!(s.w[i] > 0)) continue;
      const double ref = Model(s, best, true, i);
      const double e = (Model(s, m, true, i) - ref) / std::max(ref, 1e-6);
      sum += s.w[i] * e * e, sw += s.w[i];
    }
    return sw > 0 ? std::sqrt(sum / sw) : 0.0;
  };
  // Walk out from r0 in steps of 2 % of the smallest radius (no floor exceeds it) until the predictions part.
  const double step = 0.02 * r_min;
  double lo = r0, hi = r0;
  while (lo > 0 && off(std::max(0.0, lo - step)) <= kFloorTolerance) lo = std::max(0.0, lo - step);
  while (hi < r_min && off(std::min(r_min, hi + step)) <= kFloorTolerance) hi = std::min(r_min, hi + step);
  return {lo, hi};
}

double WeightedRms(const Data& s, const std::vector<double>& e, const std::vector<bool>& take) {
  double sum = 0, sw = 0;
  for (size_t i = 0; i < s.n(); ++i)
    if (take[i]) sum += s.w[i] * e[i] * e[i], sw += s.w[i];
  return sw > 0 ? std::sqrt(sum / sw) : 0.0;
}

}  // namespace

// In step with FitThinLens's kMinSamplesForFloor and clearly_better below.
const char* const kModelChoiceRule =
    "leave-one-out rms: the floor is kept only when it predicts held-out sections >= 10 % and >= 0.001 px better, "
    "with at least 10 sections";

double FittedModel::PredictPx(const Lens& lens, double u_mm) const {
  const Lens fitted{lens.focal_length_mm, aperture_mm, lens.pixel_pitch_mm};
  const double thin = SignedBlurRadiusPx(fitted, focus_mm, u_mm);
  return std::sqrt(std::max(0.0, thin * thin + floor_px * floor_px + cancel_px2));
}

bool FloorRangePinned(double lo, double hi, double floor_px) { return hi - lo <= std::max(0.1, 0.2 * floor_px); }

bool FloorPinned(const FittedModel& m) { return m.kind != "thin_lens+floor" || m.floor_determined; }

std::string FloorText(const FittedModel& m) {
  char text[160];
  const bool range = std::isfinite(m.floor_lo_px) && std::isfinite(m.floor_hi_px);
  if (m.kind != "thin_lens+floor") {
    // The thin lens kept: its floor is 0, but where the floor model's floors span a range the sections do not say
    // there is none (focus off the board): a lens floor would then show only near focus, where nothing was measured.
    if (range && m.floor_hi_px - m.floor_lo_px > std::max(0.1, 0.2 * m.floor_hi_px))
      std::snprintf(text, sizeof text, "floor 0 px (thin lens alone; floors %.2f-%.2f px fit alike: not determined)",
                    m.floor_lo_px, m.floor_hi_px);
    else
      std::snprintf(text, sizeof text, "floor 0 px (thin lens alone)");
  } else if (m.floor_determined) {
    std::snprintf(text, sizeof text, "floor %.2f px (a std of %.2f px)", m.floor_px, m.floor_px / 2);
  } else {
    std::snprintf(text, sizeof text, "floor not determined (%.2f-%.2f px fit alike)", m.floor_lo_px, m.floor_hi_px);
  }
  return text;
}

FittedModel FitThinLens(const Lens& lens, const std::vector<BlurSample>& samples, const FitOptions& options) {
  if (!(lens.focal_length_mm > 0) || !std::isfinite(lens.focal_length_mm))
    throw InputError("FitThinLens: lens focal_length_mm", "must be > 0, got " + Num(lens.focal_length_mm));
  if (!(lens.pixel_pitch_mm > 0) || !std::isfinite(lens.pixel_pitch_mm))
    throw InputError("FitThinLens: lens pixel_pitch_mm", "must be > 0, got " + Num(lens.pixel_pitch_mm));
  if (!(options.huber_px > 0) || !std::isfinite(options.huber_px))
    throw InputError("FitThinLens: options huber_px", "must be > 0, got " + Num(options.huber_px));

  Data s;
  s.f = lens.focal_length_mm;
  s.c0 = lens.focal_length_mm / (2 * lens.pixel_pitch_mm);
  s.q_max = (1 - 1e-6) / lens.focal_length_mm;
  for (size_t i = 0; i < samples.size(); ++i) {
    const BlurSample& b = samples[i];
    const std::string where = "FitThinLens: sample " + std::to_string(i);
    if (!(b.weight >= 0) || !std::isfinite(b.weight))
      throw InputError(where + " weight", "must be a finite number >= 0, got " + Num(b.weight));
    if (b.weight == 0) continue;
    if (!(b.r_px >= 0) || !std::isfinite(b.r_px))
      throw InputError(where + " r_px", "must be a finite number >= 0, got " + Num(b.r_px));
    if (!(b.u_mm > lens.focal_length_mm))  // +infinity is a depth like any other here: p = 0
      throw Error(ErrorKind::kDomain, where + ": u = " + Num(b.u_mm) + " mm is not beyond the focal length f = " +
                                          Num(lens.focal_length_mm) + " mm: a thin lens forms no real image there");
    s.p.push_back(1 / b.u_mm);
    s.r.push_back(b.r_px);
    s.w.push_back(b.weight);
  }
  if (s.n() < 3)
    throw Error(ErrorKind::kNotFound, "FitThinLens: need at least 3 samples with weight > 0 to fit focus and "
                                      "aperture, got " + std::to_string(s.n()));
  const auto [p_lo, p_hi] = std::minmax_element(s.p.begin(), s.p.end());
  if (!(*p_hi - *p_lo > 1e-9 * *p_hi))
    throw Error(ErrorKind::kNotFound, "FitThinLens: all " + std::to_string(s.n()) + " samples lie at one depth (u = " +
                                          Num(1 / *p_hi) + " mm): focus and aperture cannot be told apart");

  const double c = options.huber_px;
  const Params thin = FitOne(s, s.w, false, c);
  const Residuals thin_res = Evaluate(s, thin, false, c);

  // Leave-one-out over a handful of samples cannot tell a floor from noise and a flawed section: on random
  // scenes with 10 % doubled radii, 5-9 samples kept a floor that was not there three times as often as 10+ did.
  constexpr size_t kMinSamplesForFloor = 10;
  bool use_floor = false;
  Params with_floor;
  Residuals floor_res;
  std::vector<bool> judged(s.n(), true);
  auto inlier = [&](double e) { return std::abs(e) <= 3 * c; };
  if (options.allow_floor && s.n() >= kMinSamplesForFloor) {
    with_floor = FitOne(s, s.w, true, c);
    // The thin-lens optimum is a floor model with t = 0; keep whichever of the two starts ends lower.
    Params from_thin = thin;
    from_thin = Refine(s, s.w, from_thin, true, true, c, 50);
    if (Loss(s, s.w, from_thin, true, c) < Loss(s, s.w, with_floor, true, c)) with_floor = from_thin;
    const std::vector<double> floor_fit = FitResiduals(s, with_floor, true);
    // Compare both models on the same samples, and not on gross outliers: a flawed section held out is
    // mispredicted by any model and would drown the difference the floor makes.
    for (size_t i = 0; i < s.n(); ++i) judged[i] = inlier(thin_res.fit[i]) && inlier(floor_fit[i]);
    if (std::none_of(judged.begin(), judged.end(), [](bool b) { return b; })) judged.assign(s.n(), true);
    // A clear margin, relative and absolute: a third parameter that buys less than 10 % is noise being fitted,
    // and one that buys less than 0.001 px is rounding on exact data. (The absolute margin was 0.01 px, "far below
    // anything a renderer can show"; but a floor worth 0.003-0.008 px of held-out rms on the board changes the
    // focus it finds, and so the radius off the board: focus 1000 mm and a 0.7 px floor behind a board at
    // 360-640 mm, measured to 0.01 px, kept the thin lens with focus 1147 mm, which predicts 0.24 px at the true
    // focus where the blur is 0.70 px.)
    auto clearly_better = [](double floor_px, double thin_px, double ratio) {
      return floor_px < ratio * thin_px && thin_px - floor_px > 0.001;
    };
    // Held-out error exceeds the in-sample error, and more so for the model with more parameters, so a floor
    // that does not even fit the data 5 % better cannot predict it 10 % better: skip its n refits (most scenes).
    // (Both errors are still written to calib.json, so the floor's leave-one-out error is computed either way.)
    const bool worth_judging = with_floor.t > 0 && clearly_better(WeightedRms(s, floor_fit, judged),
                                                                   WeightedRms(s, thin_res.fit, judged), 0.95);
    floor_res = Evaluate(s, with_floor, true, c);
    if (worth_judging)
      use_floor = clearly_better(WeightedRms(s, floor_res.loo, judged), WeightedRms(s, thin_res.loo, judged), 0.9);
  } else {
    for (size_t i = 0; i < s.n(); ++i) judged[i] = inlier(thin_res.fit[i]);
    if (std::none_of(judged.begin(), judged.end(), [](bool b) { return b; })) judged.assign(s.n(), true);
  }

  const Params& m = use_floor ? with_floor : thin;
  const Residuals& res = use_floor ? floor_res : thin_res;
  FittedModel out;
  out.focus_mm = m.q > 0 ? 1 / m.q : std::numeric_limits<double>::infinity();
  out.aperture_mm = m.d;
  out.floor_px = use_floor ? std::sqrt(m.t) : 0.0;
  out.kind = use_floor ? "thin_lens+floor" : "thin_lens";
  out.samples_used = static_cast<int>(s.n());
  std::vector<bool> inliers(s.n());
  for (size_t i = 0; i < s.n(); ++i) {
    inliers[i] = inlier(res.fit[i]);
    out.outliers += inliers[i] ? 0 : 1;
  }
  if (out.outliers == out.samples_used) inliers.assign(s.n(), true);
  out.rms_px = WeightedRms(s, res.fit, inliers);
  out.loo_rms_px = WeightedRms(s, res.loo, judged);
  out.thin_rms_px = WeightedRms(s, thin_res.fit, judged);
  out.thin_loo_rms_px = WeightedRms(s, thin_res.loo, judged);
  const bool floor_fitted = !floor_res.loo.empty();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  out.floor_rms_px = floor_fitted ? WeightedRms(s, floor_res.fit, judged) : nan;
  out.floor_loo_rms_px = floor_fitted ? WeightedRms(s, floor_res.loo, judged) : nan;
  out.floor_candidate_px = floor_fitted ? std::sqrt(with_floor.t) : nan;
  if (floor_fitted) {
    const auto [lo, hi] = FloorRange(s, with_floor, c);
    out.floor_lo_px = lo, out.floor_hi_px = hi;
  } else {
    out.floor_lo_px = out.floor_hi_px = nan;
  }
  out.floor_determined = use_floor && FloorRangePinned(out.floor_lo_px, out.floor_hi_px, out.floor_px);
  return out;
}

}  // namespace blurcue::optics
