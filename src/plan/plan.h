#pragma once
// Plan a study before anyone sits down: many seeded simulated studies of a protocol, each participant answered by
// the simulated observer through the session's own decisions (procedure/trial_logic.h: the same trial list, scenes,
// procedures, stop rules, practice criteria and answers as `blurcue run --observer sim`), headless and without GL,
// in parallel. From them, per condition, the expected share and how wide its 95 % interval would be, and the power
// of the protocol's tests against the number of participants:
//   exact          per condition, the report's exact test against chance with participants as the unit
//                  (analysis/study_tests.py against_chance_counts; a pair: the side showing the larger blur radius
//                  - trials.csv's chose_more_blurred - among decisive answers where the radii differ, against 0.5 -
//                  the sign-flip test of the participants' shares; an odd one out: correct
//                  against its guess rate - the binomial of the answers; one participant: the binomial of their
//                  answers; two: none), at alpha;
//   participants_t across participants, a one-sample t-test of each participant's share (over all their scored
//                  trials) against chance: a stand-in for the report's GLMM (random intercept per participant), whose
//                  fit per simulated study would take minutes; it tests the same population-level effect (the
//                  intercept), not the GLMM's per-level terms.
//   slope_t        depth matching (an adjustment block over two or more distances): each participant's least-squares
//                  slope b of log(accepted cut-off) on log(distance) - the report's power law c = e^a d^b - and a
//                  one-sample t-test of the slopes against 0 across participants (the report's mixed model's slope
//                  with a random intercept, in the same stand-in spirit).
//   (a procedure cell - a crossing of a staircase's or QUEST+'s block - sets its own share correct, so it is not
//   tested against chance; plan/comparisons.h plans what it measures instead: the threshold's bias, sd and interval
//   width against the observer's true threshold (plan/threshold.h), and paired / Welch t-tests between cells and
//   groups, for the model's own difference and a declared one.)
// With between-subject groups, shares are tested per group and between groups (Welch), never pooled over them.
// Deterministic: participant i of study s is "P<i+1>" with seed DeriveSeed(DeriveSeed(seed, s), i), whatever the
// thread count, so the first n participants of a study of N are the study of n, and every simulated participant can
// be rerun with `blurcue run --participant P<i+1> --seed <its seed> --observer <the same>`.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "procedure/answer.h"
#include "procedure/threshold_fit.h"
#include "protocol/level.h"

namespace blurcue::procedure {
struct PreparedSession;
}

namespace blurcue::plan {

// A difference between thresholds to plan for (--difference): in the procedure's units, or relative to the true one.
struct Difference {
  double value = 0;
  bool relative = false;  // value is a fraction of each cell's true threshold ("20%" -> 0.2)
};
// "0.5" (the procedure's units) or "20%" (of the true threshold); throws Error(kUsage) naming --difference otherwise.
Difference ParseDifference(const std::string& text);

struct PlanOptions {
  std::filesystem::path protocol_file;
  std::filesystem::path display_profile;  // empty: the protocol's display.profile, else the default monitor
  int participants = 20;                  // per simulated study; power is reported for 1 .. participants
  int studies = 200;                      // simulated studies
  uint64_t seed = 1;
  std::string observer = "sim";           // procedure::ParseObserver's form
  int threads = 0;                        // 0: every core (std::thread::hardware_concurrency)
  double alpha = 0.05;                    // the tests' level
  double target_power = 0.8;              // smallest N reaching this
  std::optional<Difference> difference;   // procedure cells: the difference whose power is planned (none: not planned)
  std::function<void(const std::string&)> progress;  // about every 10 % of the participants
};

// What tells a condition from the others: its block, its levels (typed, as designed), a depth matching's slope
// (one per block, no levels), and the group it is planned for ("" when not planned per group).
struct ConditionKey {
  std::string block;
  std::vector<protocol::Level> levels;
  bool slope = false;
  std::string group;
  bool operator<(const ConditionKey& o) const;
  bool operator==(const ConditionKey& o) const { return !(*this < o) && !(o < *this); }
};

// One condition: a crossing of a block's factors (as designed, swaps undone), with the measure its tests use.
struct Condition {
  ConditionKey key;       // unique
  int block = 0;          // index in protocol.blocks (conditions are ordered by block, then levels)
  std::string label;      // "edge=3" (and the block's name when the protocol has several)
  std::string measure;    // "more_blurred" (a pair: the report's chose_more_blurred) | "first_source" (a pair of
                          // the thesis's studies, as the report's thesis view) | "correct" | "yes" | "log_cutoff_slope" (depth matching)
                          // | "threshold" (a procedure cell: what it estimates, not its share correct)
  double chance = -1;     // the test's null share; < 0: no test (yes/no, threshold)
  // A procedure cell: its variable (the threshold's unit) and the simulated observer's true threshold (threshold.h).
  std::string units;
  bool truth_determined = false;
  double truth = 0;
  std::string truth_why;  // why there is no truth, in words
  int truth_beyond = 0;   // the truth lies below (-1) or above (+1) the procedure's range (TrueThreshold::beyond)
  double range_lo = 0, range_hi = 0;  // where the procedure measures a threshold (TrueThreshold's range)
  std::string target;     // what the threshold means, in words ("70.7 % correct, lapses included")
};

// What one simulated participant answered: per condition (by Condition::key) the counts.
struct Tally {
  int k = 0, n = 0;       // successes (first source, correct, yes) of the trials that count (decisive, answered)
  int first = 0, second = 0, cant_tell = 0, none = 0, shown = 0;  // a pair's answers (none: past the deadline)
  // A pair's trials by the source (as designed) that showed the larger radius: the first, the second, neither (equal).
  int blurrier_first = 0, blurrier_second = 0, blurrier_equal = 0;
};

struct SimParticipant {
  std::string id, group;
  uint64_t seed = 0;
  std::vector<std::pair<int, procedure::Choice>> answers;  // (trial index, choice as the record stores it), every trial
  std::map<ConditionKey, Tally> tallies;
  // Depth matching, by condition key: (log distance, log accepted cut-off) of each answered trial.
  std::map<ConditionKey, std::vector<std::pair<double, double>>> matches;
  // A procedure cell's threshold estimate, as the report takes it from the track (threshold.h TrackEstimate).
  std::map<ConditionKey, double> thresholds;
  // Every procedure cell's track as the report reads it (determined or not, with its interval and why).
  std::map<ConditionKey, procedure::TrackThreshold> tracks;
};

inline constexpr double kNoValue = __builtin_nan("");

// One row of the plan: a test of a condition (or of all the participants' trials) at a number of participants.
struct PowerRow {
  std::string test;        // "exact" | "participants_t" | "slope_t" | "none" (a condition without a chance level) |
                           // "threshold" | "paired_t" | "second_cell_t" | "groups_t" (comparisons.h)
  std::string condition;   // its label; "all" for participants_t
  std::string measure;
  double chance = -1;
  int participants = 0;
  double expected_share = 0;   // over every simulated study and participant (slope_t: the mean slope b)
  double share_first = 0, share_second = 0, share_cant_tell = 0, share_none = 0;  // a pair's answers, of shown
  // A pair: which source (as designed) showed the larger radius - "first", "second", "equal" or "varies" (trials of
  // the condition differ); empty for other measures.
  std::string more_blurred;
  double mean_trials = 0;      // counting trials per study at this N (mean)
  double wilson_width = 0;     // mean width of the 95 % Wilson interval at this N (slope_t: of the slope's t interval)
  double power = 0;            // share of studies whose test has p < alpha (NaN for "none")
  // Procedure cells (NaN elsewhere): the observer's true threshold, the mean estimate (a comparison: of the
  // differences), bias = mean - truth, the estimates' sd across participants, the mean width of the 95 % t interval
  // of the mean of N estimates, and a comparison's true (or declared) difference.
  double true_threshold = kNoValue, mean_estimate = kNoValue, bias = kNoValue, sd_estimate = kNoValue;
  double interval_width = kNoValue, difference = kNoValue;
  // Procedure cells, over every simulated track (the row at N = participants; NaN elsewhere): the share of tracks
  // whose threshold is determined (TrackEstimate's rule, the report's), and of those, the share whose own 95 %
  // interval holds the observer's true threshold (NaN where the truth is not determined).
  double determined_share = kNoValue, coverage = kNoValue;
  double median_estimate = kNoValue;  // the estimates' median (the mean of skewed estimates runs above it)
};

struct PlanResult {
  std::vector<Condition> conditions;
  std::vector<std::vector<SimParticipant>> studies;  // [study][participant]
  std::vector<PowerRow> rows;
  std::map<std::string, int> smallest_n;   // "exact edge=3" -> smallest N with power >= target (absent: none)
  std::vector<std::string> notes;          // what is not planned and why
  std::vector<std::string> groups;         // the protocol's between-subject groups (empty: none)
  int threads_used = 0;
  double seconds = 0;                      // wall time of the simulation
  std::string observer;                    // canonical form
  std::string study;                       // the protocol's name
  std::string display;                     // the display profile's name (--display, the protocol's, or the default)
  std::string protocol_hash;               // as the record hashes it (store::ProtocolHash of its canonical text)
};

// Throws Error(kInput) for a protocol that cannot be prepared (as `blurcue validate`), kUsage for bad options.
PlanResult RunPlan(const PlanOptions& options);

// Only the simulation, of a study already prepared (procedure::PrepareStudy of options.protocol_file and
// display_profile), as the benchmark times it: the participants of options.studies studies x options.participants,
// on options.threads workers; the conditions found (ordered), notes on what is not planned and the workers used.
std::vector<std::vector<SimParticipant>> SimulateStudies(const PlanOptions& options,
                                                         const procedure::PreparedSession& study,
                                                         std::vector<Condition>* conditions,
                                                         std::vector<std::string>* notes, int* threads_used);

// plan.csv: one row per PowerRow, fixed formatting (the same plan gives the same bytes).
std::string PlanCsv(const PlanResult& result);
// answers.csv: study 1's participants, one row per trial: participant, seed (s-prefixed), group, trial_index, choice.
std::string AnswersCsv(const PlanResult& result);
// The summary printed on stdout.
std::string Summary(const PlanResult& result, const PlanOptions& options);

}  // namespace blurcue::plan
