#pragma once
// The X-junctions at an edge section's ends in the profile model (edge_blur.cc): a large blur on a short section (a
// turned board's far squares, focus in front of the board) reaches past the crossing lines at the section's ends into
// the squares of the other colour. The board is a product pattern: across the edge its rows alternate, along it its
// columns do, so the photo near a section is m + (S / 2) p(d) q(c) blurred, with p the rows' pattern across the edge
// (the edge's step and its neighbours') and q = +1 inside the section, -1 past each crossing line (up to the next).
// Averaged over the samples' places along the edge, each step of p is then blurred by the PSF less twice its share
// that lands past a crossing line: E(x) - 2 C(x), C below. Internal to calib.
#include <vector>

namespace blurcue::calib::detail {

// Where the samples lie along the edge: between the crossing lines at the section's ends, which slant by ka (end a)
// and kb (end b) px along the edge per px across it (EdgeWindow::ka, kb); each sample's distance along the edge
// from either line is uniform on [c_lo_px, c_hi_px] (the central part WindowSamples keeps). The next crossing lines
// lie a section's length further.
struct JunctionGeometry {
  double length_px = 0, ka = 0, kb = 0, c_lo_px = 0, c_hi_px = 0;
};

// C(x) for the PSF of radius r and shape angle phi (edge_esf.h's disc of r cos phi x Gaussian of std r sin(phi) / 2):
// the share of the PSF centred x px from the edge on its bright side (u < x) that lands past a crossing line,
// averaged over the samples' places (the pixel aperture is left out: it changes the small share by a small part).
// Tabulated once per PSF on a grid of at most ~50 x 50 cells (the 2-D PSF times the share past the lines, summed
// along the edge and then across).
class JunctionShare {
 public:
  JunctionShare(const JunctionGeometry& geometry, double r, double phi);
  double operator()(double x) const;

 private:
  double x0_ = 0, dx_ = 1;
  std::vector<double> cumulative_;  // C at x0_ + i dx_
};

}  // namespace blurcue::calib::detail
