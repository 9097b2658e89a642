#include "calib/edge_window.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace blurcue::calib {
namespace {

// Signed distance along the normal from the section's middle to the neighbour's line (px), where the samples' strip
// meets it: the strip's centre leaves the middle along n + shear t (shear: the mean slant of the crossing lines the
// samples keep between, EdgeWindow::ka and kb). The board's rows converge in the image, so on a turned board (its
// squares parallelograms: shear of 1-2) the neighbour lies nearer or farther there than on the normal; its step
// modelled at the normal's distance made short far sections read 3-5 % high. 0 when the neighbour is degenerate or
// runs along the strip.
double NeighbourDistance(const EdgeFrame& x, const NeighbourEdge& k, double shear) {
  const cv::Point2d m = x.a + 0.5 * x.length * x.t, dir = k.b - k.a, centre = x.n + shear * x.t;
  // m + g centre = k.a + lambda dir, solved for g (Cramer's rule).
  const cv::Point2d rhs = k.a - m;
  const double det = centre.x * (-dir.y) - centre.y * (-dir.x);
  if (!(std::abs(det) > 1e-9 * cv::norm(dir))) return 0;
  const double g = (rhs.x * (-dir.y) - rhs.y * (-dir.x)) / det;
  return std::isfinite(g) ? g : 0;
}

// Along-per-across slope of the line from a section end `p` to the neighbour's matching end `q`.
double ColumnSlope(const EdgeFrame& x, const cv::Point2d& p, const cv::Point2d& q) {
  const double across = x.n.dot(q - p);
  return std::abs(across) > 1e-9 ? x.t.dot(q - p) / across : 0;
}

// How far along the edge a crossing line of direction `cross` moves per px across it (0: perpendicular, or not
// given). Lines within 6 degrees of the edge itself are not a square's side: treated as perpendicular.
double CrossShear(const cv::Point2d& cross, const EdgeFrame& f) {
  const double along = cross.dot(f.t), across = cross.dot(f.n);
  if (!std::isfinite(along) || !std::isfinite(across) || !(std::abs(across) > 0.1 * std::hypot(along, across))) return 0;
  return along / across;
}

std::string Format(const char* fmt, double a, double b, double c = 0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, fmt, a, b, c);
  return buf;
}

}  // namespace

EdgeFrame MakeEdgeFrame(const EdgeSegment& s) {
  EdgeFrame f;
  f.a = s.a;
  const cv::Point2d d = s.b - s.a;
  f.length = std::hypot(d.x, d.y);
  if (f.length > 0) f.t = d / f.length;
  f.n = cv::Point2d(-f.t.y, f.t.x);
  return f;
}

std::vector<EdgeWindow::Step> EdgeWindow::Steps() const {
  std::vector<Step> out;
  if (minus.neighbour_px > 0) out.push_back({-minus.neighbour_px, minus.neighbour_r_px});
  if (plus.neighbour_px > 0) out.push_back({plus.neighbour_px, plus.neighbour_r_px});
  return out;
}

EdgeWindow PlainWindow(const EdgeSegment& segment) {
  EdgeWindow w;
  w.minus.end_px = w.plus.end_px = segment.half_window_px;
  const EdgeFrame x = MakeEdgeFrame(segment);
  w.ka = CrossShear(segment.cross_a, x), w.kb = CrossShear(segment.cross_b, x);
  return w;
}

EdgeWindow NeighbourWindow(const EdgeSegment& segment, double reach_px) {
  EdgeWindow w = PlainWindow(segment);
  const EdgeFrame x = MakeEdgeFrame(segment);
  // The crossing lines' own directions where calibrate gave them; otherwise the lines to the neighbours' ends.
  const bool crossing = segment.cross_a != cv::Point2d(0, 0) || segment.cross_b != cv::Point2d(0, 0);
  double ka = 0, kb = 0;
  int slopes = 0;
  for (const NeighbourEdge& k : segment.neighbours) {
    if (!(k.beyond_px >= 0) || NeighbourDistance(x, k, 0) == 0) continue;
    ka += ColumnSlope(x, segment.a, k.a), kb += ColumnSlope(x, segment.b, k.b), ++slopes;
  }
  if (slopes > 0 && !crossing) w.ka = ka / slopes, w.kb = kb / slopes;
  const double shear = 0.5 * (w.ka + w.kb);
  for (const NeighbourEdge& k : segment.neighbours) {
    const double g = NeighbourDistance(x, k, shear);
    if (g == 0 || !(k.beyond_px >= 0)) continue;
    EdgeWindow::Side& side = g > 0 ? w.plus : w.minus;
    if (side.neighbour_px > 0 && side.neighbour_px <= std::abs(g)) continue;  // the nearer one on a side
    side.neighbour_px = std::abs(g);
    side.neighbour_r_px = std::isfinite(k.r_px) && k.r_px > 0 ? k.r_px : 0;
    // Past the neighbour until the edge after it (2 x beyond_px further) comes within reach.
    side.end_px = side.neighbour_px + std::max(0.0, std::min(k.beyond_px, 2 * k.beyond_px - reach_px));
  }
  return w;
}

bool WidenFreeSides(const cv::Mat& linear, const EdgeSegment& segment, double reach_px, double offset_px, double step,
                    EdgeWindow* window) {
  const EdgeFrame x = MakeEdgeFrame(segment);
  if (linear.empty() || !(x.length > 4) || !(std::abs(step) > 0) || !std::isfinite(reach_px) ||
      !std::isfinite(offset_px))
    return false;
  bool widened = false;
  for (const double sign : {-1.0, 1.0}) {
    EdgeWindow::Side& side = sign < 0 ? window->minus : window->plus;
    const double need = reach_px + std::abs(offset_px);  // to where the blur ends, as CrowdedReason counts it
    if (side.neighbour_px > 0 || need <= side.end_px || need > 2 * side.end_px) continue;
    double lo = 1e300, hi = -1e300;
    bool ok = true;
    for (double d = side.end_px; ok && d <= need + 1; d += 1) {
      std::vector<float> band;
      for (double s = 0.25 * x.length; s <= 0.75 * x.length; s += 1) {
        const cv::Point2d p = x.a + s * x.t + sign * d * x.n;
        const int px = int(std::lround(p.x)), py = int(std::lround(p.y));
        if (px < 0 || py < 0 || px >= linear.cols || py >= linear.rows) continue;
        const float v = linear.at<float>(py, px);
        if (std::isfinite(v)) band.push_back(v);
      }
      if (band.size() < 3) {
        ok = false;
        break;
      }
      std::nth_element(band.begin(), band.begin() + band.size() / 2, band.end());
      const double median = band[band.size() / 2];
      lo = std::min(lo, median), hi = std::max(hi, median);
    }
    if (!ok || hi - lo > 0.05 * std::abs(step)) continue;
    side.end_px = need + 1;
    widened = true;
  }
  return widened;
}

double BlurReachPx(const ModelFit& fit) {
  if (fit.shape_ambiguous) return 1.5 * fit.r_px + 1.5;
  return fit.disc_r_px + 3 * fit.floor_sigma_px + 1.5;
}

double JunctionMarginPerUnusedPx(const EdgeSegment& segment, const EdgeWindow& window) {
  const double length = cv::norm(segment.b - segment.a);
  double margin = 1e300;
  for (double d : {window.lo(), window.hi()}) margin = std::min(margin, 0.5 * (length + (window.kb - window.ka) * d));
  // The X-junctions' distance from the samples is taken across the crossing lines (shorter where they lean).
  return std::max(0.0, margin) / std::sqrt(1 + std::max(window.ka * window.ka, window.kb * window.kb));
}

double AlongFractionClearOfJunctions(const EdgeSegment& segment, const EdgeWindow& window, double r_px) {
  const double per = JunctionMarginPerUnusedPx(segment, window);
  return per > 0 && std::isfinite(r_px) ? 1 - (r_px + 1) / per : 0;
}

std::string CrowdedReason(const EdgeSegment& segment, const EdgeWindow& window, const ModelFit& fit,
                          double along_fraction, double along_span_px, bool plain, bool junctions_modelled) {
  const double r = fit.r_px, offset = std::abs(fit.offset_px);
  const double reach = plain ? 1.5 * r + 2 : BlurReachPx(fit);
  for (const EdgeWindow::Side* side : {&window.minus, &window.plus}) {
    if (side->neighbour_px == 0) {
      if (reach > side->end_px - offset)
        return Format(plain ? "its blur (r = %.2f px) needs %.1f px each side of the edge, but the next edge is %.1f "
                              "px away"
                            : "its blur (r = %.2f px) reaches %.1f px from the edge, past the %.1f px free of other "
                              "edges on the side without a neighbouring edge",
                      r, reach, plain ? 2 * side->end_px : side->end_px);
    } else {
      if (side->neighbour_px < r)
        return Format("the neighbouring edge (%.1f px away) lies inside its blur (r = %.2f px)", side->neighbour_px,
                      r);
      if (side->end_px - side->neighbour_px < 1)
        return Format("the edge after the neighbouring one (%.1f px away) lies within reach of its blur (r = %.2f "
                      "px)", side->neighbour_px, r);
    }
  }
  const double length = cv::norm(segment.b - segment.a), frac = std::clamp(along_fraction, 0.0, 1.0);
  const double margin = (1 - frac) * JunctionMarginPerUnusedPx(segment, window);
  if (margin < r + 1 && !junctions_modelled)
    return Format("the X-junctions at the section's ends lie %.1f px from the part measured, within its blur (r = "
                  "%.2f px): the section is too short", margin, r);
  if (along_span_px < std::min(2 * reach, 0.5 * frac * length))
    return Format("the image border leaves %.1f px of the section's %.1f px", along_span_px, length);
  return "";
}

}  // namespace blurcue::calib
