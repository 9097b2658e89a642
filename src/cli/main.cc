// blurcue: measure the defocus blur of a real scene, predict it anywhere, render and run depth-cue studies.
#include <algorithm>
#include <cctype>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>

#include "cli/commands.h"
#include "core/error.h"
#include "core/names.h"
#include "core/typed.h"

namespace {

// After a failed parse: the first name on the command line that its command does not know - an option, or a
// subcommand of bench or display - with the nearest known one ("synth-scene: unknown option --post-filtr (did you
// mean --post-filter?)"); "" when every name is known and the parse failed for another reason (CLI11's message
// says which). CLI11 alone said "The following arguments were not expected: sharpen --post-filtr", or, where the
// slip left a required option out, only that. Read as CLI11 reads: an option's values are the words after it (its
// least count of them, none for a flag), "--" ends the options, "-5" is a number.
std::string UnknownName(CLI::App& app, int argc, char** argv) {
  CLI::App* at = &app;
  std::string command;  // "synth-scene", "bench blur"
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--") break;
    const bool is_long = arg.size() > 2 && arg.compare(0, 2, "--") == 0;
    const bool is_short =
        !is_long && arg.size() > 1 && arg[0] == '-' && std::isalpha(static_cast<unsigned char>(arg[1]));
    if (!is_long && !is_short) {
      std::vector<std::string> subcommands;
      for (CLI::App* sub : at->get_subcommands({}))
        if (!sub->get_name().empty()) subcommands.push_back(sub->get_name());  // not an option group
      if (const auto it = std::find(subcommands.begin(), subcommands.end(), arg); it != subcommands.end()) {
        at = at->get_subcommand(arg);
        command += (command.empty() ? "" : " ") + arg;
      } else if (!subcommands.empty() && at != &app &&
                 at->get_options([](const CLI::Option* o) { return o->get_positional(); }).empty()) {
        const std::string hint = blurcue::DidYouMean(arg, subcommands);
        return command + ": unknown command " + blurcue::Echo(arg) +
               (hint.empty() ? "; 'blurcue " + command + " --help' lists them" : hint);
      }
      continue;
    }
    const std::string name = is_long ? arg.substr(0, arg.find('=')) : arg.substr(0, 2);
    if (const CLI::Option* option = at->get_option_no_throw(name)) {
      const bool inline_value = is_long ? arg.find('=') != std::string::npos : arg.size() > 2;
      i += std::max(0, option->get_expected_min() - (inline_value ? 1 : 0));
      continue;
    }
    std::vector<std::string> known;
    for (const CLI::Option* o : at->get_options()) {
      for (const std::string& l : o->get_lnames()) known.push_back("--" + l);
      for (const std::string& s : o->get_snames()) known.push_back("-" + s);
    }
    const std::string hint = blurcue::DidYouMean(name, known);
    const std::string who = command.empty() ? "blurcue" : "blurcue " + command;
    return (command.empty() ? "" : command + ": ") + "unknown option " + blurcue::Echo(name, false) +
           (hint.empty() ? "; '" + who + " --help' lists the options" : hint);
  }
  return "";
}

}  // namespace

int main(int argc, char** argv) {
  using namespace blurcue;
  CLI::App app{"blurcue " BLURCUE_VERSION
               " - blur as a depth cue: calibrate a scene's defocus blur, predict it anywhere, run studies.\n"
               "Typical flow: synth-scene (or a photo + camera.json) -> calibrate -> render / animate stimuli;\n"
               "validate and preview a study protocol -> run sessions -> export, merge and report the records.\n"
               "Run 'blurcue COMMAND --help' for the options of one command."};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("blurcue ") + BLURCUE_VERSION);

  // The command table: one entry per subcommand, each in its own file under src/cli/.
  const std::vector<std::pair<const char*, void (*)(CLI::App&)>> commands = {
      {"init", &cli::AddInitCommand},
      {"synth-scene", &cli::AddSynthSceneCommand},
      {"synth-take", &cli::AddSynthTakeCommand},
      {"camera", &cli::AddCameraCommand},
      {"calibrate", &cli::AddCalibrateCommand},
      {"track", &cli::AddTrackCommand},
      {"ar", &cli::AddArCommand},
      {"live", &cli::AddLiveCommand},
      {"estimate", &cli::AddEstimateCommand},
      {"make-stimuli", &cli::AddMakeStimuliCommand},
      {"synth-pictures", &cli::AddSynthPicturesCommand},
      {"blur", &cli::AddBlurCommand},
      {"render", &cli::AddRenderCommand},
      {"animate", &cli::AddAnimateCommand},
      {"validate", &cli::AddValidateCommand},
      {"preview", &cli::AddPreviewCommand},
      {"run", &cli::AddRunCommand},
      {"sessions", &cli::AddSessionsCommand},
      {"export", &cli::AddExportCommand},
      {"merge", &cli::AddMergeCommand},
      {"report", &cli::AddReportCommand},
      {"plan", &cli::AddPlanCommand},
      {"display", &cli::AddDisplayCommand},
      {"bench", &cli::AddBenchCommand},
      {"info", &cli::AddInfoCommand},
  };
  for (const auto& [name, add] : commands) add(app);
  // 'blurcue --help' lists each command with its first sentence; the rest is its own --help's footer.
  for (CLI::App* sub : app.get_subcommands({})) {
    const std::string text = sub->get_description();
    size_t cut = std::string::npos;
    for (size_t i = 0; i < text.size() && cut == std::string::npos; ++i) {
      if (text[i] != '.' || (i + 1 < text.size() && text[i + 1] != ' ' && text[i + 1] != '\n')) continue;
      const size_t word = text.find_last_of(" \n(", i) + 1;  // npos + 1 = 0
      const std::string before = text.substr(word, i - word);
      if (before != "eq" && before != "Eq" && before != "e.g" && before != "i.e") cut = i + 1;
    }
    const bool long_sentence = cut == std::string::npos || cut > 160;
    if (long_sentence) cut = text.find('\n');
    if (cut == std::string::npos || cut >= text.size()) continue;
    std::string first = text.substr(0, cut) + (long_sentence && text[cut - 1] != ':' ? " ..." : "");
    std::replace(first.begin(), first.end(), '\n', ' ');
    const size_t rest = text.find_first_not_of(" \n", cut);
    sub->description(first);
    if (rest != std::string::npos) sub->footer(text.substr(rest));
  }

  // An unknown command says how to list the known ones (CLI11 alone would say "a subcommand is required").
  if (argc > 1 && argv[1][0] != '-') {
    bool known = false;
    for (const auto& [name, add] : commands) known = known || name == std::string(argv[1]);
    if (!known) {
      std::cerr << "blurcue: unknown command '" << OneLine(argv[1]) << "'; 'blurcue --help' lists the commands\n";
      return static_cast<int>(ErrorKind::kUsage);
    }
  }

  // An empty value names nothing (no file, folder, number or spec): refused for every option and argument alike,
  // before a command reads or writes anything ("--out ''" used to reach std::filesystem and end as an internal error).
  for (int i = 2; i < argc; ++i) {
    const std::string arg = argv[i], before = argv[i - 1];
    const bool empty_value = arg.empty() || (arg.rfind("--", 0) == 0 && arg.back() == '=');
    if (!empty_value) continue;
    const std::string option =
        !arg.empty() ? arg.substr(0, arg.size() - 1) : before.rfind("-", 0) == 0 ? before : "an argument";
    std::cerr << "blurcue: " << OneLine(option) << ": must not be empty\n";
    return static_cast<int>(ErrorKind::kUsage);
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    // One line like every other error (CLI11's own printer adds "Run with --help for more information."); a name
    // the command does not know is said first, with the nearest it does.
    const std::string unknown = UnknownName(app, argc, argv);
    std::cerr << "blurcue: " << OneLine(unknown.empty() ? std::string(e.what()) : unknown) << "\n";
    return static_cast<int>(ErrorKind::kUsage);
  } catch (const Error& e) {
    // Each problem on its own line (a protocol's every problem at once), each line escaped.
    const std::vector<std::string> lines = e.lines();
    for (size_t i = 0; i < lines.size(); ++i) std::cerr << (i == 0 ? "blurcue: " : "") << OneLine(lines[i]) << "\n";
    return e.exit_code();
  } catch (const cv::Exception& e) {
    std::cerr << "blurcue: OpenCV: " << e.err << " (" << e.func << ")\n";
    return static_cast<int>(ErrorKind::kInternal);
  } catch (const std::exception& e) {
    std::cerr << "blurcue: " << OneLine(e.what()) << "\n";
    return static_cast<int>(ErrorKind::kInternal);
  }
  return 0;
}
