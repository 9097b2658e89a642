// blurcue run: one participant's session of a protocol, answered by a person at a window or by the simulated
// observer, every answer committed to the SQLite record before the next trial.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "cli/commands.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "core/typed.h"
#include "session/runner.h"
#include "store/sqlite.h"

namespace blurcue::cli {
namespace {

std::string Clock(double seconds) {
  const int s = std::max(0, int(std::lround(seconds)));
  char text[32];
  std::snprintf(text, sizeof text, "%d:%02d", s / 60, s % 60);
  return text;
}

// A terminal gets one line rewritten after every answer; a log gets about ten lines.
void SayProgress(const session::TrialProgress& p, bool tty) {
  if (!tty && p.done % std::max<int64_t>(1, p.total / 10) != 0 && p.done != p.total) return;
  std::fprintf(stderr, "%strial %lld of %lld  elapsed %s  remaining ~%s%s", tty ? "\r" : "",
               static_cast<long long>(p.done), static_cast<long long>(p.total), Clock(p.elapsed_s).c_str(),
               Clock(p.remaining_s).c_str(), tty ? "   " : "\n");
}

// The participant's information a protocol asks for and --info did not give, asked in the terminal.
bool AskInTerminal(const std::string& prompt, std::string* answer) {
  std::fputs(prompt.c_str(), stderr);
  int c;
  while ((c = std::getchar()) != EOF && c != '\n') *answer += char(c);
  return c != EOF;
}

// A refused run leaves the record as it found it. A read-only look at a record in WAL mode (its session numbers and
// groups, before anything is checked) makes its -wal and -shm files, which only a read-write connection removes as
// it closes: a run that starts removes them when it ends, one refused before (a --capture folder, a protocol) left
// them. So after a refusal, where neither was there before, one connection opens the record, reads its schema and
// closes: SQLite, the last to close, removes them (and leaves them while another process has the record open).
void TidySidecars(const std::filesystem::path& db) {
  std::error_code error;
  const bool left = std::filesystem::exists(db.string() + "-wal", error) ||
                    std::filesystem::exists(db.string() + "-shm", error);
  if (!left || !std::filesystem::is_regular_file(db, error)) return;
  try {
    store::Database record(db, store::OpenMode::kReadWrite);
    record.QueryInt64("SELECT count(*) FROM sqlite_schema");
  } catch (const std::exception&) {  // not a record SQLite opens: its refusal is the one to report
  }
}

struct RunArgs {
  session::RunOptions options;
  std::string protocol, db, observer;
  std::optional<uint64_t> seed;
  std::vector<std::string> info;
};

// What `run` does with its options: the session, then one line of what it recorded.
void Run(const RunArgs& args) {
  session::RunOptions options = args.options;
  options.protocol_file = args.protocol;
  options.db = args.db;
  options.observer = args.observer;
  options.seed = args.seed;
  for (const std::string& item : args.info) {
    const size_t eq = item.find('=');
    if (eq == std::string::npos || eq == 0)
      throw Error(ErrorKind::kUsage, "--info: must be KEY=VALUE, got " + Echo(item));
    const std::string key = item.substr(0, eq);
    // A key given twice would keep one of its values unsaid: which one was meant is the experimenter's to say.
    for (const auto& given : options.info)
      if (given.first == key)
        throw Error(ErrorKind::kUsage, "--info " + Echo(key, false) + " is given twice (" +
                                           Echo(given.first + "=" + given.second) + " and " + Echo(item) + ")");
    options.info.emplace_back(key, item.substr(eq + 1));
  }
  const bool tty = isatty(2);
  bool said = false;
  options.progress = [tty, &said](const session::TrialProgress& p) {
    SayProgress(p, tty);
    said = true;
  };
  if (isatty(0)) options.ask = AskInTerminal;
  std::error_code error;
  const bool sidecars_before = std::filesystem::exists(args.db + "-wal", error) ||
                               std::filesystem::exists(args.db + "-shm", error);
  session::RunResult r;
  try {
    r = session::RunSession(options);
  } catch (...) {
    if (!sidecars_before) TidySidecars(args.db);
    throw;
  }
  if (tty && said) std::fprintf(stderr, "\n");
  // Trials a stopped procedure skipped are recorded too: counted as done, and said apart.
  const int64_t by_stop_rule = r.skipped_now - r.skipped_by_criterion_now;
  std::string skipped;
  if (by_stop_rule > 0) skipped += ", " + std::to_string(by_stop_rule) + " skipped now: their procedure had stopped";
  if (r.skipped_by_criterion_now > 0)
    skipped += ", " + std::to_string(r.skipped_by_criterion_now) + " practice trials skipped now: the criterion was met";
  std::printf("%s: participant %s, session %lld, the participant's session %lld, seed %llu: %lld of %lld trials %s "
              "(%lld answered now%s%s)%s\n",
              args.db.c_str(), options.participant.c_str(), static_cast<long long>(r.session_id),
              static_cast<long long>(r.session_number),
              static_cast<unsigned long long>(r.seed),
              static_cast<long long>(r.answered_before + r.answered_now + r.skipped_now),
              static_cast<long long>(r.trial_count), r.skipped_now > 0 ? "done" : "answered",
              static_cast<long long>(r.answered_now), skipped.c_str(),
              r.dropped_frames > 0 ? (", " + std::to_string(r.dropped_frames) + " dropped frames in the session").c_str() : "",
              r.completed ? "; completed" : "; not finished - continue with --resume");
  if (!r.blur_note.empty()) std::printf("note: %s\n", r.blur_note.c_str());
  if (!r.ids_like.empty())
    std::printf("note: participant %s is new to this record's study; it also holds %s, differing only in case: ids are "
                "case-sensitive, so these are different people (if one was meant, `blurcue sessions --db %s` lists "
                "them)\n", options.participant.c_str(), r.ids_like.c_str(), args.db.c_str());
  if (const int signal = r.interrupted; signal != 0 && !r.completed) {  // session::RunTrials stopped between trials
    std::fflush(stdout);
    std::fprintf(stderr, "blurcue run: interrupted (%s): every answer so far is saved in %s; continue the session "
                         "with --resume\n", InterruptName(signal), args.db.c_str());
    std::exit(InterruptExitCode(signal));
  }
}

}  // namespace

void AddRunCommand(CLI::App& app) {
  using Args = RunArgs;
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "run",
      "Run one participant's session of a study protocol and record every answer in a SQLite file.\n"
      "The whole trial list is made up front from the protocol, the participant and the seed, and saved; each\n"
      "answer is committed in its own transaction before the next trial starts, so a kill, a crash or a power loss\n"
      "loses nothing already answered. --resume continues the participant's unfinished session at its first\n"
      "unanswered trial, in the same order; with nothing to continue it says what it found and exits 3 (it never\n"
      "starts a new session). A protocol file reformatted by an editor is the same protocol; one whose content\n"
      "changed cannot resume the session: close it with 'blurcue sessions --db X --abort ID' (answers kept).\n"
      "One process at a time may write a session; a second is refused. --db must be a new file or a blurcue record:\n"
      "another program's SQLite file is refused untouched.\n"
      "\n"
      "With a person (no --observer): a window opens (the protocol's display size; fullscreen if it says so).\n"
      "  forced choice: the protocol's left / right / can't-tell keys (default Left, Right, Down);\n"
      "  adjustment:    previous / next keys or the mouse wheel step through the levels, Return or a click accepts;\n"
      "  Escape pauses and asks whether to quit (Q) or go on (Return). Quitting keeps every answer so far.\n"
      "  Ctrl-C (or a kill) in the terminal stops the session between trials the same way (exit 130).\n"
      "Response times run from the first frame of the stimulus; every frame's flip time and dropped frames are\n"
      "recorded. The terminal shows trial n of N, the time elapsed and an estimate of the time left.\n"
      "\n"
      "With --observer sim[:params] a simulated observer answers through the same key mapping, headless on a\n"
      "simulated clock (add --window to watch it in real time). sim alone is model=arcmin with its defaults;\n"
      "sim:NAME=VALUE,... sets parameters (the canonical form of all of them is recorded with the session).\n"
      "  model=arcmin  blur discrimination in visual angle: the dipper Watson & Ahumada 2011 (J. Vision 11(5):10)\n"
      "                review, as intrinsic blur plus Weber's law. A blur of std s = r/2 arcmin is seen as\n"
      "                E = (s^p + s_i^p)^(1/p); two are told apart by Weber's law on E (75 % correct at E ratio\n"
      "                1 + weber). Radii reach it in arcmin through the display profile (--display)\n"
      "    intrinsic=0.6  the eye's equivalent intrinsic blur s_i (Gaussian std, arcmin)\n"
      "    weber=0.35     Weber fraction at 75 % correct        exponent=2   p, how blur and s_i combine\n"
      "    side=0         bias toward the left (noise sds)      blurrier=0.3 bias toward the more blurred side\n"
      "    rthard=0.5     a trial it cannot see takes (1 + rthard) x rt\n"
      "                Depth matching: it looks at every level once and takes the one it can least tell from the\n"
      "                real picture - each level's blur is its Butterworth's equivalent Gaussian (s = 0.187 / cut-off\n"
      "                picture widths), the real one the thin lens of content.real_camera (which it needs)\n"
      "  model=pixel   the observer of earlier versions, on photo px (a spec naming one of its parameters without\n"
      "                model= is it)\n"
      "    jnd=0.6        sd of its noise on the blur mismatch (px)   bias=0.2  preference for the more blurred side (px)\n"
      "    cutoff1m=14, slope=-0.8, sdlog=0.15, tol=0.1: depth matching aims at the cut-off\n"
      "                   cutoff1m * distance_m^slope (cycles per picture width), whatever the real picture shows\n"
      "  both: lapse=0.04 rate of random answers; rt=900 median response time (ms; log-normal, sd 0.3 in log units);\n"
      "        step=350 median time between depth-matching steps (ms)\n"
      "blurcue validate --plan shows, per stimulus pair, how often this observer would tell the sides apart, and per\n"
      "depth-matching distance, which levels it cannot tell from the real picture.\n"
      "\n"
      "Examples:\n"
      "  blurcue run protocols/test1-static-grids.json --participant P3 --db results/study.sqlite\n"
      "  blurcue run protocols/test2-moving-balls.json --participant S1 --db sim.sqlite --observer sim:weber=0.5\n"
      "  blurcue run protocols/test1-static-grids.json --participant P3 --db results/study.sqlite --resume\n"
      "  blurcue run protocols/test1-static-grids.json --participant T1 --db t.sqlite --observer sim --capture shots");
  cmd->add_option("protocol", args->protocol, "the protocol JSON file")->required();  // missing: exit 3, as validate
  cmd->add_option("--participant", args->options.participant, "participant id, e.g. P7 (its trailing number "
                                                              "decides by_participant sides)")->required();
  cmd->add_option("--db", args->db, "the SQLite record (created if missing)")->required();
  cmd->add_option("--seed", args->seed, "seed of the trial order (default: derived from the study name, the "
                                        "participant id and the session number; always recorded; a seed an "
                                        "earlier session of the participant used is refused)")
      ->transform(SeedValidator());
  CLI::Option* observer =
      cmd->add_option("--observer", args->observer, "sim or sim:NAME=VALUE,... - a simulated observer answers");
  cmd->add_option("--display", args->options.display_profile,
                  "the monitor's display profile (overrides the protocol's display.profile; recorded with the "
                  "session, with each radius in screen px and arcmin)")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--resume", args->options.resume, "continue the participant's unfinished session");
  cmd->add_flag("--again", args->options.again, "another session for a participant who completed the study (a "
                                                "participant id seen before is refused otherwise); it is numbered "
                                                "next and gets a seed of its own");
  // Options nothing would read are refused: --window and --sim-fps are the simulated observer's, --sim-fps headless.
  CLI::Option* window =
      cmd->add_flag("--window", args->options.window, "with --observer: show the session in a window, in real time")
          ->needs(observer);
  cmd->add_option("--sim-fps", args->options.sim_fps,
                  "with --observer, headless: frames rendered per simulated second (default 4; a study on video: the "
                  "take's frame rate, so that every frame of the take is shown and recorded)")
      ->check(FiniteRange(0.1, 1000, "frames per second"))->needs(observer)->excludes(window);
  cmd->add_option("--info", args->info,
                  "KEY=VALUE: participant information the protocol asks for (participant_info), repeatable; missing "
                  "required ones are asked for in the terminal");
  cmd->add_option("--capture", args->options.capture_dir,
                  "save each trial's first frame exactly as presented (DIR/trial-NNNN.png, the window's size) and "
                  "what it shows (DIR/trial-NNNN.json: the display, the photo's place, each object's centre, screen "
                  "outline, radius in photo px, screen px and arcmin, size in degrees); writing them delays that "
                  "frame's flip, so a capture run is for checking a set-up, not for data");
  cmd->add_option("--stop-after", args->options.stop_after, "leave the session after this many answers (it stays "
                                                            "resumable; for tests and split sittings)")
      ->transform(IntRange(0, 1000000));
  cmd->callback([args] { Run(*args); });
}

}  // namespace blurcue::cli
