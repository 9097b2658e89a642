#include "calib/calibrate.h"

#include "calib/calib_checks.h"
#include "calib/phase_flags.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "core/distortion.h"
#include "core/error.h"
#include "core/image.h"
#include "optics/thin_lens.h"

namespace blurcue::calib {
namespace {

double MsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

cv::Mat LinearGrey(const cv::Mat& photo) {
  cv::Mat linear;
  LinearGrey(photo, linear);
  return linear;
}

void LinearGrey(const cv::Mat& photo, cv::Mat& linear) {
  CV_Assert(photo.depth() == CV_8U);
  // One fused pass (decode each channel by table, then mix with Rec. 601 weights as cv::cvtColor does): a 14 MP
  // photo never becomes a 3-channel float image, which alone took most of a second.
  const std::array<float, 256>& lut = SrgbDecodeTable();
  const int step = photo.channels();
  linear.create(photo.size(), CV_32F);
  // Rows are independent: split among the cores (a video frame's few milliseconds matter in `track`).
  cv::parallel_for_(cv::Range(0, photo.rows), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      const uint8_t* p = photo.ptr<uint8_t>(y);
      float* g = linear.ptr<float>(y);
      if (step == 1) {
        for (int x = 0; x < photo.cols; ++x) g[x] = lut[p[x]];
      } else {
        for (int x = 0; x < photo.cols; ++x, p += step)
          g[x] = 0.114f * lut[p[0]] + 0.587f * lut[p[1]] + 0.299f * lut[p[2]];
      }
    }
  }, 8);
}

void PhotoPlanes::Fill(const cv::Mat& photo) {
  ToGrey8(photo, grey8);
  LinearGrey(photo, linear);
}

bool InModel(const SectionResult& s) { return s.fit.ok || s.phase.joins_fit; }

std::vector<optics::BlurSample> ModelSamples(const CalibResult& result, double filter_variance_px2) {
  const double v = std::min(0.0, filter_variance_px2);
  std::vector<optics::BlurSample> samples;
  for (const auto& edge : result.edges)
    for (const auto& s : edge.sections)
      if (InModel(s))
        samples.push_back({s.u_mm, (v < 0 ? std::sqrt(s.fit.r_px * s.fit.r_px - 4 * v) : s.fit.r_px) / s.stretch, 1.0});
  return samples;
}

const std::vector<std::string>& InformationalFlags() {
  // Informational flags never disqualify a section (edge_blur.h).
  static const std::vector<std::string> kInformational = {"flaw", "neighbours", "short", "junctions"};
  return kInformational;
}

std::string SectionFlagMeaning(const std::string& flag) {
  static const std::map<std::string, std::string> kMeaning = {
      {"low_contrast", "the step across the edge is too faint to measure (shade, glare)"},
      {"saturated", "too many of its pixels are clipped at white or black"},
      {"crowded", "its blur reaches the next edges or the X-junctions where no model of them holds"},
      {"poor_fit", "the blur model fits its profile worse than 8 % of the step (a smudge, a reflection, a fold)"},
      {"too_few_pixels", "too few pixels across or along it"},
      {"phase_limited", "its blur is not identified where its edge falls between pixel rows (the phase check)"},
      {"not measured", "no blur was read there"},
      {"flaw", "printing spots near the edge, left out of the profile (the section is used)"},
      {"neighbours", "measured across the neighbouring edges, their steps in the model (used)"},
      {"short", "read on a shorter central part, to keep the X-junctions out of its blur (used)"},
      {"junctions", "the X-junctions within its blur's reach, modelled (used)"}};
  const auto it = kMeaning.find(flag);
  return it == kMeaning.end() ? std::string() : it->second;
}

std::map<std::string, int> SectionsLeftOut(const CalibResult& result) {
  const std::vector<std::string>& kInformational = InformationalFlags();
  std::map<std::string, int> out;
  for (const auto& edge : result.edges)
    for (const auto& s : edge.sections) {
      if (InModel(s)) continue;
      std::string why = "not measured";
      for (const std::string& flag : s.fit.flags)
        if (std::find(kInformational.begin(), kInformational.end(), flag) == kInformational.end()) {
          why = flag;
          break;
        }
      ++out[why];
    }
  return out;
}

namespace {
// The thin lens's radius is unsigned: sections at two depths fit a focus between them and one beyond them alike
// (an overexposed photo that leaves the first and last edges only gave focus 140 mm for 400 and an aperture 7 x off).
// Three edges with a usable section are the least a model is fitted to; fewer is refused, saying why the others
// were not usable.
void RequireThreeDepths(const CalibResult& result) {
  std::vector<int> usable;
  std::map<std::string, int> why;  // the flags of the unusable edges' sections (a section may carry two)
  for (const auto& edge : result.edges) {
    bool any = false;
    for (const auto& s : edge.sections) any = any || InModel(s);
    if (any) {
      usable.push_back(edge.index);
      continue;
    }
    for (const auto& s : edge.sections)
      for (const std::string& flag : s.fit.flags) ++why[flag];
  }
  if (usable.size() >= 3) return;
  std::string edges, flags;
  for (const int e : usable) edges += (edges.empty() ? "" : " and ") + std::to_string(e);
  std::vector<std::pair<int, std::string>> common;
  for (const auto& [flag, n] : why) common.push_back({-n, flag});
  std::sort(common.begin(), common.end());
  for (size_t i = 0; i < common.size() && i < 3; ++i)
    flags += (i ? ", " : "") + common[i].second + " (" + std::to_string(-common[i].first) + " sections)";
  // A pose that fits the corners only to a pixel or more says the camera is not the photo's (a focal length of 50 mm
  // for 21 left 2 edges usable): that is named, as calibrate's other refusals of an absurd calibration name it.
  if (result.pose.reprojection_error_px > kPoseSuspectPx)
    throw InputError("/focal_length_mm", PoseSuspectText(result, "") + "; only " + std::to_string(usable.size()) +
                                             " of " + std::to_string(result.edges.size()) +
                                             " edges have a usable section: is this camera.json the photo's (focal "
                                             "length, sensor size, dist_coeffs)?");
  throw Error(ErrorKind::kNotFound,
              (usable.empty() ? "none of the " + std::to_string(result.edges.size()) + " edges has"
                              : "only " + std::to_string(usable.size()) + " of " + std::to_string(result.edges.size()) +
                                    (usable.size() == 1 ? " edges has" : " edges have")) +
                  " a usable section" + (edges.empty() ? "" : " (edge " + edges + ")") +
                  (flags.empty() ? ""
                                 : (usable.empty() ? "; their" : "; the others'") + std::string(" sections are flagged ") +
                                       flags) +
                  ": a thin lens needs sections at 3 or more depths (at 2 a focus between them and one beyond "
                  "them fit alike); retake the photo so that more of the board's edges are measured (exposure, "
                  "framing, focus)");
}
// The reference edge's depth and blur for eq. 3.7: the medians over its usable sections (the median resists a flawed
// section; the thesis averaged its 7 sections). Error(kNotFound) when it has none.
void SetReference(CalibResult& result, int reference_edge) {
  const EdgeResult& ref = result.edges[reference_edge - 1];
  std::vector<double> ref_r, ref_u;
  for (const auto& s : ref.sections)
    if (InModel(s)) ref_r.push_back(s.fit.r_px), ref_u.push_back(s.u_mm);
  // (Sections flagged but joined to the lens fit at their readings are pooled here as there.) A reference edge whose
  // every section is phase_limited still has its readings (eq. 3.7 is the thesis's estimate from them, whatever their
  // family): taken rather than refusing the photo.
  if (ref_r.empty())
    for (const auto& s : ref.sections)
      if (!s.fit.phase_why.empty()) ref_r.push_back(s.fit.r_px), ref_u.push_back(s.u_mm);
  if (ref_r.empty())
    throw Error(ErrorKind::kNotFound, "reference edge " + std::to_string(reference_edge) +
                                          " has no usable section (all flagged); choose another --reference-edge");
  result.reference_r_px = Median(ref_r);
  result.reference_u_mm = Median(ref_u);
}

// Sections sampled at few phases with blur near or below a pixel: read once per PSF family that could fit them
// (phase_check.h), each on its own (on every core, as the blur fit).
void CheckPhases(CalibResult& result, const cv::Mat& linear, const CalibrateOptions& options) {
  ReadPhaseFamilies(result, linear, options.model_fit, options.parallel_sections);
}

}  // namespace

void ApplyModel(CalibResult& result, const optics::FittedModel& model) {
  const optics::Lens lens = optics::Lens::FromCamera(result.camera);
  result.model = model;
  for (auto& edge : result.edges) {
    edge.r_fitted_px = 0;
    for (auto& s : edge.sections) {
      s.r_fitted_px = model.PredictPx(lens, s.u_mm) * s.stretch;
      edge.r_fitted_px += s.r_fitted_px;
    }
    if (!edge.sections.empty()) edge.r_fitted_px /= double(edge.sections.size());
  }
}

CalibResult Calibrate(const cv::Mat& photo, const Camera& camera, const Board& board,
                      const CalibrateOptions& options) {
  PhotoPlanes planes;
  planes.Fill(photo);
  return Calibrate(planes, camera, board, options);
}

namespace {

// Geometry of every section: end points in the photo and 3-D midpoint, its sampling window, its neighbouring
// edges' sections and the distortion's stretch across it - result->edges from result->pose.
void PlaceSections(CalibResult* out, const Camera& camera, const Board& board) {
  CalibResult& result = *out;
  const int E = board.EdgeCount(), S = board.SectionCount();
  // Per section: start, end, midpoint, and a point a tenth of a square along the board line crossing the edge at
  // the start and at the end (their directions in the photo shape the sampling window, edge_blur.h).
  constexpr int kPoints = 5;
  std::vector<std::array<double, 3>> points;
  const double step_mm = 0.1 * board.square_mm;
  for (int e = 1; e <= E; ++e)
    for (int s = 1; s <= S; ++s) {
      const std::array<double, 3> a = board.SectionStart(e, s), b = board.SectionEnd(e, s);
      points.push_back(a);
      points.push_back(b);
      points.push_back(board.SectionMidpoint(e, s));
      points.push_back({a[0], a[1] + step_mm, a[2]});
      points.push_back({b[0], b[1] + step_mm, b[2]});
    }
  const std::vector<cv::Point2d> px = Project(result.pose, camera, points);
  auto mid_px = [&](int e, int s) { return px[((e - 1) * S + (s - 1)) * kPoints + 2]; };
  // The same points through the pinhole alone (ideal px): there the edge is straight, and the distortion's Jacobian
  // at its midpoint says how the photo stretches a blur across it.
  const LensDistortion distortion(camera);
  Camera pinhole = camera;
  pinhole.dist_coeffs.clear();
  const std::vector<cv::Point2d> ideal = distortion.Identity() ? px : Project(result.pose, pinhole, points);

  for (int e = 1; e <= E; ++e) {
    EdgeResult edge;
    edge.index = e;
    for (int s = 1; s <= S; ++s) {
      const size_t i = ((e - 1) * S + (s - 1)) * kPoints;
      SectionResult sec;
      sec.edge = e;
      sec.section = s;
      sec.midpoint_camera_mm = ToCamera(result.pose, points[i + 2]);
      sec.u_mm = sec.midpoint_camera_mm[2];
      // Half the distance to the nearest parallel edge in the photo bounds how far across the edge we may look.
      const cv::Point2d m = px[i + 2];
      double gap = 1e9;
      if (e > 1) gap = std::min(gap, cv::norm(m - mid_px(e - 1, s)));
      if (e < E) gap = std::min(gap, cv::norm(m - mid_px(e + 1, s)));
      sec.segment = EdgeSegment{px[i], px[i + 1], 0.5 * gap};
      sec.segment.cross_a = px[i + 3] - px[i];
      sec.segment.cross_b = px[i + 4] - px[i + 1];
      // The same section of the parallel edges either side: where the blur reaches them, their steps are modelled.
      // Past the board's outer edge the image is taken to be free of edges for half a gap, as the plain window does.
      for (const int k : {e - 1, e + 1}) {
        if (k < 1 || k > E) continue;
        const size_t j = ((k - 1) * S + (s - 1)) * kPoints;
        const int next = k + (k - e);
        const double beyond = next >= 1 && next <= E ? cv::norm(mid_px(k, s) - mid_px(next, s))
                                                     : cv::norm(mid_px(k, s) - m);
        sec.segment.neighbours.push_back({px[j], px[j + 1], 0.5 * beyond});
      }
      if (!distortion.Identity()) {
        const cv::Point2d a = ideal[i], b = ideal[i + 1], mid = ideal[i + 2];
        sec.stretch = distortion.StretchAcross({mid.x, mid.y}, {a.y - b.y, b.x - a.x});
        // The photo's edge bows away from the chord between its ends: by this much at the midpoint, along the
        // chord's normal (edge_blur.h).
        const cv::Point2d chord = px[i + 1] - px[i];
        const double len = cv::norm(chord);
        if (len > 0) sec.segment.bow_px = (m - 0.5 * (px[i] + px[i + 1])).dot(cv::Point2d(-chord.y, chord.x) / len);
      }
      edge.sections.push_back(sec);
    }
    result.edges.push_back(std::move(edge));
  }
}

// Every section (or options.only_sections) measured on every core, then the ones read across a neighbouring edge
// measured again with that neighbour's own blur.
void MeasureSections(CalibResult* out, const PhotoPlanes& planes, const Board& board,
                     const CalibrateOptions& options) {
  CalibResult& result = *out;
  const cv::Mat& linear = planes.linear;
  const cv::Mat& grey8 = planes.grey8;
  const int E = board.EdgeCount(), S = board.SectionCount();
  // Each section's measurement reads the photo and writes only its own result, so measured on every core (OpenCV's
  // thread pool, made once per process) the numbers are the serial ones; one stripe a section balances their
  // unequal costs.
  std::vector<int> order;
  if (options.only_sections.empty())
    for (int k = 0; k < E * S; ++k) order.push_back(k);
  for (const int k : options.only_sections)
    if (k >= 0 && k < E * S) order.push_back(k);
  const int measured = int(order.size());
  auto measure = [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      const int k = order[i];
      SectionResult& sec = result.edges[k / S].sections[k % S];
      sec.fit = MeasureEdgeModel(linear, sec.segment, options.model_fit);
      sec.thesis = MeasureEdgeThesis(grey8, sec.segment, options.thesis);
    }
  };
  if (options.parallel_sections && measured > 1) cv::parallel_for_(cv::Range(0, measured), measure, measured);
  else measure(cv::Range(0, measured));
  // A section measured across its neighbouring edges took their blur for its own; measured again with each
  // neighbour's own measured blur (where usable; edge by edge, so a neighbour measured again already counts), since
  // their depths differ by a square's.
  // The sections of one edge are independent of each other: measured again on every core, edge after edge.
  for (int e = 1; e <= E; ++e) {
    auto again = [&](const cv::Range& range) {
      for (int s = range.start + 1; s <= range.end; ++s) {
        SectionResult& sec = result.edges[e - 1].sections[s - 1];
        const auto& flags = sec.fit.flags;
        if (std::find(flags.begin(), flags.end(), "neighbours") == flags.end()) continue;
        size_t n = 0;
        for (const int k : {e - 1, e + 1}) {  // the order they were listed in above
          if (k < 1 || k > E || n >= sec.segment.neighbours.size()) continue;
          const ModelFit& other = result.edges[k - 1].sections[s - 1].fit;
          sec.segment.neighbours[n++].r_px = other.ok ? other.r_px : 0;
        }
        sec.fit = MeasureEdgeModel(linear, sec.segment, options.model_fit);
      }
    };
    if (options.parallel_sections) cv::parallel_for_(cv::Range(0, S), again, S);
    else again(cv::Range(0, S));
  }
}

// Each section's eq. 3.7 estimate from the reference, and each edge's means over its usable sections.
void SummariseEdges(CalibResult* out, const optics::Lens& lens) {
  CalibResult& result = *out;
  for (auto& edge : result.edges) {
    double su = 0;
    for (auto& s : edge.sections) {
      su += s.u_mm;
      if (result.reference_u_mm <= 0) {
        s.estimated_note = "no reference: its edge was not measured in this frame";
      } else {
        try {
          s.r_estimated_px = optics::Eq37Px(lens, result.reference_u_mm, result.reference_r_px, s.u_mm);
        } catch (const Error& e) {
          if (e.kind() != ErrorKind::kDomain) throw;
          s.estimated_note = e.what();
        }
      }
      // The edge's measured value is what blur source `measured` draws (scene_blur.cc): the mean over its usable
      // sections and those pooled into the lens fit (phase.joins_fit). Eq. 3.7 needs only a section's depth.
      if (s.fit.ok) ++edge.usable, edge.r_thesis_px += s.thesis.r_px;
      if (InModel(s)) ++edge.measured, edge.r_px += s.fit.r_px;
      if (s.r_estimated_px) ++edge.estimated, edge.r_estimated_px += *s.r_estimated_px;
    }
    edge.u_mm = su / edge.sections.size();
    if (edge.usable > 0) edge.r_thesis_px /= edge.usable;
    if (edge.measured > 0) edge.r_px /= edge.measured;
    if (edge.estimated > 0) edge.r_estimated_px /= edge.estimated;
  }
}

}  // namespace

CalibResult Calibrate(const PhotoPlanes& planes, const Camera& camera, const Board& board,
                      const CalibrateOptions& options) {
  const cv::Mat& photo = planes.grey8;
  if (photo.cols != camera.image_width_px || photo.rows != camera.image_height_px)
    throw InputError("camera /image_width_px, /image_height_px",
                     "say " + std::to_string(camera.image_width_px) + "x" + std::to_string(camera.image_height_px) +
                         " but the photo is " + std::to_string(photo.cols) + "x" + std::to_string(photo.rows));
  if (options.reference_edge < 1 || options.reference_edge > board.EdgeCount())
    throw Error(ErrorKind::kUsage, "--reference-edge must be 1.." + std::to_string(board.EdgeCount()) + ", got " +
                                       std::to_string(options.reference_edge));
  CalibResult result;
  result.camera = camera;
  result.board = board;
  result.reference_edge = options.reference_edge;

  auto t0 = std::chrono::steady_clock::now();
  result.pose = options.known_pose ? *options.known_pose : FindBoardPose(photo, camera, board, options.detect);
  result.detect_ms = MsSince(t0);

  // Geometry of every section, then its measurement.
  t0 = std::chrono::steady_clock::now();
  PlaceSections(&result, camera, board);
  MeasureSections(&result, planes, board, options);
  if (options.phase_check && options.fit_model) CheckPhases(result, planes.linear, options);
  result.measure_ms = MsSince(t0);

  // Estimation: eq. 3.7 from the reference edge, and a thin-lens model fitted to every usable section.
  t0 = std::chrono::steady_clock::now();
  const optics::Lens lens = optics::Lens::FromCamera(camera);
  // The sections at other phases choose the PSF family; a section it leaves open is flagged and predicted.
  if (options.fit_model && options.phase_check) result.phase = ChoosePhaseFamily(result);
  if (options.fit_model) RequireThreeDepths(result);  // before the reference: with no usable edge, say why
  // A subset (a live view's few sections a frame) leaves the reference edge unmeasured most frames: no reference then.
  if (options.only_sections.empty()) SetReference(result, options.reference_edge);

  optics::FittedModel optics_model;
  if (options.fit_model)
    result.model = FitModelWithinPhaseRanges(result, lens, options.optics_fit, &result.phase.held, &optics_model);

  if (options.fit_model) ApplyModel(result, result.model);
  // Every photo: near focus the profiles pin a small blur least (a sharp step at one phase reads alike from 0 to
  // about 0.3 px), and where a mask sharpens, it magnifies the optics' own error there.
  if (options.fit_model)
    PropagateModelError(result, lens, optics_model, ValleyModels(result, lens, options.optics_fit));
  if (options.fit_model && options.phase_check && options.only_sections.empty()) FlagOffTheLensFit(result);
  SummariseEdges(&result, lens);
  result.estimate_ms = MsSince(t0);
  return result;
}

namespace {

Json PhaseCheckJson(const PhaseCheck& p) {
  Json readings = Json::array();
  for (const PhaseReading& f : p.families) {
    readings.push_back({{"r_px", f.r_px}, {"offset_px", f.offset_px}, {"rms_rel", f.rms_rel}, {"chi2", f.chi2}});
    if (std::isfinite(f.r_table_px)) readings.back()["r_table_px"] = f.r_table_px;  // on the board's outer edge
    if (std::isfinite(f.r_se_px)) readings.back()["r_se_px"] = f.r_se_px;
  }
  Json j = {{"axis_deg", p.axis_deg}, {"span_px", p.span_px}, {"every_phase", p.every_phase}, {"phase_px", p.phase_px},
            {"noise", p.noise}, {"bins", p.bins}, {"range_px", {p.range_lo_px, p.range_hi_px}}, {"joins_fit", p.joins_fit},
            {"bound", p.bound}, {"families", readings}};
  if (std::isfinite(p.valley_r_px[0]) && std::isfinite(p.valley_r_px[1]))  // the chosen mask's valley ends' readings
    j["valley_r_px"] = {p.valley_r_px[0], p.valley_r_px[1]};
  return j;
}

Json PhaseChoiceJson(const PhaseChoice& c) {
  Json families = Json::array();
  for (size_t i = 0; i < c.chi2.size(); ++i)
    families.push_back({{"post_sigma_px", c.families[i].sigma_px}, {"sharpen", c.families[i].sharpen},
                        {"fitted", c.families[i].fitted}, {"chi2", c.chi2[i]}, {"alike", bool(c.alike[i])}});
  return {{"limited_sections", c.limited}, {"every_phase_sections", c.every_phase}, {"flagged", c.flagged},
          {"held_the_model", c.held},
          {"chosen", c.limited + c.every_phase > 0 ? Json(c.families[c.chosen].Name()) : Json(nullptr)},
          {"chi2_per_point", c.chi2_per_point}, {"variance_px2", c.variance_px2}, {"families", families},
          {"summary", c.summary},
          {"note", "sections along the pixel rows or columns with blur under 2 px are read once per PSF family "
                   "(the optics, then on the sampled image a Gaussian of post_sigma_px or an unsharp mask of that std "
                   "and amount `sharpen`; each section's phase.families in that order) with the edge where the pose "
                   "puts it; the family whose profiles fit best over all of them (their edges at other phases) is "
                   "taken, and "
                   "a section whose reading moves by more than max(0.04 px, 8 %) among the families that fit alike "
                   "(or under a sharpening that cancels most of the optics' blur, or that jumps outside its "
                   "neighbouring families' readings, or, at few phases, between the masks at the ends of a refined "
                   "mask's valley, valley_r_px) is flagged phase_limited (phase_why says which) and predicted "
                   "by the lens fit; with the optics alone, one whose reading's standard error (r_se_px) exceeds "
                   "2 % (an edge near a pixel centre) is flagged too; it is left out of that fit but for those "
                   "flagged by the cancellation, the valley or the standard error alone (phase.joins_fit), which "
                   "join it at their readings; on the board's outer edges each family is read again with the table's slope "
                   "(r_table_px) and, where a filter is chosen, a section whose two readings differ by that much is "
                   "flagged too, as is one (after the lens fit) whose reading lies off the fit's prediction by more "
                   "than that less the prediction's standard error (the table's texture); sections of 2 px or more "
                   "are read with the chosen filter"}};
}

}  // namespace

Json CalibToJson(const CalibResult& r) {
  auto vec = [](const cv::Vec3d& v) { return Json::array({v[0], v[1], v[2]}); };
  auto opt = [](const std::optional<double>& v) { return v ? Json(*v) : Json(nullptr); };
  const bool distorted = !LensDistortion(r.camera).Identity();
  Json edges = Json::array();
  for (const auto& e : r.edges) {
    Json sections = Json::array();
    for (const auto& s : e.sections) {
      Json js = {{"index", s.section},
                 {"u_mm", s.u_mm},
                 {"midpoint_camera_mm", vec(s.midpoint_camera_mm)},
                 {"image_px", {{s.segment.a.x, s.segment.a.y}, {s.segment.b.x, s.segment.b.y}}},
                 {"r_px", s.fit.r_px},
                 {"r_thesis_px", s.thesis.r_px},
                 {"r_estimated_px", opt(s.r_estimated_px)},
                 {"r_fitted_px", s.r_fitted_px},
                 {"ok", s.fit.ok},
                 {"flags", s.fit.flags},
                 {"psf", s.fit.psf},
                 {"disc_r_px", s.fit.disc_r_px},
                 {"floor_sigma_px", s.fit.floor_sigma_px},
                 {"shape_ambiguous", s.fit.shape_ambiguous},
                 {"fit_rms_rel", s.fit.rms_rel},
                 {"step_linear", s.fit.step},
                 {"thesis_ok", s.thesis.ok}};
      if (!s.estimated_note.empty()) js["r_estimated_note"] = s.estimated_note;
      if (!s.fit.crowded_why.empty()) js["crowded_why"] = s.fit.crowded_why;
      if (s.fit.r_se_px > 0 && std::isfinite(s.fit.r_se_px)) js["r_se_px"] = s.fit.r_se_px;
      if (s.r_fitted_se_px > 0) js["r_fitted_se_px"] = s.r_fitted_se_px;
      if (!s.fit.phase_why.empty()) js["phase_why"] = s.fit.phase_why;
      if (s.phase.limited || s.phase.every_phase) js["phase"] = PhaseCheckJson(s.phase);
      if (distorted) js["stretch"] = s.stretch;
      sections.push_back(js);
    }
    edges.push_back({{"index", e.index}, {"u_mm", e.u_mm}, {"usable_sections", e.usable}, {"sections", sections}});
  }
  const auto& m = r.model;
  // The model choice (DESIGN.md: the simplest model whose held-out error is within target): both candidates'
  // errors against the measured sections, and eq. 3.7 (as published, from the reference edge) beside them.
  auto number_or_note = [](double v) { return std::isfinite(v) ? Json(v) : Json("not determined (not fitted)"); };
  double eq37_sum = 0;
  int eq37_n = 0;
  for (const auto& e : r.edges)
    for (const auto& s : e.sections)
      if (s.fit.ok && s.r_estimated_px) eq37_sum += std::pow(*s.r_estimated_px - s.fit.r_px, 2), ++eq37_n;
  const Json choice = {
      {"chosen", m.kind},
      {"rule", optics::kModelChoiceRule},
      {"thin_lens", {{"rms_px", m.thin_rms_px}, {"loo_rms_px", m.thin_loo_rms_px}}},
      {"thin_lens+floor", {{"rms_px", number_or_note(m.floor_rms_px)}, {"loo_rms_px", number_or_note(m.floor_loo_rms_px)},
                           {"floor_px", number_or_note(m.floor_candidate_px)},
                           {"floor_range_px", std::isfinite(m.floor_lo_px) ? Json::array({m.floor_lo_px, m.floor_hi_px})
                                                                            : Json("not determined (not fitted)")}}},
      {"eq37", {{"rms_px", eq37_n > 0 ? Json(std::sqrt(eq37_sum / eq37_n)) : Json("not determined (no section)")},
                {"sections", eq37_n},
                {"note", "eq. 3.7 as published, from the reference edge; no parameters fitted, error against the "
                         "measured sections"}}}};
  return {
      {"format", "blurcue-calib"},
      {"version", 1},
      {"software", std::string("blurcue ") + BLURCUE_VERSION},
      {"camera", CameraToJson(r.camera)},
      {"board", {{"cols", r.board.cols}, {"rows", r.board.rows}, {"square_mm", r.board.square_mm}}},
      {"pose", {{"rvec", vec(r.pose.rvec)}, {"tvec", vec(r.pose.tvec)},
                {"reprojection_error_px", r.pose.reprojection_error_px}}},
      {"reference_edge", r.reference_edge},
      {"reference", {{"u_mm", r.reference_u_mm}, {"r_px", r.reference_r_px}}},
      {"model", {{"kind", m.kind}, {"focus_mm", std::isinf(m.focus_mm) ? Json("infinity") : Json(m.focus_mm)},
                 {"aperture_mm", m.aperture_mm}, {"floor_px", m.floor_px}, {"cancel_px2", m.cancel_px2},
                 // floor_px stays a number (the model predicts with it); whether the sections pin it is said here.
                 {"floor_determined", m.floor_determined}, {"rms_px", m.rms_px},
                 {"loo_rms_px", m.loo_rms_px}, {"samples_used", m.samples_used}, {"outliers", m.outliers},
                 {"sections_left_out", SectionsLeftOut(r)},
                 {"undetermined", !r.undetermined.Named() ? Json(nullptr)
                                                          : Json({{"u_mm", {r.undetermined.lo_mm, r.undetermined.hi_mm}},
                                                                  {"worst_se_rel", r.undetermined.worst_se_rel},
                                                                  {"why", r.undetermined.why}})},
                 {"choice", choice},
                 {"fitted_to", r.phase.variance_px2 < 0
                                   ? "the optics' readings sqrt(r_px^2 - 4 phase_check.variance_px2) (a sharpening after "
                                     "sampling was chosen); floor_px and its range have the sharpening added back, "
                                     "the rms figures are the optics' px"
                                   : "r_px"}}},
      {"r_units", !distorted ? Json("px of the photo (no dist_coeffs: the photo is the pinhole image)") : Json({
           {"sections", "r_px, r_thesis_px, r_estimated_px, r_fitted_px: photo px (distorted), across the edge"},
           {"model", "floor_px and the thin lens's radius: ideal (undistorted, pinhole) px; a point's photo-px radius "
                     "is the model's times the stretch there (sections: stretch across the edge; a round blur "
                     "anywhere: sqrt(det J) of the distortion map)"}})},
      {"phase_check", PhaseChoiceJson(r.phase)},
      {"timing_ms", {{"detect", r.detect_ms}, {"measure", r.measure_ms}, {"estimate", r.estimate_ms}}},
      {"edges", edges},
  };
}

std::string FormatEdgeTable(const CalibResult& r, const std::vector<double>& true_r_per_edge) {
  const bool truth = true_r_per_edge.size() == r.edges.size();
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line, "%4s %8s %6s %9s %9s %9s %9s%s\n", "edge", "u/mm", "usable", "measured",
                "thesis", "eq3.7", "fitted", truth ? "      true" : "");
  out += line;
  for (size_t i = 0; i < r.edges.size(); ++i) {
    const EdgeResult& e = r.edges[i];
    // The model's value, in parentheses where it is not determined within 5 % (CalibResult::undetermined).
    char fitted[32] = "        -";  // without a fitted model
    if (r.model.samples_used > 0) {
      const bool unsure = r.undetermined.Inside(e.u_mm);
      char value[24];
      std::snprintf(value, sizeof value, unsure ? "(%.2f)" : "%.2f", e.r_fitted_px);
      std::snprintf(fitted, sizeof fitted, "%9s", value);
    }
    // measured: in brackets where only pooled readings give it (no usable section), '-' where nothing does (a
    // session refuses `measured` there); eq. 3.7 '-' nearer than focus, where it does not hold.
    char measured[32] = "        -", thesis[32] = "        -", est[32] = "        -";
    if (e.measured > 0) {
      char value[24];
      std::snprintf(value, sizeof value, e.usable > 0 ? "%.2f" : "[%.2f]", e.r_px);
      std::snprintf(measured, sizeof measured, "%9s", value);
    }
    if (e.usable > 0) std::snprintf(thesis, sizeof thesis, "%9.2f", e.r_thesis_px);
    if (e.estimated > 0) std::snprintf(est, sizeof est, "%9.2f", e.r_estimated_px);
    const std::string usable = std::to_string(e.usable) + "/" + std::to_string(e.sections.size());
    std::snprintf(line, sizeof line, "%4d %8.1f %6s %s %s %s %s", e.index, e.u_mm, usable.c_str(), measured, thesis,
                  est, fitted);
    out += line;
    if (truth) {
      std::snprintf(line, sizeof line, " %9.2f", true_r_per_edge[i]);
      out += line;
    }
    out += "\n";
  }
  return out;
}

}  // namespace blurcue::calib
