#include "calib/family_esf.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <memory>

namespace blurcue::calib::detail {
namespace {

// Projected taps lighter than this are left out (a 0.8 px Gaussian's corner taps, 4e-12; its edge taps' 2e-6 stay).
constexpr double kMinTapWeight = 1e-7;
// The second axis's taps are summed into the first's where w2^2 |V| is at most this (px^2): the term that leaves out
// is w2^2 V ESF'' / 2, under 1e-6 of the step for |ESF''| up to 20 (optics of 0.02 px over a pixel's box).
constexpr double kCollapsePx2 = 1e-7;
// The table's step: the largest 0.01 px x 2^k (k from -6 to 4) at most r / kStepsPerRadius. Measured against
// EsfModel (r 0.02-4 px; disc, Gaussian and mixed shapes; edges at 0-60 deg): max |error| 6e-6 at r / 40 (1e-6
// under r = 1 px), 3e-5 at r / 20; a fixed 0.005 px step left 1.8e-4 at r = 0.02 px. Its points, 300-600 from
// r = 0.2 px, are what a reading costs on a long profile (100-160 points x 9-81 taps).
constexpr double kStepsPerRadius = 40;

double TableStep(const EsfModel& model) {
  double h = 0.01 * 16;
  while (h > model.r / kStepsPerRadius && h > 0.01 / 64) h *= 0.5;
  return h;
}

// The tables built last on this thread: a reading evaluates the same optics again (its Levenberg-Marquardt step in
// the edge's position; the radius grid, the same for every family on a section).
constexpr size_t kCachedTables = 64;
struct CachedTable {
  double r = 0, phi = 0, w1 = 0, w2 = 0;
  std::shared_ptr<const EsfTable> table;
};

std::shared_ptr<const EsfTable> Tabulated(const EsfModel& model) {
  thread_local std::deque<CachedTable> cache;
  for (const CachedTable& c : cache)
    if (c.r == model.r && c.phi == model.phi && c.w1 == model.w1 && c.w2 == model.w2) return c.table;
  if (cache.size() >= kCachedTables) cache.pop_front();
  cache.push_back({model.r, model.phi, model.w1, model.w2, std::make_shared<const EsfTable>(model)});
  return cache.back().table;
}

}  // namespace

std::vector<double> FamilyTaps(const PhaseFamily& family) {
  const double sigma = family.sigma_px;
  if (!(sigma > 0)) return {1.0};
  const int reach = std::max(1, static_cast<int>(std::ceil(4 * sigma)));
  std::vector<double> t(2 * reach + 1);
  double sum = 0;
  for (int k = -reach; k <= reach; ++k) sum += t[k + reach] = std::exp(-0.5 * (k / sigma) * (k / sigma));
  const double a = std::max(0.0, family.sharpen);
  for (int k = -reach; k <= reach; ++k)
    t[k + reach] = a > 0 ? (k == 0 ? 1 + a : 0) - a * t[k + reach] / sum : t[k + reach] / sum;
  return t;
}

double TapsVariance(const std::vector<double>& t) {
  const int reach = static_cast<int>(t.size()) / 2;
  double v = 0;
  for (int k = -reach; k <= reach; ++k) v += double(k) * k * t[k + reach];
  return v;
}

std::vector<ProjectedTap> ProjectTaps(const std::vector<double>& taps, double w1, double w2) {
  const int reach = static_cast<int>(taps.size()) / 2;
  std::vector<ProjectedTap> out;
  if (w2 * w2 * std::abs(TapsVariance(taps)) <= kCollapsePx2) {
    for (int i = -reach; i <= reach; ++i) out.push_back({w1 * i, taps[i + reach]});  // the taps sum to 1
    return out;
  }
  for (int i = -reach; i <= reach; ++i)
    for (int j = -reach; j <= reach; ++j)
      if (const double w = taps[i + reach] * taps[j + reach]; std::abs(w) >= kMinTapWeight)
        out.push_back({w1 * i + w2 * j, w});
  return out;
}

size_t EsfTable::Points(const EsfModel& model) {
  const double h = TableStep(model);
  return static_cast<size_t>(std::floor(model.reach / h) - std::ceil(-model.reach / h)) + 1;
}

EsfTable::EsfTable(const EsfModel& model) : step_(TableStep(model)) {
  first_ = std::ceil(-model.reach / step_);
  const size_t n = Points(model);
  v_.resize(n);
  for (size_t k = 0; k < n; ++k) v_[k] = model((first_ + double(k)) * step_);
}

double EsfTable::operator()(double x) const {
  const double u = x / step_ - first_;
  const double fl = std::floor(u);
  const long n = static_cast<long>(v_.size());
  if (fl < 0) return 0.0;  // the first node lies within a step of the model's reach, below which it is 0
  if (fl >= double(n - 1)) return v_.back();
  const long i = static_cast<long>(fl);
  const double f = u - fl;
  const double p0 = v_[std::max(0L, i - 1)], p1 = v_[i], p2 = v_[i + 1], p3 = v_[std::min(n - 1, i + 2)];
  return p1 + 0.5 * f * (p2 - p0 + f * (2 * p0 - 5 * p1 + 4 * p2 - p3 + f * (3 * (p1 - p2) + p3 - p0)));
}

FamilyProfile::FamilyProfile(double r1, double phi, double w1, double w2, const std::vector<ProjectedTap>& taps,
                             size_t points)
    : model_(r1, phi, w1, w2), taps_(taps) {
  if (points * taps.size() > EsfTable::Points(model_)) table_ = Tabulated(model_);
}

double FamilyProfile::operator()(double x) const {
  double m = 0;
  if (table_)
    for (const ProjectedTap& t : taps_) m += t.weight * (*table_)(x - t.offset);
  else
    for (const ProjectedTap& t : taps_) m += t.weight * model_(x - t.offset);
  return m;
}

}  // namespace blurcue::calib::detail

namespace blurcue::calib {

std::string PhaseFamily::Name() const {
  char text[160];
  if (!(sigma_px > 0)) return "the optics alone";
  const char* between = fitted ? ", fitted between the families" : "";
  if (sharpen > 0)
    std::snprintf(text, sizeof text, "the optics then sharpening (unsharp mask of amount %.2f, std %.2f px%s)", sharpen,
                  sigma_px, between);
  else
    std::snprintf(text, sizeof text, "the optics then a Gaussian of std %.2f px on the sampled image%s", sigma_px,
                  between);
  return text;
}

const std::vector<PhaseFamily>& PhaseFamilies() {
  // Gaussians: under 0.3 px one's taps at whole pixels are the identity to 4e-3 (0.3 px reads as the optics alone);
  // steps of 0.05 px beyond, where a step moves a sub-pixel reading by 3-8 %. Sharpening: a camera's unsharp masks,
  // mild to strong, over a narrow and a wide Gaussian.
  static const std::vector<PhaseFamily> families = {
      {0, 0},      {0.35, 0},   {0.4, 0},   {0.45, 0},  {0.5, 0},   {0.55, 0},  {0.6, 0}, {0.7, 0}, {0.8, 0},
      {0.6, 0.15}, {0.6, 0.3},  {0.6, 0.5}, {0.6, 0.7}, {0.8, 0.15}, {0.8, 0.3}, {0.8, 0.5}, {0.8, 0.7},
      {1.0, 0.15}, {1.0, 0.3}, {1.0, 0.5}, {1.0, 0.7}};
  return families;
}

std::vector<size_t> PhaseNeighbours(size_t c) {
  // Axes: the Gaussians by std, and the unsharp masks of each std by amount; the optics alone is the zero of each.
  const std::vector<PhaseFamily>& f = PhaseFamilies();
  auto param = [&](size_t a) { return f[a].sharpen > 0 ? f[a].sharpen : f[a].sigma_px; };
  auto on_axis = [&](size_t a, size_t of) {  // a lies on the axis of family `of` (not the optics alone)
    return a == 0 || ((f[a].sharpen > 0) == (f[of].sharpen > 0) && (f[of].sharpen <= 0 || f[a].sigma_px == f[of].sigma_px));
  };
  std::vector<size_t> out;
  auto add = [&](size_t a) {
    if (a < f.size() && std::find(out.begin(), out.end(), a) == out.end()) out.push_back(a);
  };
  for (size_t axis = 1; axis < f.size(); ++axis) {
    if (c != 0 && axis != c) continue;
    // The nearest on each side of c along this axis.
    size_t below = f.size(), above = f.size();
    for (size_t a = 0; a < f.size(); ++a) {
      if (a == c || !on_axis(a, axis)) continue;
      const double d = param(a) - (c == 0 ? 0.0 : param(c));
      if (a == 0 || d < 0) {
        if (below == f.size() || d > param(below) - param(c)) below = a;
      } else if (d > 0 && (above == f.size() || d < param(above) - (c == 0 ? 0.0 : param(c)))) {
        above = a;
      }
    }
    if (c != 0) add(below);
    add(above);
  }
  return out;
}

}  // namespace blurcue::calib
