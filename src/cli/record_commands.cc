// blurcue export / merge: the SQLite record out to analysis tables, and several stations' records into one.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/own_output.h"
#include "core/typed.h"
#include "store/export.h"
#include "store/record.h"

namespace blurcue::cli {

void AddExportCommand(CLI::App& app) {
  struct Args {
    std::string db, out;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "export",
      "Write a record's answers as tidy tables, with the codebook that says what each column holds.\n"
      "One row per planned trial (answered or not), one column per variable and one type per column, no JSON in any\n"
      "cell; DIR/codebook.csv says every column's type, unit, allowed values and meaning (written from the same\n"
      "definitions as the tables):\n"
      "  trials.csv       who (observer person|simulated, its parameters, window or headless), the session (its id,\n"
      "                   the participant's session number and its status: running|completed|aborted), the seed (s<digits>: exact in R, spreadsheets and\n"
      "                   JavaScript; run --seed takes it), the trial's block, task, practice, swap and every design\n"
      "                   variable, each side's source and fixed radius, and the answer split by kind: status,\n"
      "                   chosen_side, chose_more_blurred, chosen_interval, yes_no, rating, adjusted_level, correct,\n"
      "                   rt_ms, answered_at\n"
      "  adjustments.csv  every step of a method-of-adjustment trial (level, time)\n"
      "  procedures.csv   every adaptive procedure a study version ran (staircase, QUEST+): its cell, guess rate and\n"
      "                   every parameter as the parser read it, from the record (no protocol parsed again)\n"
      "  frames.csv       every display flip (time from the trial's first flip, dropped or not, each side's radius\n"
      "                   and the objects' place along the board)\n"
      "  summary-STUDY.csv  per session the trials planned and answered (practice apart), the median response\n"
      "                   time and how often each answer was given. A study named other than in 1-100 bytes of\n"
      "                   lower-case a-z, 0-9, ., - and _ is summary-SAFE-HASH.csv: its UTF-8 bytes with others as _,\n"
      "                   cut to 83 bytes, and the 16 hex digits of the name's FNV-1a 64 (the same in every export\n"
      "                   and in the report's chart files; the codebook names the study)\n"
      "A record of an earlier version is exported from a migrated copy; the record itself is only read.\n"
      "The folder is written as a whole: built beside DIR as .DIR.partial-PID and swapped in at the end, so an\n"
      "interrupted export leaves the previous tables complete (its leftovers are removed by the next export). An\n"
      "existing DIR must hold only such tables, its codebook.csv among them: a folder of other files (or of one's own\n"
      "trials.csv alone) is refused, not replaced.\n"
      "Example: blurcue export --db results/study.sqlite --out results/tables");
  cmd->add_option("--db", args->db, "the SQLite record")->required()->check(CLI::ExistingFile);
  cmd->add_option("--out", args->out, "folder for the tables (created)")->required();
  cmd->callback([args] {
    // export replaces DIR whole when it holds only names of its tables: a folder of one's own trials.csv alone was
    // replaced. Tables export wrote always hold its codebook.csv, with this header.
    RequireMarkedFolder("--out", args->out, "codebook.csv", "tables export wrote", "one's own trials.csv?");
    RequireOwnFile("--out", std::filesystem::path(args->out) / "codebook.csv", "a codebook.csv export wrote",
                   BeginsWith("table,column,type,unit,allowed,meaning"));
    const int64_t rows = store::ExportCsv(args->db, args->out, [](const std::string& line) {
      std::fprintf(stderr, "export: %s\n", line.c_str());
    });
    std::printf("wrote %s/trials.csv (%lld rows) and the per-study summaries\n", args->out.c_str(),
                static_cast<long long>(rows));
  });
}

void AddMergeCommand(CLI::App& app) {
  struct Args {
    std::vector<std::string> inputs, renames, same_person;
    std::string out;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "merge",
      "Combine the records of several lab stations into a new one, with fresh ids (nothing collides).\n"
      "Protocol versions are shared by their hash and participants by their code. Refuses an existing --out. The record is\n"
      "built beside it as .OUT.partial-PID and renamed to OUT when complete; an interrupted merge's leftovers are\n"
      "removed by the next merge to the same OUT.\n"
      "A session still being written (its lock held by a live run, as blurcue sessions shows it) is refused, exit 3,\n"
      "naming the file, the session and its writer: merge once it has ended (or stop that run and close the session\n"
      "with blurcue sessions --db FILE --abort ID). An unfinished session nobody is writing (a run killed or stopped)\n"
      "is copied as running, and one line on stderr per such session says so: resume it in one record only - its\n"
      "own (then merge again into a new OUT) or the merged one - never both, or the two copies cannot be merged again.\n"
      "People are kept apart: a participant id that two inputs both hold (in one study) is refused, exit 3, until you\n"
      "say who they are - two people who got one id: --rename INPUT:ID=NEWID gives one of them another id in that\n"
      "input; one person who ran sessions at two stations: --same-person ID.\n"
      "Example: blurcue merge station-a.sqlite station-b.sqlite --out all.sqlite\n"
      "         blurcue merge a.sqlite b.sqlite --rename b.sqlite:P1=P1b --out all.sqlite");
  cmd->add_option("inputs", args->inputs, "records to combine")->required()->check(CLI::ExistingFile);
  cmd->add_option("--out", args->out, "the new record")->required();
  cmd->add_option("--rename", args->renames,
                  "INPUT:ID=NEWID: in that input, participant ID is recorded as NEWID (two people who got one id); "
                  "repeatable")
      ->allow_extra_args(false);  // one value each time: before the inputs it must not take them as renames
  cmd->add_option("--same-person", args->same_person,
                  "ID: the inputs' participant ID is one person who ran at several stations; repeatable")
      ->allow_extra_args(false);
  cmd->callback([args] {
    std::vector<std::filesystem::path> inputs(args->inputs.begin(), args->inputs.end());
    store::MergeOptions options;
    options.same_person = args->same_person;
    for (const std::string& spec : args->renames) {
      // INPUT:ID=NEWID, INPUT as listed (a path may hold ':'): the input this spec begins with, then ':'.
      std::optional<store::MergeOptions::Rename> rename;
      for (const std::string& input : args->inputs)
        if (spec.size() > input.size() + 1 && spec.compare(0, input.size(), input) == 0 && spec[input.size()] == ':') {
          const std::string ids = spec.substr(input.size() + 1);
          const size_t eq = ids.find('=');
          if (eq == std::string::npos || eq == 0 || eq + 1 == ids.size()) break;
          rename = store::MergeOptions::Rename{input, ids.substr(0, eq), ids.substr(eq + 1)};
        }
      if (!rename) {
        std::string listed;
        for (const std::string& input : args->inputs) listed += (listed.empty() ? "" : ", ") + input;
        throw Error(ErrorKind::kUsage, "--rename " + Echo(spec) + ": write INPUT:ID=NEWID, INPUT one of the records "
                                       "listed (" + listed + ")");
      }
      options.renames.push_back(*rename);
    }
    store::MergeDatabases(inputs, args->out, [](const std::string& line) {
      std::fprintf(stderr, "merge: %s\n", line.c_str());
    }, options);
    std::printf("merged %zu records into %s\n", inputs.size(), args->out.c_str());
  });
}

void AddSessionsCommand(CLI::App& app) {
  struct Args {
    std::string db;
    std::optional<int64_t> abort, break_lock;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "sessions",
      "List the sessions of a record: who took each, how far it got and what became of it.\n"
      "Each row: study, the protocol's \"version\" it ran (v), participant, the participant's session number (n),\n"
      "group, observer (person or simulated), status, trials answered of planned (skipped and timed-out trials\n"
      "counted apart, never as answered), seed, start and end, host, and who holds its lock (a writer alive, or a stale lock left by a crash). The status is completed, aborted, or for a session neither (the record's and export's 'running'):\n"
      "  running      another process runs it now (a live writer holds its lock)\n"
      "  unfinished   its run left it: the participant quit, the window was closed, or --stop-after was reached\n"
      "  interrupted  its writer died holding the lock (killed, crashed); the next run takes the lock over\n"
      "An unfinished or interrupted session continues with blurcue run ... --resume. A read-only record (an archive,\n"
      "a read-only mount) lists too.\n"
      "\n"
      "Two repairs, each the experimenter's explicit call:\n"
      "  --abort ID       close an unfinished session as aborted, keeping every answer (e.g. its protocol was\n"
      "                   changed, so it cannot be resumed); refused while a live writer holds it.\n"
      "  --break-lock ID  clear a session's lock whoever holds it (a station that died holding it; a lock of this\n"
      "                   host whose process is gone, or silent for 60 s, is taken over by the next run anyway).\n"
      "\n"
      "Examples:\n"
      "  blurcue sessions --db results/study.sqlite\n"
      "  blurcue sessions --db results/study.sqlite --abort 12");
  cmd->add_option("--db", args->db, "the SQLite record")->required()->check(CLI::ExistingFile);
  // Session ids are SQLite rowids: 1 and up.
  cmd->add_option("--abort", args->abort, "close this unfinished session as aborted (answers kept)")
      ->transform(IntRange(1, INT64_MAX));
  cmd->add_option("--break-lock", args->break_lock, "clear this session's lock")->transform(IntRange(1, INT64_MAX));
  cmd->callback([args] {
    if (args->abort || args->break_lock) {
      store::Record record = store::Record::Open(args->db);
      if (args->break_lock) {
        const store::LockState lock = record.BreakLock(*args->break_lock);
        std::printf("%s: session %lld: broke the lock of %s\n", args->db.c_str(),
                    static_cast<long long>(*args->break_lock), lock.text.c_str());
      }
      if (args->abort) {
        record.AbortSession(*args->abort);
        std::printf("%s: session %lld closed as aborted; its answers are kept\n", args->db.c_str(),
                    static_cast<long long>(*args->abort));
      }
      return;
    }
    const auto sessions = store::ListSessions(args->db);
    const std::string& db = args->db;
    if (sessions.empty()) {
      std::printf("%s: no sessions yet\n", db.c_str());
      return;
    }
    // answered: answers given of the trials planned; skipped and timed-out trials are counted apart, never as
    // answered. v: the protocol's declared version the session ran; n: the participant's n-th session of the study.
    std::printf("%4s  %-28s %3s %-12s %3s %-12s %-9s %-11s %9s %7s %9s  %-20s  %-24s %-24s %s\n", "id", "study",
                "v", "participant", "n", "group", "observer", "status", "answered", "skipped", "timed_out", "seed",
                "started", "ended", "host");
    int unfinished = 0, running_now = 0;
    for (const auto& s : sessions) {
      const std::string answered = std::to_string(s.answered) + "/" + std::to_string(s.planned);
      const std::string number = s.number > 0 ? std::to_string(s.number) : "-";
      const std::string version = s.protocol_version > 0 ? std::to_string(s.protocol_version) : "-";
      std::printf("%4lld  %-28s %3s %-12s %3s %-12s %-9s %-11s %9s %7lld %9lld  %-20llu  %-24s %-24s %s%s\n",
                  static_cast<long long>(s.id), s.study.c_str(), version.c_str(), s.participant.c_str(), number.c_str(),
                  s.group.empty() ? "-" : s.group.c_str(), s.observer.empty() ? "-" : s.observer.c_str(),
                  s.state.c_str(), answered.c_str(), static_cast<long long>(s.skipped),
                  static_cast<long long>(s.timed_out), static_cast<unsigned long long>(s.seed), s.started.c_str(),
                  s.ended.empty() ? "-" : s.ended.c_str(), s.host.c_str(),
                  s.writer.empty() ? "" : ("  lock: " + s.writer).c_str());
      unfinished += s.status == "running";
      running_now += s.state == "running";
    }
    // Unfinished as the record and the report count them: every session neither completed nor aborted.
    std::printf("%zu sessions, %d unfinished", sessions.size(), unfinished);
    if (running_now > 0) std::printf(" (%d of them running now)", running_now);
    std::printf("\n");
  });
}

}  // namespace blurcue::cli
