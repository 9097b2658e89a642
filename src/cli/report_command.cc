// blurcue report: the record exported to tables, then every chart and an index.html (analysis/report.py).
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "cli/child.h"
#include "cli/commands.h"
#include "core/atomic_file.h"
#include "core/data_dir.h"
#include "core/error.h"
#include "store/export.h"
#include "store/export_table.h"
#include "store/schema.h"
#include "store/sqlite.h"

namespace blurcue::cli {

void AddReportCommand(CLI::App& app) {
  struct Args {
    std::string db, out, bench = "results/bench", python = "/usr/bin/python3";
    int boot = 200;
    bool pool_simulated = false, include_aborted = false, include_unfinished = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "report",
      "Write the report of a record: the tables (DIR/tables/, as blurcue export, with their codebook), then every\n"
      "chart as PNG and SVG with its numbers beside it, DIR/index.html (a summary of what each study found, then a\n"
      "section per study) and DIR/bench.html (the software benchmarks):\n"
      "  any study, from what its trials declare: per condition the share with Wilson intervals and a test against\n"
      "          chance with participants as the unit (Holm), a chart per factor, a psychometric function per\n"
      "          procedure cell over its level, or an odd one out's over the blur difference on screen (Weibull, guess\n"
      "          and lapse, bootstrap band and threshold interval; none for a preference question),\n"
      "          procedure tracks, models across participants (GLMM from three), side bias, ratings, adjusted levels;\n"
      "          people and simulated observers apart (--pool-simulated pools them); a study on a tracked video\n"
      "          has its scene described in the summary: the take, its frames (its track.csv, looked for from the\n"
      "          working folder, its protocols/ and the record's folder), the exposure and the motion streaks\n"
      "  the thesis's studies, besides:\n"
      "  depth matching: chosen cut-off vs distance per observer and pooled, with a fitted curve (thesis Fig. 3.3)\n"
      "  test 1: answers per edge (Fig. 5.2); tests 2 and 3: per pattern (Fig. 5.9, 5.13) and per section\n"
      "          (Fig. 5.10-5.12); 95 % Wilson intervals, binomial tests against chance, a GLMM across observers\n"
      "  psychometric: choosing the more blurred side vs the blur difference, logistic/Weibull, bootstrap band\n"
      "  speed vs accuracy of every blur and measurement method with the Pareto front, and where each breaks\n"
      "          (from --bench: measure.csv and render.csv of blurcue bench)\n"
      "Aborted sessions (closed with blurcue sessions --abort) are left out of every analysis, and the summary says\n"
      "how many sessions and answers per study (--include-aborted analyses them too); so are unfinished sessions\n"
      "(running: stopped, killed or still being written; --include-unfinished analyses them as partial data).\n"
      "A between-subject group is analysed per group and compared with participants as the unit; an adaptive\n"
      "procedure per cell, without a test against chance; a participant's repeated sessions (--again) and each\n"
      "protocol version get sections of their own.\n"
      "Sections without data are skipped with a note. Needs Debian's python3-pandas, -scipy, -matplotlib and\n"
      "-statsmodels (scripts/setup.sh installs them).\n"
      "The folder is built beside DIR as .DIR.partial-PID and swapped in only when the analysis succeeded: an\n"
      "interrupted or failed report leaves the previous one (or none), never half of one, and the analysis dies\n"
      "with blurcue. An existing DIR must be an earlier report (index.html or tables/trials.csv) holding only\n"
      "what a report writes (index.html, bench.html, charts, their .csv tables, tables/), or empty.\n"
      "Example: blurcue report --db results/demo/study.sqlite --out results/demo/report");
  cmd->add_option("--db", args->db, "the SQLite record")->required()->check(CLI::ExistingFile);
  cmd->add_option("--out", args->out, "folder for the report (created)")->required();
  CLI::Option* bench = cmd->add_option("--bench", args->bench, "folder of the benchmark CSVs (by default results/bench, "
                                      "where it exists: without benchmarks the report has no benchmark page)");
  cmd->add_option("--boot", args->boot, "bootstrap samples of each psychometric fit: its band and its threshold's "
                 "interval come from the same samples")->capture_default_str()
      ->transform(IntRange(10, 100000));
  cmd->add_option("--python", args->python, "the Python that sees the analysis packages")->capture_default_str();
  cmd->add_flag("--pool-simulated", args->pool_simulated,
                "analyse people and simulated observers together (by default each study reports them apart)");
  cmd->add_flag("--include-aborted", args->include_aborted,
                "analyse the answers of aborted sessions too (by default they are left out, and the summary says so)");
  cmd->add_flag("--include-unfinished", args->include_unfinished,
                "analyse the answers of unfinished sessions too, as partial data (by default they are left out, and "
                "the summary says so)");
  cmd->callback([args, bench] {
    const std::filesystem::path out = args->out;
    const std::filesystem::path script = DataDir().path / "analysis" / "report.py";
    if (!std::filesystem::exists(script)) throw InputError(script.string(), "the analysis script is missing");
    // The options first (a usage error, exit 2), then the record: both before anything is made, so a record this
    // build cannot read leaves no folder behind.
    RequirePython3(args->python, {"numpy", "pandas", "matplotlib", "scipy", "statsmodels"});
    {
      store::Database record(args->db, store::OpenMode::kReadOnly);
      store::RequireReadableRecord(record);
    }
    for (const auto& path : RemoveStaleLeftovers(out))
      std::fprintf(stderr, "report: removed %s, left by an interrupted run\n", path.c_str());
    // An earlier report is replaced as a whole; a folder of something else is not ours to replace, nor is a file
    // someone put into an earlier report (notes.txt, another report made inside it: they were deleted with it). A
    // report holds index.html, bench.html, its charts (.png, .svg) with their tables (.csv), and tables/ as export
    // writes it.
    std::error_code ignored;
    const bool earlier_report = std::filesystem::exists(out / "index.html", ignored) ||
                                std::filesystem::exists(out / "tables" / "trials.csv", ignored);
    const auto ours = [earlier_report](const std::string& name) {
      const auto ends = [&name](const std::string& tail) {
        return name.size() > tail.size() && name.compare(name.size() - tail.size(), tail.size(), tail) == 0;
      };
      return earlier_report && (name == "index.html" || name == "bench.html" || name == "tables" || ends(".png") ||
                                ends(".svg") || ends(".csv"));
    };
    if (earlier_report) RequireReplaceableFolder(out / "tables", store::IsExportFile);
    WriteFolderAtomically(
        out,
        [&](const std::filesystem::path& partial) {
          const int64_t rows = store::ExportCsv(args->db, partial / "tables", [](const std::string& line) {
            std::fprintf(stderr, "report: %s\n", line.c_str());
          });
          std::fprintf(stderr, "report: exported %lld trials to %s\n", static_cast<long long>(rows),
                       (out / "tables").c_str());
          std::vector<std::string> argv = {args->python, script.string(), "--trials",
                                           (partial / "tables" / "trials.csv").string(), "--out", partial.string(), "--final-out", out.string(), "--boot",
                                           std::to_string(args->boot), "--db", args->db};
          if (bench->count() > 0) argv.insert(argv.end(), {"--bench", args->bench});
          if (args->pool_simulated) argv.push_back("--pool-simulated");
          if (args->include_aborted) argv.push_back("--include-aborted");
          if (args->include_unfinished) argv.push_back("--include-unfinished");
          RunAnalysis(argv, "the analysis", out.string(), {(partial / "index.html").string()});
        },
        ours);
    std::printf("wrote %s/index.html\n", args->out.c_str());
  });
}

}  // namespace blurcue::cli
