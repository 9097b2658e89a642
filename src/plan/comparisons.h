#pragma once
// The plan's rows for what a procedure measures and for between-subject groups (plan.h): per procedure cell the
// threshold's precision, the paired t-tests between cells, a declared difference's power, and the group effect.
#include "plan/plan.h"

namespace blurcue::plan {

// Per procedure cell (Condition::measure "threshold"): rows "threshold" (truth, mean estimate, bias, sd, 95 %
// interval width of the mean at each N), "paired_t" (between two cells of the same participants: the model's own
// difference, and --difference declared), "second_cell_t" (one cell alone and --difference: a second cell like it,
// differing by the declared amount) and "groups_t" (the same cell in two groups, Welch). Notes say what is not planned.
void AddThresholdRows(PlanResult& r, const PlanOptions& options);

// A protocol with groups: per measure with a chance level, Welch's t-test between each two groups of the
// participants' shares (rows "groups_t"), and the t-test against chance per group (rows "participants_t" whose
// condition is "group=NAME") instead of pooled over the groups.
void AddGroupShareRows(PlanResult& r, const PlanOptions& options);

// The summary's part for procedure cells: precision per cell and the comparisons' power at N = participants; an
// undetermined true threshold is said in words, never printed as a number.
std::string ThresholdSummary(const PlanResult& r, const PlanOptions& options);

// What a design should give before it is run, by simulation: at least this share of tracks determined, of those at
// least this share of 95 % intervals holding the truth, estimates on average within this fraction of the truth.
inline constexpr double kDeterminedEnough = 0.8, kCoveredEnough = 0.9, kBiasEnough = 0.1;

// The warnings for one procedure cell's threshold row at N = participants: rarely determined, intervals that rarely
// cover, a biased estimate (each one line, naming the cell and the measured share).
std::vector<std::string> DesignWarnings(const Condition& c, const PowerRow& row);

// "plus 0.5 difference_arcmin" or "plus 20 % of the true threshold": the declared difference in words.
std::string DifferenceText(const Difference& d, const std::string& units);

}  // namespace blurcue::plan
