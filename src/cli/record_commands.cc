// blurcue export / merge: the SQLite record out to analysis tables, and several stations' records into one.
#include <cstdio>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "store/export.h"

namespace blurcue::cli {

void AddExportCommand(CLI::App& app) {
  struct Args {
    std::string db, out;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "export",
      "Write a record's answers as a long-format table: DIR/trials.csv, one row per planned trial (answered or\n"
      "not), the same columns for every participant (study, protocol_hash, participant, session, seed,\n"
      "trial_index, block, every trial variable, left, right, choice, rt_ms, adjustment (the steps of an adjustment\n"
      "as JSON), answered_at), and per study\n"
      "DIR/summary-STUDY.csv: per session the trials planned and answered, the median response time and how often\n"
      "each answer was given (the source chosen or cant_tell; the level accepted). Practice trials are left out\n"
      "of the summaries.\n"
      "Example: blurcue export --db results/study.sqlite --out results/tables");
  cmd->add_option("--db", args->db, "the SQLite record")->required()->check(CLI::ExistingFile);
  cmd->add_option("--out", args->out, "folder for the tables (created)")->required();
  cmd->callback([args] {
    const int64_t rows = store::ExportCsv(args->db, args->out);
    std::printf("wrote %s/trials.csv (%lld rows) and the per-study summaries\n", args->out.c_str(),
                static_cast<long long>(rows));
  });
}

void AddMergeCommand(CLI::App& app) {
  struct Args {
    std::vector<std::string> inputs;
    std::string out;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "merge",
      "Combine the records of several lab stations into a new one, with fresh ids (nothing collides); protocol\n"
      "versions are shared by their hash and participants by their code. Refuses an existing --out.\n"
      "Example: blurcue merge station-a.sqlite station-b.sqlite --out all.sqlite");
  cmd->add_option("inputs", args->inputs, "records to combine")->required()->check(CLI::ExistingFile);
  cmd->add_option("--out", args->out, "the new record")->required();
  cmd->callback([args] {
    std::vector<std::filesystem::path> inputs(args->inputs.begin(), args->inputs.end());
    store::MergeDatabases(inputs, args->out);
    std::printf("merged %zu records into %s\n", inputs.size(), args->out.c_str());
  });
}

}  // namespace blurcue::cli
