#pragma once
// The subcommands of `blurcue`. Each Add* registers one CLI11 subcommand whose callback does the work and throws
// blurcue::Error on failure; main() turns that into one line on stderr and the error's exit code.
#include <CLI/CLI.hpp>

namespace blurcue::cli {

// --seed: a whole number 0 .. 2^64 - 1 (CLI11 alone would wrap "-3" into a huge unsigned number).
inline CLI::Validator SeedValidator() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        const bool digits = !text.empty() && text.size() <= 20 &&
                            text.find_first_not_of("0123456789") == std::string::npos &&
                            (text.size() < 20 || text <= "18446744073709551615");
        return digits ? "" : "must be a whole number from 0 to 18446744073709551615, got '" + text + "'";
      },
      "SEED");
}

void AddEstimateCommand(CLI::App& app);     // estimate_command.cc
void AddSynthSceneCommand(CLI::App& app);   // synth_scene_command.cc
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

}  // namespace blurcue::cli
