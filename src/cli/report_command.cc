// blurcue report: the record exported to tables, then every chart and an index.html (analysis/report.py).
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include "cli/commands.h"
#include "core/error.h"
#include "store/export.h"

namespace blurcue::cli {
namespace {

// A shell word: single-quoted, with single quotes escaped.
std::string Quote(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

}  // namespace

void AddReportCommand(CLI::App& app) {
  struct Args {
    std::string db, out, bench = "results/bench", python = "/usr/bin/python3";
    int boot = 200;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "report",
      "Write the report of a record: the tables (DIR/tables/trials.csv and per-study summaries, as blurcue export),\n"
      "then every chart as PNG and SVG with its numbers beside it, and DIR/index.html showing them:\n"
      "  depth matching: chosen cut-off vs distance per observer and pooled, with a fitted curve (thesis Fig. 3.3)\n"
      "  test 1: answers per edge (Fig. 5.2); tests 2 and 3: per pattern (Fig. 5.9, 5.13) and per section\n"
      "          (Fig. 5.10-5.12); 95 % Wilson intervals, binomial tests against chance, a GLMM across observers\n"
      "  psychometric: choosing the more blurred side vs the blur difference, logistic/Weibull, bootstrap band\n"
      "  speed vs accuracy of every blur and measurement method with the Pareto front, and where each breaks\n"
      "          (from --bench: measure.csv and render.csv of blurcue bench)\n"
      "Sections without data are skipped with a note. Needs Debian's python3-pandas, -scipy, -matplotlib and\n"
      "-statsmodels (scripts/setup.sh installs them).\n"
      "Example: blurcue report --db results/demo/study.sqlite --out results/demo/report");
  cmd->add_option("--db", args->db, "the SQLite record")->required()->check(CLI::ExistingFile);
  cmd->add_option("--out", args->out, "folder for the report (created)")->required();
  cmd->add_option("--bench", args->bench, "folder of the benchmark CSVs")->capture_default_str();
  cmd->add_option("--boot", args->boot, "bootstrap samples of the psychometric fit")->capture_default_str()
      ->check(IntRange(10, 100000));
  cmd->add_option("--python", args->python, "the Python that sees the analysis packages")->capture_default_str();
  cmd->callback([args] {
    const std::filesystem::path tables = std::filesystem::path(args->out) / "tables";
    const int64_t rows = store::ExportCsv(args->db, tables);
    std::fprintf(stderr, "report: exported %lld trials to %s\n", static_cast<long long>(rows), tables.c_str());
    const std::filesystem::path script = std::filesystem::path(BLURCUE_SOURCE_DIR) / "analysis" / "report.py";
    if (!std::filesystem::exists(script)) throw InputError(script.string(), "the analysis script is missing");
    const std::string command = Quote(args->python) + " " + Quote(script.string()) + " --trials " +
                                Quote((tables / "trials.csv").string()) + " --bench " + Quote(args->bench) +
                                " --out " + Quote(args->out) + " --boot " + std::to_string(args->boot);
    std::fflush(stdout);
    const int status = std::system(command.c_str());
    if (status == -1 || !WIFEXITED(status))
      throw Error(ErrorKind::kInternal, "cannot run " + args->python + " " + script.string());
    const int code = WEXITSTATUS(status);
    if (code == 127) throw Error(ErrorKind::kUsage, "--python " + args->python + ": not found");
    if (code != 0) throw Error(code == 3 ? ErrorKind::kInput : ErrorKind::kInternal,
                               "the analysis stopped (exit " + std::to_string(code) + "); its message is above");
    std::printf("wrote %s/index.html\n", args->out.c_str());
  });
}

}  // namespace blurcue::cli
