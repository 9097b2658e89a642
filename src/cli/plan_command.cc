// blurcue plan: power analysis of a protocol by simulated studies (src/plan/plan.h), its chart by the analysis's
// Python (analysis/plan_chart.py).

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "cli/child.h"
#include "cli/commands.h"
#include "core/atomic_file.h"
#include "core/own_output.h"
#include "core/data_dir.h"
#include "core/error.h"
#include "core/hash.h"
#include "core/json_io.h"
#include "plan/plan.h"

namespace blurcue::cli {

namespace {

struct PlanArgs {
  plan::PlanOptions options;
  std::string protocol, display, out = "results/plan", python = "/usr/bin/python3", difference;
  bool no_chart = false;
};

// The help text: what a plan simulates, what it reports and what it writes.
const char* const kPlanHelp =
    "Plan a study before anyone sits down: how many participants a protocol needs, and what it can find.\n"
    "Simulates --studies whole studies of --participants participants each, every participant answered by the\n"
    "simulated observer (--observer, as 'blurcue run --observer') through the runner's own decisions - the same trial\n"
    "list, scenes on --display, staircases and QUEST+, stop rules, practice criteria and deadlines - headless, without\n"
    "GL, on every core. Participant i of study s is P<i+1> with seed DeriveSeed(DeriveSeed(--seed, s), i): the same\n"
    "plan on any machine and with any --threads, and each simulated participant can be rerun with blurcue run\n"
    "(DIR/answers.csv lists study 1's participants, their seeds and answers).\n"
    "\n"
    "Reported per condition (a crossing of a block's factors; a pair's sides as designed, swaps undone):\n"
    "  share    the expected share: a pair - the side showing the larger blur radius among decisive answers\n"
    "           (more_blurred: the report's chose_more_blurred; the thesis's tests 1-3: first_source, the design's\n"
    "           first source, as their report view), with all its answers' shares (first / second / can't tell /\n"
    "           none past a deadline) and which source was the more blurred; a procedure or odd one out -\n"
    "           correct; yes/no - yes\n"
    "  width    the mean width of its 95 % Wilson interval with N participants\n"
    "  power    against N = 1 .. --participants:\n"
    "           exact           per condition, the report's exact test against chance with participants as the\n"
    "                           unit, p < --alpha, unadjusted: at chance 0.5 the sign-flip test of their shares\n"
    "                           (it cannot reach p < 0.05 with fewer than 6 participants), else (1/n odd one out)\n"
    "                           the binomial of the answers; one participant: the binomial of their answers, no\n"
    "                           test of a single answer (as the report); two: no test\n"
    "           participants_t  a one-sample t-test of each participant's share against chance: a stand-in for the\n"
    "                           report's GLMM (a random-intercept logistic model, too slow to fit per simulated\n"
    "                           study); it tests the population-level effect, not the GLMM's per-level terms\n"
    "  N(80%)   the smallest N whose power reaches --power\n"
    "  cut-off ~ distance  depth matching (adjustment over distances): each participant's slope b of\n"
    "                           log(accepted cut-off) on log(distance), the report's power law; share is the mean\n"
    "                           b, width its 95 % t interval's, power that of a t-test of the slopes against 0\n"
    "Rating trials have no chance level and are not planned (a note says so).\n"
    "\n"
    "An adaptive block (a staircase or QUEST+) sets how often its trials are right, so its share correct is not\n"
    "tested; per procedure cell (a crossing of the block's factors, e.g. edge=9) the plan reports what it measures:\n"
    "  threshold      the participants' estimates as the report takes them (QUEST+: the median of its posterior\n"
    "                 over its grid; a staircase: its posterior median at its target, docs/thresholds.md) against the simulated\n"
    "                 observer's true threshold, worked out from the observer model's own psychometric function (the\n"
    "                 point the procedure aims at: QUEST+'s Weibull threshold, a staircase's convergence point):\n"
    "                 truth, mean, bias, sd and the width of the 95 % t interval of the mean of N estimates. A truth\n"
    "                 outside the procedure's range is said in words, and no bias is given.\n"
    "  paired_t       two cells of the same participants: the paired t-test of their thresholds the report would\n"
    "                 run - the difference the model itself predicts, and with --difference a declared one\n"
    "  groups_t       the same cell in two groups (protocol 'groups'): Welch's t-test between the groups\n"
    "  second_cell_t  one cell alone, with --difference: against a second cell like it in the same participants\n"
    "--difference D declares the difference to plan for, in the procedure's units (its variable: 0.5 is half an\n"
    "arcmin for difference_arcmin, 0.5 x the reference for relative_difference), or relative to each cell's true\n"
    "threshold with a percent sign (20%): the estimates' scatter as simulated, one side shifted by D - planned only\n"
    "from a cell whose truth is known to a second threshold (truth + D) inside the procedure's range (else a note).\n"
    "With groups, every share is tested per group and between groups (Welch), never pooled over them.\n"
    "\n"
    "Writes DIR (--out, built beside it and swapped in whole): plan.csv (one row per test, condition and N),\n"
    "answers.csv, plan.json (the settings and the smallest N per test) and power.png / power.svg (power against\n"
    "participants, drawn by analysis/plan_chart.py; --no-chart skips it). A summary goes to stdout, progress to stderr.\n"
    "Example (the thesis's test 1 on a 24-inch 1920x1080 monitor at 60 cm, the default display):\n"
    "  blurcue plan protocols/test1-static-grids.json --participants 30 --studies 400 --seed 1 --out results/plan\n"
    "QUEST+ on the blur difference, planning for a 0.5 arcmin difference between two cells:\n"
    "  blurcue plan protocols/quest-blur-difference.json --participants 20 --difference 0.5 --out results/plan-quest";

// Simulates the plan and writes its folder (the checks that would stop the writing first), then the summary.
void WritePlan(const PlanArgs& args) {
  plan::PlanOptions options = args.options;
  options.protocol_file = args.protocol;
  options.display_profile = args.display;
  if (!args.difference.empty()) options.difference = plan::ParseDifference(args.difference);
  options.progress = [](const std::string& line) { std::fprintf(stderr, "plan: %s\n", line.c_str()); };
  const std::filesystem::path out = args.out;
  const std::filesystem::path script = DataDir().path / "analysis" / "plan_chart.py";
  if (!args.no_chart && !std::filesystem::exists(script))
    throw InputError(script.string(), "the chart script is missing (--no-chart writes the tables only)");
  // What would stop the writing stops it now, not after the simulation: a --python that is no Python 3, an --out
  // that is a file or a folder of something other than an earlier plan.
  if (!args.no_chart) RequirePython3(args.python, {"matplotlib", "pandas"});
  std::error_code ignored;
  if (std::filesystem::exists(out, ignored) && !std::filesystem::is_directory(out, ignored))
    throw InputError(out.string(), "--out: is a file, not a folder");
  // An earlier plan is replaced whole: its own files only, so a file someone put beside them is not deleted with it.
  const auto ours = [](const std::string& name) {
    for (const char* own : {"plan.csv", "answers.csv", "plan.json", "power.png", "power.svg"})
      if (name == own) return true;
    return false;
  };
  RequireReplaceableFolder(out, ours);
  // And it holds the plan.json plan wrote: a folder of one's own plan.csv or answers.csv alone, or beside a
  // plan.json of another tool, was replaced as if it were one.
  RequireMarkedFolder("--out", out, "plan.json", "a plan blurcue plan wrote", "one's own plan.csv or tables?");
  RequireOwnFile("--out", out / "plan.json", "a plan.json plan wrote", Holds("\"smallest_n\""));
  const plan::PlanResult result = plan::RunPlan(options);
  std::fprintf(stderr, "plan: %zu participants in %.2f s on %d threads (%.2f ms per participant)\n",
               static_cast<size_t>(options.studies) * static_cast<size_t>(options.participants), result.seconds,
               result.threads_used,
               1000 * result.seconds / (double(options.studies) * options.participants));
  Json settings = {{"protocol", std::filesystem::absolute(args.protocol).string()},
                   {"protocol_hash", result.protocol_hash},
                   {"study", result.study},
                   {"display", args.display.empty() ? result.display : args.display},
                   {"participants", options.participants},
                   {"studies", options.studies},
                   {"seed", "s" + std::to_string(options.seed)},
                   {"observer", result.observer},
                   {"alpha", options.alpha},
                   {"target_power", options.target_power},
                   {"difference", args.difference.empty() ? Json() : Json(args.difference)},
                   {"smallest_n", result.smallest_n},
                   {"notes", result.notes}};
  for (const auto& path : RemoveStaleLeftovers(out))
    std::fprintf(stderr, "plan: removed %s, left by an interrupted run\n", path.c_str());
  WriteFolderAtomically(
      out,
      [&](const std::filesystem::path& partial) {
        WriteFileAtomically(partial / "plan.csv", plan::PlanCsv(result));
        WriteFileAtomically(partial / "answers.csv", plan::AnswersCsv(result));
        WriteFileAtomically(partial / "plan.json", settings.dump(2) + "\n");
        if (!args.no_chart)
          RunAnalysis({args.python, script.string(), "--plan", (partial / "plan.csv").string(), "--out",
                       partial.string(), "--title", result.study, "--target", std::to_string(options.target_power)},
                      "the chart", out.string(),
                      {(partial / "power.png").string(), (partial / "power.svg").string()});
      },
      ours);
  std::printf("%s", plan::Summary(result, options).c_str());
  std::printf("wrote %s (plan.csv, answers.csv, plan.json%s)\n", out.c_str(),
              args.no_chart ? "" : ", power.png, power.svg");
}

}  // namespace

void AddPlanCommand(CLI::App& app) {
  auto args = std::make_shared<PlanArgs>();
  CLI::App* cmd = app.add_subcommand("plan", kPlanHelp);
  cmd->add_option("protocol", args->protocol, "the protocol JSON file")->required();
  cmd->add_option("--display", args->display,
                  "the monitor's display profile (default: the protocol's display.profile, else a 24-inch 1920x1080 "
                  "monitor at 60 cm)");
  cmd->add_option("--participants", args->options.participants,
                  "participants per simulated study; power is reported for every N from 1 to this")
      ->capture_default_str()->transform(IntRange(1, 10000));
  cmd->add_option("--studies", args->options.studies, "simulated studies (more: power known more precisely; its "
                                                      "standard error is at most 0.5 / sqrt(studies))")
      ->capture_default_str()->transform(IntRange(1, 100000));
  cmd->add_option("--observer", args->options.observer, "the simulated observer, sim or sim:NAME=VALUE,... (see "
                                                        "'blurcue run --help')")
      ->capture_default_str();
  cmd->add_option("--seed", args->options.seed, "the plan's seed (every participant's seed is derived from it)")
      ->capture_default_str()->transform(SeedValidator());
  cmd->add_option("--threads", args->options.threads, "worker threads (0: every core); the results do not depend on it")
      ->capture_default_str()->transform(IntRange(0, 256));
  cmd->add_option("--alpha", args->options.alpha, "level of the tests")->capture_default_str()
      ->check(FiniteRange(0, 0.5, "", "", true));
  cmd->add_option("--power", args->options.target_power, "the power N(80%) asks for")->capture_default_str()
      ->check(FiniteRange(0, 1, "", "", true));
  cmd->add_option("--difference", args->difference,
                  "procedure cells: the threshold difference to plan the power for, in the procedure's units (0.5) "
                  "or relative to the true threshold (20%)");
  cmd->add_option("--out", args->out,
                  "output folder (created; an earlier plan there is replaced when it holds only the files plan\n"
                  "writes, its plan.json among them)")
      ->capture_default_str();
  cmd->add_option("--python", args->python, "the Python that draws the chart")->capture_default_str();
  cmd->add_flag("--no-chart", args->no_chart, "write the tables only");
  cmd->callback([args] { WritePlan(*args); });
}

}  // namespace blurcue::cli
