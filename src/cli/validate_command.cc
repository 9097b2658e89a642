// blurcue validate: check a protocol file and build its trial list, through the pre-flight a session runs.
#include <cstdio>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "cli/commands.h"
#include "cli/groups.h"
#include "core/error.h"
#include "core/hash.h"
#include "plan/comparisons.h"
#include "plan/plan.h"
#include "plan/threshold.h"
#include "protocol/protocol.h"
#include "protocol/trials.h"
#include "procedure/observer.h"
#include "procedure/prepare.h"
#include "procedure/recorded_names.h"
#include "procedure/visibility.h"
#include "stimulus/video_take.h"

namespace blurcue::cli {

namespace {

struct Args {
  std::string file, participant = "P1", display, observer = "sim", group;
  std::optional<uint64_t> seed;
  bool no_files = false, list = false, plan = false;
  double visible = 0.75;
};

// --plan on a protocol with a staircase or QUEST+ block: 200 simulated tracks per procedure cell (`blurcue plan`'s
// simulation, 10 studies of 20), and how often the report would determine each cell's threshold and its interval
// hold the truth - a WARNING line where the design rarely does (plan::DesignWarnings, the plan's own rule).
std::string ProcedureDesignLines(const protocol::Protocol& protocol, const Args& args) {
  bool any = false;
  for (const auto& b : protocol.blocks) any = any || (b.procedure && !b.practice);
  if (!any) return "";
  plan::PlanOptions options;
  options.protocol_file = args.file;
  options.display_profile = args.display;
  options.observer = args.observer;
  options.participants = 20, options.studies = 10, options.seed = 1;
  const plan::PlanResult r = plan::RunPlan(options);
  std::string out;
  char line[400];
  for (const plan::Condition& c : r.conditions) {
    if (c.measure != "threshold") continue;
    for (const plan::PowerRow& row : r.rows) {
      if (row.test != "threshold" || row.condition != c.label || row.participants != options.participants) continue;
      // Coverage is a share of the determined tracks against a known truth: without either, which one is missing.
      std::string covered;
      if (std::isfinite(row.coverage))
        covered = std::to_string(int(std::lround(100 * row.coverage))) +
                  " % of their 95 % intervals hold the observer's true threshold";
      else if (!c.truth_determined)
        covered = "the observer's true threshold is " + c.truth_why;
      else {
        char truth[64];
        std::snprintf(truth, sizeof truth, "%.3g", c.truth);
        covered = "so no interval to check against the observer's true threshold, " + std::string(truth) + " " + c.units;
      }
      std::snprintf(line, sizeof line,
                    "  procedure cell %s: %.0f %% of 200 simulated tracks determine their threshold; %s\n",
                    c.label.c_str(), 100 * row.determined_share, covered.c_str());
      out += line;
      for (const std::string& warning : plan::DesignWarnings(c, row)) out += "  WARNING: " + warning + "\n";
    }
  }
  return out;
}

// One participant's session per group checked: its seed, trials and what the pre-flight found.
struct CheckedGroup {
  std::string group;
  uint64_t seed = 0;
  std::vector<protocol::Trial> trials;
  std::string shown;  // how a frame reaches the screen and the eye
};

// How a prepared participant's frames reach the screen and the eye: the frame and window, the take, the group and
// the blur plan, a line each.
std::string PresentationLines(const procedure::PreparedSession& prepared) {
  const stimulus::Presentation& at = prepared.presentation;
  char line[400];
  std::snprintf(line, sizeof line,
                "  shown: a %d x %d %s in a %d x %d window (%s) at %.4f screen px per photo px; %s: %.2f px "
                "per degree, 1 photo px = %.3f arcmin\n",
                at.frame_width_px, at.frame_height_px,
                prepared.images.take ? "video" : prepared.scene ? "photo" : "frame", at.window_width_px,
                at.window_height_px, at.scaling.c_str(), at.scale, at.profile.name.c_str(),
                display::PxPerDeg(at.profile), at.Arcmin(1));
  std::string shown = line;
  if (const auto& take = prepared.images.take) {
    const protocol::Content& c = prepared.protocol.content;
    shown += "  take: " + std::to_string(take->take().frames.size()) + " frames at " +
             Num(std::round(take->fps() * 100) / 100) + " fps";
    if (c.type == protocol::ContentType::kBall)
      shown += "; exposure " + Num(std::round(c.exposure_ms * 1000) / 1000) + " ms (" +
               (c.exposure_given ? std::string("content.exposure_ms")
                : take->take().camera().exposure_ms ? std::string("the take's camera.json exposure_ms")
                                                    : std::string("half a frame: the take's camera states no "
                                                                  "exposure_ms; give content.exposure_ms")) +
               ")";
    shown += "\n";
  }
  if (prepared.protocol.groups)
    shown += "  group: " + prepared.group +
             (prepared.protocol.groups->assign == protocol::GroupAssign::kBalanced
                  ? " (balanced: a run takes the group with the fewest sessions in its record)\n"
                  : " (by participant number)\n");
  if (prepared.scene) {
    const procedure::BlurPlans plans = procedure::CountBlurPlans(prepared);
    const protocol::Content& c = prepared.protocol.content;
    std::snprintf(line, sizeof line, "by depth, where its blur changes by %g %s or more across it: "
                  "content.depth_blur_threshold", c.depth_blur_threshold,
                  c.depth_blur_threshold_unit == protocol::ThresholdUnit::kArcmin ? "arcmin" : "screen px");
    const std::string where = line;
    shown += "  blur plan: ";
    if (plans.fixed > 0) {
      std::snprintf(line, sizeof line, "%zu of %zu trials blur the object pixel by pixel (%s), the rest with one "
                    "radius", plans.fixed_per_pixel, plans.fixed, where.c_str());
      shown += line;
    }
    if (plans.leveled > 0) {  // run plans each at its level as it is shown
      std::snprintf(line, sizeof line,
                    "%sthe %zu procedure trials are planned at their level as each is shown: %zu would be per pixel%s "
                    "at the procedure's least level, %zu at its largest",
                    plans.fixed > 0 ? "; " : "", plans.leveled, plans.per_pixel_at_least,
                    plans.fixed > 0 ? "" : (" (" + where + ")").c_str(), plans.per_pixel_at_most);
      shown += line;
    }
    shown += "\n";
  }
  return shown;
}

// --no-files: the protocol alone, and each group's trial list.
std::vector<CheckedGroup> CheckProtocolAlone(const Args& args, protocol::Protocol* p) {
  std::vector<CheckedGroup> checked;
  *p = protocol::LoadProtocol(args.file, protocol::ValidateOptions{false});
  // As PrepareStudy does for run: each design variable recorded in a column of its own.
  procedure::CheckRecordedNames(*p);
  for (const std::string& group : GroupsToCheck(*p, args.group)) {
    const uint64_t seed = args.seed ? *args.seed : protocol::DefaultSeed(p->name, args.participant);
    checked.push_back({group, seed, protocol::BuildTrials(*p, args.participant, seed, group), ""});
  }
  return checked;
}

// What `blurcue run` does before its first trial, through the same functions: files decoded, the calibration read,
// every trial's scene and radii worked out - for each group's blocks. With `observer` (--plan), what it can see, and
// the QUEST+ grids that do not hold it (in `grid_problems`, each once).
std::vector<CheckedGroup> CheckAsRunWould(const Args& args, const std::optional<procedure::ObserverParams>& observer,
                                          protocol::Protocol* p, std::vector<std::string>* grid_problems) {
  std::vector<CheckedGroup> checked;
  try {
    procedure::PreparedSession prepared = procedure::PrepareStudy(args.file, args.display);
    for (const std::string& group : GroupsToCheck(prepared.protocol, args.group)) {
      procedure::PrepareParticipant(&prepared, args.participant, args.seed, group);
      std::string shown = PresentationLines(prepared);
      if (const std::string note = procedure::UndeterminedBlurNote(prepared); !note.empty())
        shown += "  note: " + note + "\n";
      if (observer) {
        // What `run --observer` refuses before its first trial, refused here by the same check.
        procedure::CheckObserverCanAnswer(*observer, prepared.protocol);
        for (const std::string& text : procedure::VisibilityLines(prepared, *observer, args.visible, false))
          shown += "  " + text + "\n";
        for (const std::string& problem : plan::QuestGridProblems(prepared, *observer, args.file))
          if (std::find(grid_problems->begin(), grid_problems->end(), problem) == grid_problems->end())
            grid_problems->push_back(problem);
        if (checked.empty()) shown += ProcedureDesignLines(prepared.protocol, args);
      }
      checked.push_back({group, prepared.seed, prepared.trials, shown});
    }
    *p = std::move(prepared.protocol);
  } catch (const Error& e) {
    const std::string message = e.what();
    if (message.find(": no such file: ") == std::string::npos) throw;
    // One problem is one line, the hint at its end; a list keeps its own lines and the hint as the last.
    const std::string hint = "'blurcue init DIR --from EXAMPLE' makes a shipped example a study folder with its own "
                             "scene and calibration; --no-files skips the file checks";
    if (e.lines().size() == 1) throw Error(e.kind(), message + " (" + hint + ")");
    throw e.Wrapped(e.kind(), "", "(" + hint + ")");
  }
  return checked;
}

// Whether a block's planned trials may not all be shown: a staircase's stop rule, or a practice criterion (the runs
// after the one that met it) ends it sooner, the rest recorded as skipped.
bool CanEndSooner(const protocol::Block& b) {
  return (b.procedure && b.procedure->stop_reversals > 0) || b.criterion;
}

// A checked group's summary: its trials (with --list), their count and hash, and each block's share; "up to" where
// a block can end sooner (the list holds every trial it may show).
void PrintCheckedGroup(const CheckedGroup& one, const protocol::Protocol& p, const Args& args) {
  const auto& trials = one.trials;
  if (args.list)
    for (const auto& t : trials) std::cout << protocol::ToJson(t).dump() << "\n";
  auto sooner = [&](const protocol::Trial& t) {
    const protocol::Block* b = protocol::BlockOf(p, t);
    return b && CanEndSooner(*b);
  };
  const bool up_to = std::any_of(trials.begin(), trials.end(), sooner);
  std::cout << "ok: " << (up_to ? "up to " : "") << trials.size() << " trials for participant " << args.participant
            << " with seed " << one.seed << " (hash " << HashHex(protocol::TrialsHash(trials)) << ")"
            << (one.group.empty() ? "" : ", group " + one.group) << "\n";
  std::string counts;
  int practice = 0;
  bool practice_sooner = false;
  for (const auto& t : trials)
    if (t.practice) ++practice, practice_sooner = practice_sooner || sooner(t);
  if (practice > 0) counts = std::string("practice ") + (practice_sooner ? "up to " : "") + std::to_string(practice);
  for (const auto& b : p.blocks) {
    // A group's own blocks (and those every group runs); another group's are its to report.
    if (!one.group.empty() && !b.groups.empty() &&
        std::find(b.groups.begin(), b.groups.end(), one.group) == b.groups.end())
      continue;
    int n = 0;
    for (const auto& t : trials) n += (!t.practice && t.block == b.name) ? 1 : 0;
    counts += (counts.empty() ? "" : ", ") + b.name + " " + (CanEndSooner(b) && n > 0 ? "up to " : "") +
              std::to_string(n) + " (" + protocol::ToString(b.task) + ", " + protocol::ToString(b.counterbalance) +
              ")";
  }
  std::cout << "  " << counts << "\n" << one.shown;
}

}  // namespace

void AddValidateCommand(CLI::App& app) {
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "validate",
      "Check a study protocol and build its trial list.\n"
      "Every problem is reported at once, one per line, as FILE: /json/pointer: what is wrong, got VALUE\n"
      "(exit code 3). Then the checks blurcue run makes before its first trial, through the same code: the\n"
      "calibration is read, every image decoded and its size checked, every trial's blur radii worked out - a\n"
      "protocol that validates is one that runs. When the protocol is valid, prints the number of trials and the\n"
      "hash of the list that a session with the same participant and seed would run.\n"
      "--plan adds what a participant can see: for every distinct stimulus pair, on the display profile, the\n"
      "probability that an observer (--observer's model, without lapses or bias) tells its two sides apart in a\n"
      "2AFC, and the pairs below --visible flagged as invisible at that viewing distance.\n"
      "A protocol with between-subject groups is checked for every group (each group's trial count, checks and\n"
      "--plan), or for the one --group names.\n"
      "Example: blurcue validate protocols/test2-moving-balls.json --participant P4 --seed 4");
  cmd->add_option("protocol", args->file, "the protocol JSON file")->required();
  cmd->add_flag("--no-files", args->no_files, "check the protocol alone: skip the referenced files (scene, calib, "
                                              "images) and the per-trial checks that need them");
  cmd->add_option("--participant", args->participant, "participant id (its trailing number decides by_participant "
                                                      "counterbalancing)")->capture_default_str();
  cmd->add_option("--seed", args->seed, "seed of the trial order (default: the one blurcue run gives the participant, "
                                        "derived from the study name and the participant id)")
      ->transform(SeedValidator());
  cmd->add_option("--display", args->display, "the monitor's display profile, as blurcue run --display")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--list", args->list, "print the trial list as JSON, one trial per line");
  cmd->add_option("--group", args->group, "a protocol with groups: check only this group (default: every group)");
  CLI::Option* plan = cmd->add_flag("--plan", args->plan, "also predict, per distinct stimulus pair, whether an observer can tell its "
                                      "two sides apart on this display (flags the invisible ones), and per "
                                      "depth-matching distance which levels it cannot tell from the real picture");
  cmd->add_option("--observer", args->observer, "with --plan: the observer model, as blurcue run --observer "
                                                "(sim: the arcmin model's defaults); a protocol that observer cannot "
                                                "answer is refused as run refuses it")
      ->capture_default_str()->needs(plan);  // an option nothing would read is refused
  cmd->add_option("--visible", args->visible, "with --plan: the predicted share correct (2AFC) below which a pair "
                                              "is flagged invisible")
      ->capture_default_str()->check(FiniteRange(0.5, 1, "share correct"))->needs(plan);
  cmd->callback([args] {
    // The observer is checked before any file is read: a typo in it is a usage error, whatever the protocol.
    std::optional<procedure::ObserverParams> observer;
    if (args->plan) {
      if (args->no_files)
        throw Error(ErrorKind::kUsage, "--plan needs the radii the files give; it cannot go with --no-files");
      observer = procedure::ParseObserver(args->observer);
    }
    protocol::Protocol p;
    std::vector<std::string> grid_problems;  // --plan: a QUEST+ grid that does not hold the observer
    const std::vector<CheckedGroup> checked =
        args->no_files ? CheckProtocolAlone(*args, &p) : CheckAsRunWould(*args, observer, &p, &grid_problems);
    // Each on its own line, as a protocol's problems are (one joined text came out as one line with "\n" in it).
    if (!grid_problems.empty()) throw Error(ErrorKind::kInput, grid_problems);
    for (const CheckedGroup& one : checked) PrintCheckedGroup(one, p, *args);
  });
}

}  // namespace blurcue::cli
