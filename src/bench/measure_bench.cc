#include "bench/measure_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <functional>

#include <opencv2/imgcodecs.hpp>  // its flags (the functions: core/media.h)
#include "bench/clock.h"
#include "core/media.h"

#include "calib/calibrate.h"
#include "calib/truth.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/image.h"
#include "synth/scene.h"

namespace blurcue::bench {
namespace {

using detail::Clock;
using detail::Ms;

struct Condition {
  std::string factor;
  double level;
  synth::SceneOptions scene;
  // The level is the blur radius rendered: replaced by the scene's applied truth (the median section's r_px, 2 x the
  // std of the kernels synth really applied), not the nominal sqrt(R^2 + 4 sigma^2), 12 % high at R = 0.25 px.
  bool level_is_true_r = false;
  // The level is the edges' angle to the pixel rows in the photo (the median over the sections), not the board's yaw.
  bool level_is_edge_angle = false;
  // The sections are split by their edge's sub-pixel phase (PhaseLevels): one row per phase band, not per scene.
  bool per_phase = false;
};

synth::SceneOptions Base(uint64_t seed) {
  synth::SceneOptions o;  // thesis set-up at quarter resolution
  o.noise_std = 0.004;
  o.seed = seed;
  return o;
}

// Issue 42: the post-sampling PSF family, the edge angle and the sub-pixel phase (`pick` keeps two levels in a quick
// run).
template <class Pick>
void AddSamplingConditions(uint64_t seed, const Pick& pick, std::vector<Condition>* out) {
  std::vector<Condition>& c = *out;
  // Near focus inside the board (r about 0.9-1.5 px, where they matter), noise 0.0025. A filter on the sampled image (as a camera's demosaicing and
  // sharpening): a Gaussian of std level px over a disc x 0.2 px floor, then an unsharp mask of amount level (std
  // 0.6 px) over a disc x 0.5 px floor; the truth adds the filter's taps' second moment.
  auto near_inside = [&](double floor_px) {
    auto o = Base(seed);
    o.focus_mm = 430, o.floor_sigma_px = floor_px, o.noise_std = 0.0025;
    return o;
  };
  for (double sigma : pick({0.35, 0.45, 0.6, 0.8})) {
    auto o = near_inside(0.2);
    o.post_filter.kind = synth::PostFilter::kGaussian, o.post_filter.sigma_px = sigma;
    c.push_back({"post_gaussian", sigma, o});
  }
  for (double amount : pick({0.15, 0.3, 0.5, 0.7})) {
    auto o = near_inside(0.5);
    o.post_filter.kind = synth::PostFilter::kSharpen, o.post_filter.sigma_px = 0.6, o.post_filter.amount = amount;
    c.push_back({"post_sharpen", amount, o});
  }
  // The board turned on the table (physical optics: disc x 0.45 px floor): its edges at level deg to the pixel rows.
  for (double yaw : pick({0, 10, 20, 30, 45, 60})) {
    auto o = near_inside(0.45);
    o.yaw_deg = yaw;
    Condition cond{"edge_angle", yaw, o};
    cond.level_is_edge_angle = true;
    c.push_back(cond);
  }
  // The sub-pixel phase: a level board's sections (each edge along the pixel rows, at one phase) under a Gaussian of
  // 0.45 px on the sampled image, split by how far their edge lies from the nearest pixel centre (0-0.5 px).
  {
    auto o = near_inside(0.2);
    o.post_filter.kind = synth::PostFilter::kGaussian, o.post_filter.sigma_px = 0.45;
    Condition cond{"phase", 0, o};
    cond.per_phase = true;
    c.push_back(cond);
  }
}

// One factor at a time from the base scene, in order of increasing difficulty.
std::vector<Condition> Conditions(bool quick, uint64_t seed) {
  std::vector<Condition> c;
  c.push_back({"base", 0, Base(seed)});
  auto pick = [quick](std::vector<double> levels) {
    if (quick) levels = {levels.front(), levels.back()};
    return levels;
  };
  for (double n : pick({0.0, 0.002, 0.005, 0.01, 0.02, 0.04})) {
    auto o = Base(seed);
    o.noise_std = n;
    c.push_back({"noise", n, o});
  }
  for (double m : pick({0.9, 0.5, 0.2, 0.1, 0.05, 0.02})) {  // Michelson contrast around a mean of 0.42
    auto o = Base(seed);
    o.white = 0.42 * (1 + m);
    o.black = 0.42 * (1 - m);
    c.push_back({"contrast", m, o});
  }
  for (double q : pick({95, 80, 60, 40, 20, 10})) {
    auto o = Base(seed);
    o.jpeg_quality = int(q);
    c.push_back({"jpeg", q, o});
  }
  for (double f : pick({3, 10, 25, 50})) {
    auto o = Base(seed);
    o.flaws = int(f);
    c.push_back({"flaws", f, o});
  }
  // Blur size: one radius everywhere, a steeper view and half resolution so big radii still fit between edges.
  for (double r : pick({0.5, 1, 2, 4, 8, 12, 16, 20})) {
    auto o = Base(seed);
    o.camera = ThesisCamera().Resized(2296, 1528);
    o.tilt_deg = 65;
    o.fixed_r_px = r;
    o.supersample = r >= 2 ? 2 : 4;
    c.push_back({"blur", r, o});
  }
  // The PSF family (issue 25): one radius everywhere, from a sharp edge through the near-focus range to 8 px, as a
  // pure disc, a pure Gaussian, and a disc convolved with a floor of std ratio x its radius. The level is the true r
  // (2 x the LSF's std) as rendered (Condition::level_is_true_r); nominally sqrt(R^2 + 4 (ratio R)^2).
  struct Family {
    const char* name;
    synth::Psf psf;
    double floor_ratio;
  };
  for (const Family& fam : {Family{"psf_disc", synth::Psf::kDisc, 0}, Family{"psf_gaussian", synth::Psf::kGaussian, 0},
                            Family{"psf_disc_floor_0.25", synth::Psf::kDisc, 0.25},
                            Family{"psf_disc_floor_0.5", synth::Psf::kDisc, 0.5},
                            Family{"psf_disc_floor_1", synth::Psf::kDisc, 1.0}})
    for (double R : pick({0.25, 0.5, 0.75, 1, 1.5, 3, 8})) {
      auto o = Base(seed);
      if (R >= 2) {  // as the blur sweep: big radii need more room between the edges
        o.camera = ThesisCamera().Resized(2296, 1528);
        o.tilt_deg = 65;
        o.supersample = 2;
      }
      o.noise_std = 0.003;
      o.psf = fam.psf;
      o.fixed_r_px = R;
      o.floor_sigma_px = fam.floor_ratio * R;
      c.push_back({fam.name, R * std::sqrt(1 + 4 * fam.floor_ratio * fam.floor_ratio), o, true});
    }
  // Near focus with a lens floor: a 0.35 px floor under a defocus disc of 0 .. 1.5 px (true r 0.7 .. 1.66 px).
  for (double R : pick({0, 0.25, 0.5, 0.75, 1, 1.25, 1.5})) {
    auto o = Base(seed);
    o.noise_std = 0.003;
    o.fixed_r_px = R;
    o.floor_sigma_px = 0.35;
    c.push_back({"near_focus", std::hypot(R, 0.7), o, true});
  }
  // Vignetting (slowly varying levels) on the thesis scene with a 0.35 px floor.
  for (double v : pick({0, 0.15, 0.35, 0.5, 0.7})) {
    auto o = Base(seed);
    o.floor_sigma_px = 0.35;
    o.vignetting = v;
    c.push_back({"vignetting", v, o});
  }
  // Barrel distortion in camera.json (issue 25): k1 from none to strong, the board turned and shifted towards a
  // corner (centred, it sees stretches of 2 % at most), 0.35 px floor; truth is the blur times the stretch across.
  for (double k1 : pick({0, -0.05, -0.12, -0.2, -0.3})) {
    auto o = Base(seed);
    o.floor_sigma_px = 0.35;
    o.edge1_u_mm = 300, o.yaw_deg = 30, o.lateral_mm = 30;
    o.camera.dist_coeffs = {k1, 0, 0, 0};
    c.push_back({"distortion", k1, o});
  }
  AddSamplingConditions(seed, pick, &c);
  for (double t : pick({20, 30, 45, 55, 65, 75})) {
    auto o = Base(seed);
    o.tilt_deg = t;
    c.push_back({"tilt", t, o});
  }
  return c;
}

// The factors of a filter after sampling (issue 42), held to its per-section rule rather than max(0.25 px, 5 %).
bool SamplingRule(const std::string& factor) {
  return factor == "post_gaussian" || factor == "post_sharpen" || factor == "phase";
}

MeasureRow Summarize(const std::string& method, const Condition& cond, const calib::TruthComparison& cmp,
                     calib::MethodError calib::SectionComparison::*member, double time_us, int phase_limited) {
  MeasureRow row;
  row.method = method;
  row.factor = cond.factor;
  row.level = cond.level;
  row.sections = int(cmp.sections.size());
  row.phase_limited = phase_limited;
  row.time_us_per_section = time_us;
  const calib::MethodSummary m = calib::SummarizeMethod(cmp, member);
  row.answered = m.answered;
  row.mean_abs_error_px = m.mean_abs_error_px;
  row.median_abs_error_px = m.median_abs_error_px;
  row.p90_abs_error_px = m.p90_abs_error_px;
  row.max_abs_error_px = m.max_abs_error_px;
  row.bias_px = m.bias_px;
  row.median_rel_error = m.median_rel_error;
  row.p90_rel_error = m.p90_rel_error;
  row.within_target = m.answered ? double(m.within_target) / m.answered : 0;
  row.meets_target = row.answered * 2 >= row.sections && row.within_target >= 0.9;
  if (SamplingRule(cond.factor)) {
    // Issue 42's rule on images filtered after sampling: every section within max(0.05 px, 10 %) of the truth or
    // flagged (not answered); the fitted model (every section answered) within median 2 %, p90 5 %.
    int within = 0;
    for (const calib::SectionComparison& s : cmp.sections) {
      const calib::MethodError& e = s.*member;
      within += e.answered && std::abs(e.error_px) <= std::max(0.05, 0.10 * s.true_r_px);
    }
    row.within_target = m.answered ? double(within) / m.answered : 0;
    row.off_rule = m.answered - within;
    row.meets_target = method == "fitted_model" ? m.answered > 0 && m.median_rel_error <= 0.02 && m.p90_rel_error <= 0.05
                                                : row.answered * 2 >= row.sections && within == m.answered;
  }
  return row;
}

// Times both measurement methods over every section of a calibrated photo, best of `repeats` runs.
void TimeMethods(const cv::Mat& photo, const calib::CalibResult& result, int repeats, double& model_us,
                 double& thesis_us) {
  const cv::Mat linear = calib::LinearGrey(photo);
  const cv::Mat grey8 = ToGrey8(photo);
  int n = 0;
  for (const auto& e : result.edges) n += int(e.sections.size());
  model_us = thesis_us = 1e30;
  for (int rep = 0; rep < repeats; ++rep) {
    auto t0 = Clock::now();
    for (const auto& e : result.edges)
      for (const auto& s : e.sections) calib::MeasureEdgeModel(linear, s.segment);
    model_us = std::min(model_us, 1000 * Ms(t0) / n);
    t0 = Clock::now();
    for (const auto& e : result.edges)
      for (const auto& s : e.sections) calib::MeasureEdgeThesis(grey8, s.segment);
    thesis_us = std::min(thesis_us, 1000 * Ms(t0) / n);
  }
}

// The edges' median angle to the nearest pixel axis in the photo, degrees (the sections' segments).
double MedianEdgeAngleDeg(const calib::CalibResult& result) {
  std::vector<double> a;
  for (const auto& e : result.edges)
    for (const auto& s : e.sections) {
      const cv::Point2d d = s.segment.b - s.segment.a;
      a.push_back(std::atan2(std::min(std::abs(d.x), std::abs(d.y)), std::max(std::abs(d.x), std::abs(d.y))) * 180 /
                  3.14159265358979323846);
    }
  if (a.empty()) return 0;
  std::nth_element(a.begin(), a.begin() + long(a.size() / 2), a.end());
  return a[a.size() / 2];
}

// A section's sub-pixel phase: how far its edge's midpoint lies from the nearest pixel centre across the nearer
// pixel axis, 0-0.5 px (from the segment the pose gives).
double SectionPhasePx(const calib::SectionResult& s) {
  const cv::Point2d m = 0.5 * (s.segment.a + s.segment.b), d = s.segment.b - s.segment.a;
  const double across = std::abs(d.x) >= std::abs(d.y) ? m.y : m.x;
  return std::abs(across - std::round(across));
}

// The four methods' rows of one scene (or one phase band of it: `keep` picks the sections).
void AddRows(const Condition& cond, const calib::CalibResult& result, const calib::TruthComparison& all,
             double model_us, double thesis_us, bool found, const std::function<bool(const calib::SectionResult&)>& keep,
             std::vector<MeasureRow>* rows) {
  calib::TruthComparison cmp = all;
  cmp.sections.clear();
  int phase_limited = 0;
  std::map<std::pair<int, int>, const calib::SectionResult*> by_index;
  for (const auto& e : result.edges)
    for (const auto& sec : e.sections) by_index[{sec.edge, sec.section}] = &sec;
  for (const calib::SectionComparison& c : all.sections) {
    const auto found_section = by_index.find({c.edge, c.section});
    if (found_section == by_index.end() || !keep(*found_section->second)) continue;
    const calib::SectionResult& s = *found_section->second;
    cmp.sections.push_back(c);
    const auto& flags = s.fit.flags;
    phase_limited += std::find(flags.begin(), flags.end(), "phase_limited") != flags.end();
  }
  const double n = double(all.sections.size());
  rows->push_back(Summarize("model_fit", cond, cmp, &calib::SectionComparison::model, model_us, phase_limited));
  rows->push_back(Summarize("thesis", cond, cmp, &calib::SectionComparison::thesis, thesis_us, phase_limited));
  rows->push_back(Summarize("eq37", cond, cmp, &calib::SectionComparison::estimated, 0, phase_limited));
  rows->push_back(Summarize("fitted_model", cond, cmp, &calib::SectionComparison::fitted,
                            1000 * result.estimate_ms / n, phase_limited));
  for (size_t i = rows->size() - 4; i < rows->size(); ++i) (*rows)[i].board_found = found;
}

// Phase bands of 0.1 px (their middles are the levels).
constexpr double kPhaseBands[] = {0.05, 0.15, 0.25, 0.35, 0.45};

}  // namespace

std::vector<MeasureRow> RunMeasureBench(const MeasureBenchOptions& options) {
  std::vector<MeasureRow> rows;
  const auto conditions = Conditions(options.quick, options.seed);
  int done = 0;
  for (const Condition& nominal : conditions) {
    auto t0 = Clock::now();
    const synth::Scene scene = synth::RenderScene(nominal.scene);
    const double render_ms = Ms(t0);
    Condition cond = nominal;
    if (cond.level_is_true_r && !scene.sections.empty()) {
      std::vector<double> r;
      for (const synth::SectionTruth& t : scene.sections) r.push_back(t.r_px);
      std::nth_element(r.begin(), r.begin() + long(r.size() / 2), r.end());
      cond.level = r[r.size() / 2];
    }
    calib::CalibResult result;
    bool found = true;
    try {
      result = calib::Calibrate(scene.image, scene.camera, scene.board);
    } catch (const Error& e) {
      if (e.kind() != ErrorKind::kNotFound) throw;
      // Detection broke first; measure the blur at the true pose so the measurement's own limit still shows.
      found = false;
      calib::CalibrateOptions at_truth;
      calib::BoardPose pose;
      pose.rvec = scene.rvec;
      pose.tvec = scene.tvec;
      at_truth.known_pose = pose;
      try {
        result = calib::Calibrate(scene.image, scene.camera, scene.board, at_truth);
      } catch (const Error& e2) {
        if (options.progress)
          options.progress("[" + std::to_string(++done) + "/" + std::to_string(conditions.size()) + "] " +
                           cond.factor + " " + std::to_string(cond.level) + ": no answer: " + e2.what());
        for (const char* m : {"model_fit", "thesis", "eq37", "fitted_model"}) {
          MeasureRow row;
          row.method = m;
          row.factor = cond.factor;
          row.level = cond.level;
          row.sections = scene.board.EdgeCount() * scene.board.SectionCount();
          row.board_found = false;
          rows.push_back(row);
        }
        continue;
      }
    }
    const calib::TruthComparison cmp = calib::CompareToTruth(result, scene.truth, "truth");
    double model_us = 0, thesis_us = 0;
    TimeMethods(scene.image, result, 3, model_us, thesis_us);
    if (cond.level_is_edge_angle) cond.level = MedianEdgeAngleDeg(result);
    if (!cond.per_phase) {
      AddRows(cond, result, cmp, model_us, thesis_us, found, [](const calib::SectionResult&) { return true; }, &rows);
    } else {
      for (const double band : kPhaseBands) {
        cond.level = band;
        AddRows(cond, result, cmp, model_us, thesis_us, found, [band](const calib::SectionResult& s) {
          return std::abs(SectionPhasePx(s) - band) <= 0.05;
        }, &rows);
      }
    }
    if (options.progress) {
      char line[256];
      std::snprintf(line, sizeof line,
                    "[%d/%zu] %-8s %-6g render %5.0f ms, calibrate %4.0f ms; |error| model %.3f px, thesis %.3f px%s",
                    ++done, conditions.size(), cond.factor.c_str(), cond.level, render_ms,
                    result.detect_ms + result.measure_ms + result.estimate_ms, rows[rows.size() - 4].mean_abs_error_px,
                    rows[rows.size() - 3].mean_abs_error_px, found ? "" : " (board not found: measured at the true pose)");
      options.progress(line);
    }
  }
  return rows;
}

void WriteMeasureCsv(const std::vector<MeasureRow>& rows, const std::filesystem::path& path, bool quick) {
  std::string text =
      "method,factor,level,sections,answered,mean_abs_error_px,median_abs_error_px,p90_abs_error_px,"
      "max_abs_error_px,bias_px,within_target,time_us_per_section,meets_target,board_found,median_rel_error,"
      "p90_rel_error,phase_limited,quick,off_rule\n";
  for (const auto& r : rows) {
    char line[512];
    const std::string off = r.off_rule >= 0 ? std::to_string(r.off_rule) : "";
    std::snprintf(line, sizeof line, "%s,%s,%g,%d,%d,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.2f,%d,%d,%.5f,%.5f,%d,%d,%s\n",
                  r.method.c_str(),
                  r.factor.c_str(), r.level, r.sections, r.answered, r.mean_abs_error_px, r.median_abs_error_px,
                  r.p90_abs_error_px, r.max_abs_error_px, r.bias_px, r.within_target, r.time_us_per_section,
                  int(r.meets_target), int(r.board_found), r.median_rel_error, r.p90_rel_error, r.phase_limited,
                  int(quick), off.c_str());
    text += line;
  }
  WriteFileAtomically(path, text);
}

std::string DescribeBreakpoints(const std::vector<MeasureRow>& rows) {
  // Rows come in sweep order (increasing difficulty), so the first failing level is where the method breaks - unless
  // the method fails on the base scene already: then no level of a factor is the cause, and that is said instead.
  std::map<std::pair<std::string, std::string>, std::vector<const MeasureRow*>> groups;
  std::vector<std::pair<std::string, std::string>> order;
  std::map<std::string, const MeasureRow*> failed_base;
  for (const auto& r : rows) {
    if (r.factor == "base") {
      if (!r.meets_target) failed_base[r.method] = &r;
      continue;
    }
    auto key = std::make_pair(r.method, r.factor);
    if (!groups.count(key)) order.push_back(key);
    groups[key].push_back(&r);
  }
  // A level as the charts print it (3 significant digits), marked where the board was not found (its blur was then
  // measured at the true pose: the method "held" without the pipeline's detection).
  auto level = [](const MeasureRow& r) {
    char text[64];
    std::snprintf(text, sizeof text, "%.3g%s", r.level, r.board_found ? "" : " (board not found)");
    return std::string(text);
  };
  std::ostringstream out;
  for (const auto& [method, r] : failed_base) {
    char line[512];
    std::snprintf(line, sizeof line,
                  "  %-12s %-8s fails on the base scene already: %.1f%% within target, mean |error| %.2f px (no "
                  "factor below is its cause)\n",
                  method.c_str(), "base", 100 * r->within_target, r->mean_abs_error_px);
    out << line;
  }
  for (const auto& key : order) {
    const auto& g = groups[key];
    std::string held, failed;
    const MeasureRow* broke = nullptr;
    for (const MeasureRow* r : g) {
      std::string& list = r->meets_target ? held : failed;
      list += (list.empty() ? "" : ", ") + level(*r);
      if (!r->meets_target && !broke) broke = r;
    }
    char line[512];
    if (!broke) {
      std::snprintf(line, sizeof line, "  %-12s %-8s holds at every level (%s)\n", key.first.c_str(),
                    key.second.c_str(), held.c_str());
    } else if (failed_base.count(key.first)) {
      std::snprintf(line, sizeof line, "  %-12s %-8s within target at %s; not at %s\n", key.first.c_str(),
                    key.second.c_str(), held.empty() ? "no level" : held.c_str(), failed.c_str());
    } else {
      std::snprintf(line, sizeof line,
                    "  %-12s %-8s breaks at %s: answered %d/%d, %.1f%% within target, mean |error| %.2f px%s%s\n",
                    key.first.c_str(), key.second.c_str(), level(*broke).c_str(), broke->answered, broke->sections,
                    100 * broke->within_target, broke->mean_abs_error_px, held.empty() ? "" : "; holds at ",
                    held.c_str());
    }
    out << line;
  }
  // Issue 42's rule on images filtered after sampling, per condition: the blur fit's sections off it (answered, outside
  // max(0.05 px, 10 %) of the truth: neither within it nor flagged) and those flagged phase_limited.
  bool rule_said = false;
  for (const auto& r : rows) {
    if (r.method != "model_fit" || r.off_rule < 0) continue;
    if (!rule_said)
      out << "  model_fit on images filtered after sampling (rule: each section within max(0.05 px, 10 %) of the "
             "truth or flagged phase_limited):\n";
    rule_said = true;
    char line[256];
    std::snprintf(line, sizeof line, "    %-13s %-6s %d of %d sections off the rule, %d flagged\n", r.factor.c_str(),
                  level(r).c_str(), r.off_rule, r.sections, r.phase_limited);
    out << line;
  }
  // Board detection is part of the pipeline too: say where it broke (the methods above were then measured at the
  // true pose).
  std::map<std::string, const MeasureRow*> detection_broke;
  for (const auto& r : rows)
    if (r.method == "model_fit" && !r.board_found && !detection_broke.count(r.factor)) detection_broke[r.factor] = &r;
  for (const auto& [factor, r] : detection_broke) {
    char line[256];
    std::snprintf(line, sizeof line, "  %-12s %-8s breaks at %.3g: board not found (blur measured at the true pose)\n",
                  "detection", factor.c_str(), r->level);
    out << line;
  }
  return out.str();
}

PipelineTiming TimeFullResolution(int repeats, const std::function<void(const std::string&)>& progress) {
  PipelineTiming t;
  synth::SceneOptions o = Base(1);
  o.camera = ThesisCamera();
  o.supersample = 2;
  t.width = o.camera.image_width_px;
  t.height = o.camera.image_height_px;
  if (progress) progress("rendering a full-resolution thesis scene (4592 x 3056) ...");
  auto t0 = Clock::now();
  const synth::Scene scene = synth::RenderScene(o);
  t.render_s = Ms(t0) / 1000;
  std::vector<uint8_t> png;
  media::Imencode(".png", scene.image, &png);
  t.total_ms = t.decode_ms = t.detect_ms = t.measure_ms = t.estimate_ms = 1e30;
  calib::CalibResult result;
  for (int rep = 0; rep < repeats; ++rep) {
    t0 = Clock::now();
    const cv::Mat photo = media::Imdecode(png, cv::IMREAD_COLOR);
    t.decode_ms = std::min(t.decode_ms, Ms(t0));
    t0 = Clock::now();
    result = calib::Calibrate(photo, scene.camera, scene.board);
    t.total_ms = std::min(t.total_ms, Ms(t0));
    t.detect_ms = std::min(t.detect_ms, result.detect_ms);
    t.measure_ms = std::min(t.measure_ms, result.measure_ms);
    t.estimate_ms = std::min(t.estimate_ms, result.estimate_ms);
    if (progress) progress("  run " + std::to_string(rep + 1) + ": " + std::to_string(int(Ms(t0))) + " ms");
  }
  TimeMethods(scene.image, result, 3, t.model_us_per_section, t.thesis_us_per_section);
  return t;
}

}  // namespace blurcue::bench
