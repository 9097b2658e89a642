#pragma once
// Where an edge section's blur is measured (the samples and the profile model of edge_blur.cc): how far across the
// edge, how far along it from the X-junctions, which neighbouring parallel edges' steps the profile includes; and,
// in words, why a window cannot hold a blur ("crowded").
#include <algorithm>
#include <string>
#include <vector>

#include "calib/edge_blur.h"

namespace blurcue::calib {

// A section's frame: a, the unit direction t (a -> b), the normal n = t turned +90 degrees in image coordinates (x
// right, y down): n = (-t.y, t.x), and the length. Distances across the edge are along n, along it along t from a.
struct EdgeFrame {
  cv::Point2d a, t, n;
  double length = 0;
};
EdgeFrame MakeEdgeFrame(const EdgeSegment& segment);

struct EdgeWindow {
  // One side of the edge (the normal's minus or plus side): samples reach `end_px` from the segment line; when a
  // neighbouring parallel edge is modelled there, it lies `neighbour_px` away (0: none, the side is free of edges).
  struct Side {
    double end_px = 0, neighbour_px = 0;
    double neighbour_r_px = 0;  // the neighbour's blur (NeighbourEdge::r_px; 0: this edge's)
  };
  Side minus, plus;
  // Along the edge: the section's ends lie on the board's column lines, which slant by ka (at end a) and kb (at end
  // b) px along the edge per px across it; samples keep to the central fraction of the strip between the two lines
  // at each distance across.
  double ka = 0, kb = 0;
  double lo() const { return -minus.end_px; }
  double hi() const { return plus.end_px; }
  double HalfWidth() const { return std::max(minus.end_px, plus.end_px); }
  // The modelled neighbours: signed distance from this edge along the normal (px, at the section's middle), blur.
  struct Step {
    double at_px = 0, r_px = 0;
  };
  std::vector<Step> Steps() const;
};

// +-half_window_px across, the central part along between the crossing lines (segment.cross_a/b; perpendicular ends
// where they are not given): the window of the plain fit. A rectangle's corners would reach across an oblique crossing
// line into the next square, whose opposite colour and blurred edge widen the fitted edge (docs/independent-truth.md).
EdgeWindow PlainWindow(const EdgeSegment& segment);

// The window across the neighbouring edges (segment.neighbours) for a blur that reaches `reach_px` from its edge: on
// a side with a neighbour, past it until the edge after that one comes within reach; on a side without, as far as
// the plain window. Along the edge it follows the crossing lines where given, else the lines to the neighbours' ends.
EdgeWindow NeighbourWindow(const EdgeSegment& segment, double reach_px);

// Widens each side of `window` without a neighbouring edge to where a blur reaching `reach_px` from the edge (at
// `offset_px` off the segment line) ends, where the photo there holds no other edge: the medians of 1 px bands
// across the section's central half, from the side's end to the new one, lie within 5 % of |step| of each other.
// At most to twice the side's end (the board says nothing beyond its outer edge; the photo decides). Returns whether
// a side was widened.
bool WidenFreeSides(const cv::Mat& linear, const EdgeSegment& segment, double reach_px, double offset_px, double step,
                    EdgeWindow* window);

// How far a fitted blur reaches from its edge: the disc's radius, three floor standard deviations (99.9 % of the
// floor's spread), a pixel and a plateau sample; a Gaussian's 3 std when the shape is ambiguous. px.
double BlurReachPx(const ModelFit& fit);

// The X-junctions at the section's ends: how far they lie from the part measured, per unit of the section's length
// left unused (the part used is its central `along_fraction`; the distance is taken across the crossing lines).
double JunctionMarginPerUnusedPx(const EdgeSegment& segment, const EdgeWindow& window);
// The largest central fraction of the section whose samples keep the X-junctions out of a blur of r_px (r + 1 px
// away, as CrowdedReason asks); <= 0 when none does.
double AlongFractionClearOfJunctions(const EdgeSegment& segment, const EdgeWindow& window, double r_px);

// Why `fit`, measured in `window` over samples spanning `along_span_px` of the section, cannot be trusted ("" when
// it can): the blur reaching past the window's free side, a neighbouring edge inside the blur or the edge after it
// within reach, the X-junctions within reach of the part used, or the image border leaving too little of it.
// `plain`: the window holds no neighbour, so the levels rest on the plateaus alone and need the plain margin
// (1.5 r + 2 px on each side).
// `junctions_modelled`: the X-junctions are in the profile model (edge_junction.h), so their reach is no reason.
std::string CrowdedReason(const EdgeSegment& segment, const EdgeWindow& window, const ModelFit& fit,
                          double along_fraction, double along_span_px, bool plain, bool junctions_modelled = false);

}  // namespace blurcue::calib
