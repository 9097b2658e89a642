#pragma once
// Reading a record out: a long-format CSV for analysis, and merging the records of several stations.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "core/json_io.h"

namespace blurcue::store {

// Receives one line for the user (what was cleaned up, what needs care); the caller decides where to print it.
using ProgressNote = std::function<void(const std::string&)>;

// Writes `out_dir`/trials.csv: one row per planned trial, answered or not, ordered by study,
// participant, session, trial index. Columns, the same for every participant:
//   study, protocol_hash, protocol_version, participant, ..., session_id, session_number, ..., seed, trial_index,
//   block, ..., practice, swapped, cell, <every factor key found in the record, sorted>, ..., answered_at
// (codebook.csv names each, with a design column's role and the values its protocol allows where the record keeps
// the design).
// A factor a trial lacks is an empty cell; a factor named like a column of trials.csv or a recorded variable
// (IsRecordedName) is written as "factor_<name>".
// Beside it, per study, `out_dir`/SummaryFileName(STUDY): one row per session with the trials planned and answered
// (practice apart), the median response time and the count of every answer (forced choice: the source chosen, or
// cant_tell; adjustment: the level accepted) as n_ANSWER columns. And `out_dir`/frames.csv: every recorded display
// flip (study, participant, session, window: 1 for a real window, 0 headless; trial_index, frame_index, flip_time_s
// from the trial's first flip, dropped).
// The folder is written as a whole (core/atomic_file.h WriteFolderAtomically): built beside `out_dir`, swapped in
// by one rename, so a kill leaves the previous export complete and never a mix of old and new tables. An existing
// `out_dir` holding anything but these tables is refused. Leftovers of a killed export beside `out_dir` are
// removed first, each one told to `note`.
// Returns the number of rows. Throws Error(kInput) for a file that is not a current blurcue record.
int64_t ExportCsv(const std::filesystem::path& db_path, const std::filesystem::path& out_dir,
                  const ProgressNote& note = {});

// Whether trials.csv or the record gives `name` a meaning of its own, so that no level of a design may take it: a
// fixed column of trials.csv (participant, status, correct, ...), group, an info_KEY column, or a variable the runner
// records beside a trial's levels (r_left_px, level, test_side, ...: session/stimulus.h TrialVariables). Read off the
// definitions trials.csv and its codebook are written from.
bool IsRecordedName(const std::string& name);
// The name a design's level `name` is recorded and exported under: "factor_<name>" when IsRecordedName(name) (so it
// can never be overwritten by, or mistaken for, what the runner records), else `name`.
std::string DesignColumn(const std::string& name);

// The variables a trial's levels are recorded as (the runner's, session TrialVariables): each level under
// DesignColumn(name); each value of an object level (a pattern's speed_cm_s, a conditions table's columns; not its
// sides left, right and object) under DesignColumn(key) where no level took that column; a conditions table's row
// object itself is not kept, only its columns.
Json LevelVariables(const Json& levels);
// Adds to a trial's recorded variables each value of an object level they hold (as LevelVariables records it) where
// they lack it: a record of an early build kept a pattern's speed_cm_s only inside the pattern.
void SpreadObjectLevels(Json* variables);

// Copies every study, protocol version, participant, session, trial, response and frame of `inputs` into a new
// record at `out`, with fresh ids. Protocol versions are shared by (study, hash) and participants by (study,
// participant code). Throws Error(kInput) when `out` exists, an input is listed twice, an input is not a current
// record, a session of an input is held by a live writer (JudgeLock: not stale; the message names the file, the
// session and the writer), or a session (same participant, protocol, seed, host and start) is already in the output.
// Nothing is left at `out` on failure. Each input is read in one snapshot. A running session no live writer holds
// (killed, stopped or stale) is copied as running, and one line per such session, told to `note` once `out` is in
// place, says so and that it must be resumed in one record only. The record is built beside `out` as
// DIR/.NAME.partial-PID and renamed to `out` when complete; leftovers of a killed merge to the same `out` are removed
// first, each one told to `note`. A participant's sessions are numbered again by start across the inputs (one line
// to `note` per session whose number changes), and one line per study version holding several texts.
//
// People are kept apart: a participant code (in one study) that an earlier input already holds is refused, naming
// both inputs and the two ways out, unless the experimenter says which it is - two people: `renames` gives one of
// them another code in its input; one person who ran at two stations: `same_person` lists the code.
struct MergeOptions {
  struct Rename {
    std::filesystem::path input;  // as listed among the inputs
    std::string from, to;         // participant codes
  };
  std::vector<Rename> renames;
  std::vector<std::string> same_person;
};
void MergeDatabases(const std::vector<std::filesystem::path>& inputs, const std::filesystem::path& out,
                    const ProgressNote& note = {}, const MergeOptions& options = {});

// One session as the experimenter sees it: who, what, how far.
struct SessionSummary {
  int64_t id = 0;
  std::string study, participant, status, started, ended, host;  // status: the record's (running|completed|aborted)
  // What became of the session, as `sessions` lists it: completed or aborted as recorded; a running one (the record
  // keeps every unfinished session running, resumable) is "running" only while a live writer holds its lock (another
  // process runs it now), "unfinished" when its run left it (quit, window closed, --stop-after: the lock released),
  // "interrupted" when its writer died holding the lock (killed, crashed: a stale lock, taken over by the next run).
  // Unfinished and interrupted sessions continue with blurcue run --resume.
  std::string state;
  std::string group;     // the between-subject group, "" without groups
  std::string observer;  // "person" or "simulated" ("" in a record too old to say)
  int64_t number = 0;    // the participant's n-th session of the study (0 in a record too old to say)
  int64_t protocol_version = 0;  // the protocol's declared "version" it ran (0 in a record too old to say)
  uint64_t seed = 0;
  // Planned trials (practice included) and what became of them: answered (an answer given), skipped (not shown: a
  // stopped procedure, practice after its criterion was met), timed out (shown, no answer before the deadline).
  int64_t planned = 0, answered = 0, skipped = 0, timed_out = 0;
  // Who holds its lock: empty for nobody, else JudgeLock's text ("pid P on host H, heartbeat N s ago (alive)",
  // or why it is stale).
  std::string writer;
};

// Every session of the record, by study, participant and id. Throws Error(kInput) for a file that is not a
// current blurcue record.
std::vector<SessionSummary> ListSessions(const std::filesystem::path& db_path);

// A name of the record (a study's, a factor's, a group's) as a file name's stem: the one rule export and the report
// (analysis/common.py file_stem, its twin; tests/data/file_stems.csv pins both) make file names by. The name itself
// when it is 1-100 bytes of lower-case ASCII letters, digits, '-', '_' and '.', not starting with '.' and not itself
// ending in '-' and 16 hex digits; otherwise SAFE-HASH: SAFE the name's UTF-8 bytes with every other byte (and a
// leading '.') written '_', cut to 83 bytes, HASH the 16 hex digits of FNV-1a 64 of the name's exact bytes. So a stem
// is at most 100 bytes on every file system (72 CJK characters are 216 bytes), and two names differing anywhere -
// "pilot 1" and "pilot/1", "a b" and "A b", a zero-width space - are two files, none differing by case only.
std::string FileStem(const std::string& name);

// The file name of a study's summary, the same for the study in any record: summary-FileStem(STUDY).csv.
std::string SummaryFileName(const std::string& study);

// One CSV field, quoted when it holds a comma, quote, line break or leading/trailing space.
std::string CsvField(const std::string& text);

}  // namespace blurcue::store
