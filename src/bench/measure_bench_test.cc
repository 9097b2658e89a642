#include "bench/measure_bench.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace blurcue::bench {
namespace {

MeasureRow Row(const std::string& method, const std::string& factor, double level, bool meets, bool found = true) {
  MeasureRow r;
  r.method = method, r.factor = factor, r.level = level, r.meets_target = meets, r.board_found = found;
  r.sections = r.answered = 77;
  r.within_target = meets ? 1.0 : 0.2;
  return r;
}

// A first-time reader was told "eq37 vignetting breaks at 0" (eq. 3.7 failed on the base scene, so no factor caused
// it), "holds at 0.02" where the board was not found (blur measured at the true pose), and levels like 0.279508.
TEST(MeasureBench, BreakpointsSayWhatTheyMean) {
  const std::vector<MeasureRow> rows = {
      Row("eq37", "base", 0, false),          Row("eq37", "vignetting", 0, false),
      Row("eq37", "vignetting", 0.35, true),  Row("model_fit", "base", 0, true),
      Row("model_fit", "contrast", 0.9, true), Row("model_fit", "contrast", 0.02, true, false),
      Row("model_fit", "psf_disc_floor_0.25", 0.279508, true), Row("model_fit", "psf_disc_floor_0.25", 8.94427, false)};
  const std::string text = DescribeBreakpoints(rows);
  EXPECT_NE(text.find("eq37         base     fails on the base scene already: 20.0% within target"), std::string::npos)
      << text;
  EXPECT_NE(text.find("eq37         vignetting within target at 0.35; not at 0\n"), std::string::npos) << text;
  EXPECT_EQ(text.find("eq37         vignetting breaks at"), std::string::npos) << text;
  EXPECT_NE(text.find("holds at every level (0.9, 0.02 (board not found))"), std::string::npos) << text;
  EXPECT_NE(text.find("breaks at 8.94: answered 77/77, 20.0% within target"), std::string::npos) << text;
  EXPECT_NE(text.find("holds at 0.28\n"), std::string::npos) << text;
  EXPECT_NE(text.find("detection    contrast breaks at 0.02: board not found"), std::string::npos) << text;
}

// Issue 42's rule is stated, and each filtered condition's sections off it counted, for the blur fit only.
TEST(MeasureBench, SamplingRuleCountsSectionsOffIt) {
  MeasureRow gauss = Row("model_fit", "post_gaussian", 0.35, false), fitted = Row("fitted_model", "post_gaussian", 0.35, true);
  gauss.off_rule = 1, gauss.phase_limited = 0, fitted.off_rule = 0;
  MeasureRow noise = Row("model_fit", "noise", 0.01, true);
  const std::string text = DescribeBreakpoints({gauss, fitted, noise});
  EXPECT_NE(text.find("within max(0.05 px, 10 %) of the truth or flagged phase_limited"), std::string::npos) << text;
  EXPECT_NE(text.find("post_gaussian 0.35   1 of 77 sections off the rule, 0 flagged\n"), std::string::npos) << text;
  EXPECT_EQ(text.find("noise         0.01"), std::string::npos) << text;
}

}  // namespace
}  // namespace blurcue::bench
