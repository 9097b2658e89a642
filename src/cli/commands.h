#pragma once
// The subcommands of `blurcue`. Each Add* registers one CLI11 subcommand whose callback does the work and throws
// blurcue::Error on failure; main() turns that into one line on stderr and the error's exit code.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "core/names.h"
#include "core/typed.h"

namespace blurcue::cli {

// A bound as the messages print it: 500, 0.001, 10000000.
inline std::string BoundText(double v) {
  std::ostringstream s;
  s << std::setprecision(12) << v;
  return s.str();
}

// A number option's range with its unit: "--radius-px: must be in [0, 500] px, got nan". CLI11 alone takes "nan",
// "inf" and "1e308" as doubles and lets them through NonNegativeNumber; every numeric option of every command
// names its range here instead. `note` (optional) is added in brackets after the range; `open_low` excludes lo
// ("(0, 1000] m").
inline CLI::Validator FiniteRange(double lo, double hi, const std::string& unit, const std::string& note = "",
                                  bool open_low = false) {
  const std::string range = "in " + std::string(open_low ? "(" : "[") + BoundText(lo) + ", " + BoundText(hi) + "]" +
                            (unit.empty() ? "" : " " + unit);
  const std::string what = "must be " + std::string(unit.empty() ? "a number " : "") + range +
                           (note.empty() ? "" : " (" + note + ")") + ", got ";
  return CLI::Validator(
      [lo, hi, open_low, what](std::string& text) -> std::string {
        const std::optional<double> v = ParseDecimal(text);
        if (!v) return what + Echo(text);
        const bool above = open_low ? *v > lo : *v >= lo;
        return above && *v <= hi ? "" : what + Echo(text, false);
      },
      range);
}

// FiniteRange without its lower bound: (0, hi].
inline CLI::Validator FinitePositive(double hi, const std::string& unit, const std::string& note = "") {
  return FiniteRange(0, hi, unit, note, true);
}

// A whole-number option's range: "--columns: must be a whole number in [1, 20], got '1e3'". Decimal only: the
// text is rewritten to plain digits, because CLI11 would read "010" as octal 8 and "0x10" as 16.
inline CLI::Validator IntRange(long long lo, long long hi, const std::string& unit = "") {
  const std::string range = "in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]" +
                            (unit.empty() ? "" : " " + unit);
  const std::string what = "must be a whole number " + range + ", got ";
  return CLI::Validator(
      [lo, hi, what](std::string& text) -> std::string {
        const size_t sign = !text.empty() && (text[0] == '-' || text[0] == '+') ? 1 : 0;
        const bool whole = text.size() > sign && text.find_first_not_of("0123456789", sign) == std::string::npos;
        if (!whole) return what + Echo(text);
        errno = 0;
        const long long v = std::strtoll(text.c_str(), nullptr, 10);
        if (errno == ERANGE || v < lo || v > hi) return what + Echo(text, false);
        text = std::to_string(v);
        return "";
      },
      range);
}

// --seed: a whole number 0 .. 2^64 - 1 (CLI11 alone would wrap "-3" into a huge unsigned number), as typed or as
// export writes it (a leading "s").
inline CLI::Validator SeedValidator() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        // An exported seed is written "s123...": a number no spreadsheet or R can round.
        if (text.size() > 1 && text[0] == 's') text.erase(0, 1);
        const bool digits = !text.empty() && text.size() <= 20 &&
                            text.find_first_not_of("0123456789") == std::string::npos &&
                            (text.size() < 20 || text <= "18446744073709551615");
        return digits ? "" : "must be a whole number from 0 to 18446744073709551615, got " + Echo(text);
      },
      "SEED");
}

// A word option's allowed values, for every command's enum options (--psf, --preset, --method, ...): CLI::IsMember
// with a did-you-mean, "--psf: must be one of disc, gaussian, got 'disk' (did you mean disc?)". Its help text is
// IsMember's ("{disc,gaussian}"), so the commands' --help reads as before.
inline CLI::Validator OneOf(const std::vector<std::string>& words) {
  std::string set, list;
  for (size_t i = 0; i < words.size(); ++i) {
    set += (i == 0 ? "" : ",") + words[i];
    list += (i == 0 ? "" : ", ") + words[i];
  }
  return CLI::Validator(
      [words, list](std::string& text) -> std::string {
        if (std::find(words.begin(), words.end(), text) != words.end()) return "";
        return "must be one of " + list + ", got " + Echo(text) + DidYouMean(text, words);
      },
      "{" + set + "}");
}

void AddEstimateCommand(CLI::App& app);     // estimate_command.cc
void AddSynthSceneCommand(CLI::App& app);   // synth_scene_command.cc
void AddSynthTakeCommand(CLI::App& app);    // synth_take_command.cc
void AddTrackCommand(CLI::App& app);        // track_command.cc
void AddArCommand(CLI::App& app);           // ar_command.cc
void AddLiveCommand(CLI::App& app);         // live_command.cc
void AddCameraCommand(CLI::App& app);       // camera_command.cc
void AddInitCommand(CLI::App& app);         // init_command.cc
void AddCalibrateCommand(CLI::App& app);    // calibrate_command.cc
void AddBenchCommand(CLI::App& app);        // bench_command.cc
void AddBlurCommand(CLI::App& app);         // blur_command.cc
void AddRenderCommand(CLI::App& app);       // render_command.cc
void AddAnimateCommand(CLI::App& app);      // animate_command.cc
void AddExportCommand(CLI::App& app);       // record_commands.cc
void AddMergeCommand(CLI::App& app);        // record_commands.cc
void AddSessionsCommand(CLI::App& app);     // record_commands.cc
void AddMakeStimuliCommand(CLI::App& app);  // make_stimuli_command.cc
void AddSynthPicturesCommand(CLI::App& app);  // make_stimuli_command.cc
void AddValidateCommand(CLI::App& app);     // validate_command.cc
void AddRunCommand(CLI::App& app);          // run_command.cc
void AddPreviewCommand(CLI::App& app);      // preview_command.cc
void AddReportCommand(CLI::App& app);       // report_command.cc
void AddDisplayCommand(CLI::App& app);      // display_command.cc
void AddInfoCommand(CLI::App& app);         // info_command.cc
void AddPlanCommand(CLI::App& app);         // plan_command.cc

}  // namespace blurcue::cli
