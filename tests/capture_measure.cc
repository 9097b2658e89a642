// capture_measure DIR [--tolerance-px 0.25 --tolerance-rel 0.05 --place-px 1] [--place-only: blur printed, not judged]
//
// Measures what captured frames show (blurcue run --capture) with the calibration's own edge fit
// (calib::MeasureEdgeModel), independently of how they were drawn: for every object of every trial-NNNN.json, the
// blur across its silhouette in the PNG and where that edge lies, against the recorded r_screen_px and outline_px.
//   card: each of the four sides of the outline polygon is an edge segment;
//   ball: the image is resampled along rays from the outline's centre so that the rim becomes a straight edge (one
//         segment per 45 degree sector, each ray shifted by the outline's radius at its angle).
// An object's blur is the median over its usable segments, its place the largest fitted offset of an edge from
// the outline (a ball: the median sector's). Prints one line per object and exits 1 when any is off by more than max(tolerance-px,
// tolerance-rel x r) in blur or place-px in place, or when an object has no usable segment.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "calib/edge_blur.h"
#include "core/image.h"
#include "core/json_io.h"

namespace {

using blurcue::Json;
using blurcue::calib::EdgeSegment;
using blurcue::calib::MeasureEdgeModel;
using blurcue::calib::ModelFit;

// Per segment, in order: its blur and offset, NaN when the fit is not usable.
struct Fits {
  std::vector<double> r, offset;
  void Add(const ModelFit& f) {
    r.push_back(f.ok ? f.r_px : NAN);
    offset.push_back(f.ok ? f.offset_px : NAN);
  }
};

double Median(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return std::isnan(x); }), v.end());
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

Fits MeasureCard(const cv::Mat& linear, const std::vector<cv::Point2d>& outline) {
  Fits fits;
  double shortest = 1e9;
  for (size_t i = 0; i < outline.size(); ++i)
    shortest = std::min(shortest, cv::norm(outline[(i + 1) % outline.size()] - outline[i]));
  for (size_t i = 0; i < outline.size(); ++i) {
    EdgeSegment s{outline[i], outline[(i + 1) % outline.size()], std::clamp(shortest / 3, 3.0, 20.0)};
    const ModelFit f = MeasureEdgeModel(linear, s);
    if (std::getenv("CAPTURE_MEASURE_VERBOSE")) std::printf("  side %zu: r %.3f offset %.3f ok %d rms %.3f step %.3f psf %s\n", i, f.r_px, f.offset_px, f.ok, f.rms_rel, f.step, f.psf.c_str());
    fits.Add(f);
  }
  return fits;
}

// The outline's radius from `c` along direction `angle` (ray-polygon intersection).
double RadiusAt(const std::vector<cv::Point2d>& poly, cv::Point2d c, double angle) {
  const cv::Point2d d(std::cos(angle), std::sin(angle));
  double best = 0;
  for (size_t i = 0; i < poly.size(); ++i) {
    const cv::Point2d a = poly[i] - c, b = poly[(i + 1) % poly.size()] - c, e = b - a;
    const double den = d.x * e.y - d.y * e.x;
    if (std::abs(den) < 1e-12) continue;
    const double t = (a.x * e.y - a.y * e.x) / den, u = (a.x * d.y - a.y * d.x) / den;
    if (t > 0 && u >= 0 && u <= 1) best = std::max(best, t);
  }
  return best;
}

Fits MeasureBall(const cv::Mat& linear, const std::vector<cv::Point2d>& outline) {
  Fits fits;
  cv::Point2d c(0, 0);
  for (const auto& p : outline) c += p;
  c *= 1.0 / double(outline.size());
  const double r0 = RadiusAt(outline, c, 0);
  const int half = int(std::clamp(r0 / 2.5, 4.0, 10.0));
  const int rows = std::max(256, int(std::lround(4 * M_PI * r0)));  // about half a px of rim per row
  cv::Mat map_x(rows, 2 * half + 1, CV_32F), map_y(rows, 2 * half + 1, CV_32F);
  for (int k = 0; k < rows; ++k) {
    const double angle = 2 * M_PI * k / rows, r = RadiusAt(outline, c, angle);
    for (int j = 0; j < 2 * half + 1; ++j) {
      const double rho = r + (j - half);  // column `half` is the outline
      map_x.at<float>(k, j) = float(c.x + rho * std::cos(angle));
      map_y.at<float>(k, j) = float(c.y + rho * std::sin(angle));
    }
  }
  cv::Mat rectified;
  cv::remap(linear, rectified, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  for (int sector = 0; sector < 8; ++sector) {
    const double k0 = rows * sector / 8.0, k1 = rows * (sector + 1) / 8.0 - 1;
    const ModelFit f = MeasureEdgeModel(rectified, EdgeSegment{{double(half), k0}, {double(half), k1}, double(half - 1)});
    if (std::getenv("CAPTURE_MEASURE_VERBOSE")) {
      std::printf("  sector %d: r %.3f offset %.3f ok %d rms %.3f step %.3f", sector, f.r_px, f.offset_px, f.ok, f.rms_rel, f.step);
      for (const auto& flag : f.flags) std::printf(" %s", flag.c_str());
      std::printf("\n");
    }
    fits.Add(f);
  }
  return fits;
}

// An analytic edge: a straight step at `angle` through the image centre, blurred by a Gaussian of std r / 2 and
// integrated over each pixel's area (8 x 8 subsamples), between 0.2 and 0.8 linear.
cv::Mat AnalyticEdge(double r, double angle, cv::Point2d* a, cv::Point2d* b) {
  const int n = 64;
  cv::Mat img(n, n, CV_32F);
  const cv::Point2d c(n / 2.0 - 0.3, n / 2.0 + 0.2), d(std::cos(angle), std::sin(angle)), normal(-d.y, d.x);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      double v = 0;
      for (int j = 0; j < 8; ++j)
        for (int i = 0; i < 8; ++i) {
          const cv::Point2d p(x - 0.5 + (i + 0.5) / 8, y - 0.5 + (j + 0.5) / 8);
          const double t = (p - c).dot(normal);
          v += r > 0 ? 0.5 * std::erfc(-t / (r / 2) / std::sqrt(2.0)) : (t > 0 ? 1 : 0);
        }
      img.at<float>(y, x) = float(0.2 + 0.6 * v / 64);
    }
  *a = c - 20 * d, *b = c + 20 * d;
  return img;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 2 && std::string(argv[1]) == "--self-check") {
    // The edge fit on analytic edges: how far it is from the truth at the radii a screen shows.
    for (double r : {0.0, 0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0}) {
      std::printf("r %.2f:", r);
      for (double angle : {0.0, 0.3, 0.78}) {
        cv::Point2d a, b;
        const cv::Mat img = AnalyticEdge(r, angle, &a, &b);
        const ModelFit f = MeasureEdgeModel(img, EdgeSegment{a, b, 8});
        std::printf("  %.3f%s", f.r_px, f.ok ? "" : "!");
      }
      std::printf("\n");
    }
    return 0;
  }
  if (argc < 2) {
    std::fprintf(stderr, "usage: capture_measure DIR [--tolerance-px X] [--tolerance-rel X] [--place-px X] [--place-only]\n");
    return 2;
  }
  double tol_px = 0.25, tol_rel = 0.05, place_px = 1.0;
  std::filesystem::path sharp_dir;
  bool place_only = false;  // --place-only: the blur is printed, not judged (below a screen px the fit scatters)
  for (int i = 2; i < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--place-only") {
      place_only = true;
      --i;
      continue;
    }
    if (i + 1 >= argc) return std::fprintf(stderr, "flag %s needs a value\n", flag.c_str()), 2;
    if (flag == "--sharp") {
      sharp_dir = argv[i + 1];
      continue;
    }
    const double v = std::stod(argv[i + 1]);
    if (flag == "--tolerance-px") tol_px = v;
    else if (flag == "--tolerance-rel") tol_rel = v;
    else if (flag == "--place-px") place_px = v;
    else return std::fprintf(stderr, "unknown flag %s\n", flag.c_str()), 2;
  }
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(argv[1]))
    if (e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  int objects = 0, bad = 0;
  double worst_blur = 0, worst_place = 0;
  auto linear_of = [](const std::filesystem::path& json) {
    const cv::Mat bgr = blurcue::ReadImage(std::filesystem::path(json).replace_extension(".png"), 1);
    cv::Mat linear;
    cv::cvtColor(blurcue::DecodeSrgb8(bgr), linear, cv::COLOR_BGR2GRAY);
    return linear;
  };
  auto measure = [](const cv::Mat& linear, const Json& o) {
    std::vector<cv::Point2d> outline;
    for (const Json& p : o["outline_px"]) outline.emplace_back(p[0].get<double>(), p[1].get<double>());
    return o["kind"] == "card" ? MeasureCard(linear, outline) : MeasureBall(linear, outline);
  };
  for (const auto& file : files) {
    const Json frame = blurcue::ParseJson(blurcue::ReadTextFile(file), file.string());
    const cv::Mat linear = linear_of(file);
    // --sharp: the same frames drawn without blur; each segment's blur is then taken in quadrature against its
    // sharp twin, which removes what the object's own shading and the pixel grid add to its edge.
    Json sharp_frame;
    cv::Mat sharp_linear;
    if (!sharp_dir.empty()) {
      sharp_frame = blurcue::ParseJson(blurcue::ReadTextFile(sharp_dir / file.filename()), file.string());
      sharp_linear = linear_of(sharp_dir / file.filename());
    }
    for (size_t k = 0; k < frame["objects"].size(); ++k) {
      const Json& o = frame["objects"][k];
      Fits fits = measure(linear, o);
      if (!sharp_dir.empty()) {
        const Fits sharp = measure(sharp_linear, sharp_frame["objects"][k]);
        for (size_t i = 0; i < fits.r.size(); ++i)
          fits.r[i] = std::isnan(fits.r[i]) || std::isnan(sharp.r[i])  // unusable in either: unusable
                          ? NAN
                          : std::sqrt(std::max(0.0, fits.r[i] * fits.r[i] - sharp.r[i] * sharp.r[i]));
      }
      const double recorded = o["r_screen_px"].get<double>();
      ++objects;
      const double measured = Median(fits.r);
      if (std::isnan(measured)) {
        std::printf("%s %s %s: recorded %.3f px, no usable edge  BAD\n", file.filename().c_str(),
                    o["side"].get<std::string>().c_str(), o["kind"].get<std::string>().c_str(), recorded);
        ++bad;
        continue;
      }
      // Place: a card's worst side; a ball's median sector (its shaded underside meets the table at low contrast,
      // where the fitted edge wanders).
      size_t usable = 0;
      double place = 0;
      std::vector<double> offsets;
      for (size_t i = 0; i < fits.r.size(); ++i)
        if (!std::isnan(fits.r[i])) ++usable, place = std::max(place, std::abs(fits.offset[i])),
                                    offsets.push_back(std::abs(fits.offset[i]));
      if (o["kind"] == "ball") place = Median(offsets);
      const double allowed = std::max(tol_px, tol_rel * recorded);
      const bool ok = (place_only || std::abs(measured - recorded) <= allowed) && place <= place_px;
      worst_blur = std::max(worst_blur, std::abs(measured - recorded));
      worst_place = std::max(worst_place, place);
      bad += !ok;
      std::printf("%s %s %s: recorded %.3f px, measured %.3f px (%zu edges), off %+.3f px (allowed %.3f), edge within "
                  "%.3f px of the outline%s\n",
                  file.filename().c_str(), o["side"].get<std::string>().c_str(), o["kind"].get<std::string>().c_str(),
                  recorded, measured, usable, measured - recorded, allowed, place, ok ? "" : "  BAD");
    }
  }
  std::printf("%s: %d objects in %zu frames, %d off; worst blur difference %.3f px, worst place %.3f px\n", argv[1],
              objects, files.size(), bad, worst_blur, worst_place);
  return bad == 0 && objects > 0 ? 0 : 1;
}
