#include "calib/truth.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <opencv2/calib3d.hpp>

#include "core/error.h"

namespace blurcue::calib {

static cv::Vec3d Vec3(const Json& j, const std::string& where) {
  if (!j.is_array() || j.size() != 3) throw InputError(where, "must be an array of 3 numbers, got " + j.dump());
  return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}

TruthComparison CompareToTruth(const CalibResult& result, const Json& truth, const std::string& where) {
  TruthComparison c;
  if (!truth.contains("pose")) throw InputError(where + "/pose", "is required but missing");
  const cv::Vec3d rvec = Vec3(truth["pose"].value("rvec", Json()), where + "/pose/rvec");
  const cv::Vec3d tvec = Vec3(truth["pose"].value("tvec", Json()), where + "/pose/tvec");
  c.translation_error_mm = cv::norm(result.pose.tvec - tvec);
  cv::Matx33d r_true, r_est;
  cv::Rodrigues(rvec, r_true);
  cv::Rodrigues(result.pose.rvec, r_est);
  cv::Vec3d delta;
  cv::Rodrigues(r_true.t() * r_est, delta);
  c.rotation_error_deg = cv::norm(delta) * 180.0 / M_PI;

  std::map<std::pair<int, int>, const Json*> by_key;
  if (!truth.contains("sections") || !truth["sections"].is_array())
    throw InputError(where + "/sections", "must be an array of sections");
  for (const Json& s : truth["sections"]) by_key[{s.at("edge").get<int>(), s.at("section").get<int>()}] = &s;

  for (const auto& edge : result.edges) {
    double sum = 0;
    for (const auto& s : edge.sections) {
      auto it = by_key.find({s.edge, s.section});
      if (it == by_key.end())
        throw InputError(where + "/sections", "has no edge " + std::to_string(s.edge) + " section " +
                                                   std::to_string(s.section) + " (another board?)");
      const Json& t = *it->second;
      SectionComparison row;
      row.edge = s.edge;
      row.section = s.section;
      row.true_r_px = t.at("r_px").get<double>();
      row.true_u_mm = t.at("u_mm").get<double>();
      row.flawed = t.value("flawed", false);
      c.max_depth_error_mm = std::max(c.max_depth_error_mm, std::abs(s.u_mm - row.true_u_mm));
      row.model = {s.fit.ok, s.fit.r_px - row.true_r_px};
      row.thesis = {s.thesis.ok, s.thesis.r_px - row.true_r_px};
      row.estimated = {s.r_estimated_px.has_value(), s.r_estimated_px.value_or(0) - row.true_r_px};
      row.fitted = {true, s.r_fitted_px - row.true_r_px};
      sum += row.true_r_px;
      c.sections.push_back(row);
    }
    c.true_r_per_edge.push_back(sum / edge.sections.size());
  }
  return c;
}

MethodSummary SummarizeMethod(const TruthComparison& comparison, MethodError SectionComparison::*method) {
  MethodSummary m;
  m.sections = int(comparison.sections.size());
  std::vector<double> abs_err, rel_err;
  double sum_signed = 0;
  for (const auto& s : comparison.sections) {
    const MethodError& e = s.*method;
    if (!e.answered) continue;
    abs_err.push_back(std::abs(e.error_px));
    rel_err.push_back(s.true_r_px > 0 ? std::abs(e.error_px) / s.true_r_px : 0.0);
    sum_signed += e.error_px;
    m.within_target += std::abs(e.error_px) <= MeasureTolerancePx(s.true_r_px);
  }
  m.answered = int(abs_err.size());
  if (abs_err.empty()) return m;
  std::sort(abs_err.begin(), abs_err.end());
  const size_t n = abs_err.size();
  double sum = 0;
  for (double v : abs_err) sum += v;
  m.mean_abs_error_px = sum / n;
  m.median_abs_error_px = abs_err[n / 2];
  m.p90_abs_error_px = abs_err[std::min(n - 1, size_t(0.9 * n))];
  m.max_abs_error_px = abs_err.back();
  m.bias_px = sum_signed / n;
  std::sort(rel_err.begin(), rel_err.end());
  m.median_rel_error = rel_err[n / 2];
  m.p90_rel_error = rel_err[std::min(n - 1, size_t(0.9 * n))];
  return m;
}

}  // namespace blurcue::calib
