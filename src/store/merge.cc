// blurcue merge: the records of several stations copied into one new record, with fresh ids.
#include <algorithm>
#include <map>
#include <set>
#include <string>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/names.h"
#include "core/typed.h"
#include "store/export.h"
#include "store/columns.h"
#include "store/frame_columns.h"
#include "store/procedures.h"
#include "store/export_table.h"
#include "store/record.h"
#include "store/schema.h"
#include "store/sqlite.h"

namespace blurcue::store {
namespace {

// The id a row of `input` refers to, as merged; a reference to a row the input does not hold (a hand-edited record:
// a response whose trial was deleted, a trial of a session 999) is that input's damage, said in one line (exit 3),
// not std::map::at's "map::at" (exit 10).
int64_t Mapped(const std::map<int64_t, int64_t>& ids, int64_t id, const std::filesystem::path& input,
               const char* what) {
  const auto it = ids.find(id);
  if (it == ids.end())
    throw InputError(input.string(), std::string("a row refers to ") + what + " " + std::to_string(id) +
                                         ", which the record does not hold (was it edited?); nothing was merged");
  return it->second;
}

// The typed columns (schema 7 on) the column table keeps in `table` (columns.h), as a SELECT list for an input of
// schema `version`: NULL for a column it predates (DeriveTypedColumns and DeriveVersionsAndNumbers fill those from
// its texts, as a migration would); CopiedNames and CopiedPlaceholders give the INSERT's.
std::string TypedSelect(const std::string& table, int version) {
  std::string list;
  for (const Kept& kept : KeptIn(RecordColumns(), table, 7))
    list += ", " + (version >= kept.stored->since ? kept.name : std::string("NULL"));
  return list;
}
// Where `name` is among TypedSelect's columns of `table`, from 0.
int TypedIndex(const std::string& table, const std::string& name) {
  const std::vector<Kept> kept = KeptIn(RecordColumns(), table, 7);
  for (size_t i = 0; i < kept.size(); ++i)
    if (kept[i].name == name) return int(i);
  throw Error(ErrorKind::kInternal, "merge: no typed column " + table + "." + name);
}
// A session's number is read but not copied: a participant's sessions from several inputs are numbered again.
bool Renumbered(const Kept& kept) { return kept.stored->table == "sessions" && kept.name == "session_number"; }
// ", a, b" and ", ?, ?" for the typed columns an INSERT of `table` copies.
std::string CopiedNames(const std::string& table) {
  std::string names;
  for (const Kept& kept : KeptIn(RecordColumns(), table, 7))
    if (!Renumbered(kept)) names += ", " + kept.name;
  return names;
}
std::string CopiedPlaceholders(const std::string& table) {
  std::string marks;
  for (const Kept& kept : KeptIn(RecordColumns(), table, 7))
    if (!Renumbered(kept)) marks += ", ?";
  return marks;
}
// Binds the typed columns read from `from` (TypedSelect's, starting at column `first`) that are copied to `to`
// (starting at parameter `at`).
void CopyTyped(const std::string& table, Statement& from, int first, Statement& to, int at) {
  for (const Kept& kept : KeptIn(RecordColumns(), table, 7)) {
    if (Renumbered(kept)) {
      ++first;
      continue;
    }
    if (from.IsNull(first)) to.BindNull(at);
    else if (kept.stored->sql == "TEXT") to.Bind(at, from.GetText(first));
    else if (kept.stored->sql == "REAL") to.Bind(at, from.GetDouble(first));
    else to.Bind(at, from.GetInt64(first));
    ++first, ++at;
  }
}

// Refuses an input whose session a live writer holds (the record's own rule, JudgeLock: a copy taken now would miss
// the answers still coming, and the two copies could each be resumed and never merged again). Adds one line to
// `unfinished` per running session with no live writer (a killed or stopped one): copied as it is, and it must be
// resumed in one record only.
void CheckSessionsToMerge(Database& src, const std::filesystem::path& input, std::vector<std::string>* unfinished) {
  Statement sessions(src,
                     "SELECT s.id, st.name, p.code, s.status, "
                     "(SELECT count(*) FROM trials t WHERE t.session_id = s.id), "
                     "(SELECT count(*) FROM trials t JOIN responses r ON r.trial_id = t.id WHERE t.session_id = s.id), "
                     "s.lock_token IS NOT NULL, coalesce(s.lock_host, ''), coalesce(s.lock_pid, 0), "
                     "coalesce(s.lock_heartbeat_ms, 0) "
                     "FROM sessions s JOIN participants p ON p.id = s.participant_id "
                     "JOIN studies st ON st.id = p.study_id ORDER BY s.id");
  while (sessions.Step()) {
    const std::string id = std::to_string(sessions.GetInt64(0));
    const std::string who = "session " + id + " (study " + sessions.GetText(1) + ", participant " +
                            sessions.GetText(2) + ", " + std::to_string(sessions.GetInt64(5)) + " of " +
                            std::to_string(sessions.GetInt64(4)) + " trials answered)";
    if (sessions.GetInt64(6) != 0) {
      const LockState lock = JudgeLock(sessions.GetText(7), sessions.GetInt64(8), sessions.GetInt64(9));
      if (!lock.stale)
        throw InputError(input.string(),
                         who + " is being written by " + lock.text + "; merge it once that session has ended (to "
                         "give it up instead: stop that run, then blurcue sessions --db " + input.string() +
                         " --abort " + id + ")");
    }
    if (sessions.GetText(3) == "running")
      unfinished->push_back(input.string() + ": " + who + " is unfinished, with no live writer: copied as running; "
                            "resume it in one record only (this one, then merge again into a new file, or the "
                            "merged one), never both: the two copies could not be merged again");
  }
}

using IdMap = std::map<int64_t, int64_t>;
using Renames = std::map<std::string, std::string>;  // an input's participant codes: old -> new

// The session numbers the inputs gave (version 8 on), by the merged session's id.
struct Numbered {
  std::string input;
  int64_t session = 0, number = 0;
};

// Each rename names an input of this merge and a participant that input holds; each same-person code some input
// holds; no input is listed twice. Read before anything is merged, so a rename or a same-person code that names
// nobody is refused first, with the nearest code. Returns the renames by each input's canonical path.
std::map<std::filesystem::path, Renames> CheckMergeInputs(const std::vector<std::filesystem::path>& inputs,
                                                          const MergeOptions& options) {
  std::set<std::filesystem::path> seen;
  for (const auto& input : inputs) {
    if (!seen.insert(std::filesystem::weakly_canonical(input)).second)
      throw InputError(input.string(), "listed twice among the merge inputs");
  }
  std::vector<std::string> input_names;
  for (const auto& input : inputs) input_names.push_back(input.string());
  std::map<std::filesystem::path, Renames> renames;
  for (const auto& r : options.renames) {
    const auto canonical = std::filesystem::weakly_canonical(r.input);
    if (!seen.count(canonical))
      throw InputError("--rename", "names " + Echo(r.input.string()) + ", which is not an input of this merge" +
                                       DidYouMean(r.input.string(), input_names));
    if (!renames[canonical].emplace(r.from, r.to).second)
      throw InputError("--rename", "renames participant " + Echo(r.from) + " of " + r.input.string() + " twice");
  }
  std::set<std::string> held;
  for (const auto& input : inputs) {
    Database src(input, OpenMode::kReadOnly);
    RequireReadableRecord(src);
    std::vector<std::string> codes;
    Statement all(src, "SELECT code FROM participants");
    while (all.Step()) codes.push_back(all.GetText(0));
    held.insert(codes.begin(), codes.end());
    const Renames& own = renames[std::filesystem::weakly_canonical(input)];
    for (const auto& [from, to] : own)
      if (std::find(codes.begin(), codes.end(), from) == codes.end())
        throw InputError("--rename", input.string() + " holds no participant " + Echo(from) + DidYouMean(from, codes));
    // A new id this input already gives another person of the same study (not renamed away itself) would join two
    // people the station kept apart: the collision used to be blamed on "an earlier input", and the --same-person
    // it offered made them one participant.
    std::map<std::string, std::string> renamed_to;  // new id -> the id it replaces
    Statement holder(src, "SELECT st.name FROM participants a JOIN participants b ON b.study_id = a.study_id JOIN "
                          "studies st ON st.id = a.study_id WHERE a.code = ? AND b.code = ?");
    for (const auto& [from, to] : own) {
      if (const auto [first, fresh] = renamed_to.emplace(to, from); !fresh)
        throw InputError("--rename", "gives participants " + first->second + " and " + from + " of " +
                                         input.string() + " one new id " + Echo(to) + "; they are two people there");
      if (own.count(to)) continue;
      holder.Bind(1, from);
      holder.Bind(2, to);
      if (holder.Step())
        throw InputError("--rename", input.string() + ":" + from + "=" + OneLine(to) + ": " + input.string() +
                                         " already holds a participant " + OneLine(to) + " of study " +
                                         holder.GetText(0) + ", another person than " + from + "; give " + from +
                                         " an id that record does not hold");
      holder.Reset();
    }
  }
  for (const std::string& code : options.same_person)
    if (!held.count(code))
      throw InputError("--same-person", "no input holds a participant " + Echo(code) +
                                            DidYouMean(code, std::vector<std::string>(held.begin(), held.end())));
  return renames;
}

// One input's procedures (procedures.h): a version's rows as the first input that recorded them gives them; an input
// of before schema 10 gives them from its recorded texts, as its migration would.
void CopyProcedures(Database& src, Database& dst, const std::filesystem::path& input, int version,
                    const IdMap& protocol_ids) {
  if (version < 10) {
    std::string ids;
    for (const auto& [from, to] : protocol_ids) ids += (ids.empty() ? "" : ", ") + std::to_string(to);
    if (!ids.empty()) DeriveProcedures(dst, "id IN (" + ids + ")");
    return;
  }
  CheckProcedures(src, input.string());
  // A version two inputs share was recorded by each: the first input's rows stand, and the next must agree with them
  // (its parameters were hand-edited otherwise); a block only the next recorded is added.
  Statement rows(src, "SELECT protocol_version_id, block, parameters, block_name" +
                          CopySelect(ProcedureColumns(), version) + " FROM procedures");
  Statement held(dst, "SELECT parameters, block_name FROM procedures WHERE protocol_version_id = ? AND block = ?");
  Statement insert(dst, InsertSql("procedures", "protocol_version_id", ProcedureColumns(), "INSERT"));
  while (rows.Step()) {
    const int64_t to = Mapped(protocol_ids, rows.GetInt64(0), input, "protocol version");
    held.Bind(1, to);
    held.Bind(2, rows.GetInt64(1));
    if (held.Step()) {
      if (held.GetText(0) != rows.GetText(2) || held.GetText(1) != rows.GetText(3))
        throw InputError(input.string(), "procedures row (block " + std::to_string(rows.GetInt64(1)) +
                                             "): its parameters differ from those an earlier input recorded for the "
                                             "same protocol version (a hand-edited record?)");
      held.Reset();
      continue;
    }
    held.Reset();
    insert.Bind(1, to);
    CopyKept(ProcedureColumns(), rows, 4, insert, 2);
    insert.Run();
    insert.Reset();
  }
}

// One input's studies, protocol versions (with their typed columns), procedures and designs into `dst`.
void CopyStudiesAndProtocols(Database& src, Database& dst, const std::filesystem::path& input, int version,
                             IdMap& study_ids, IdMap& protocol_ids) {
  Statement studies(src, "SELECT id, name, created FROM studies");
  while (studies.Step()) study_ids[studies.GetInt64(0)] = EnsureStudy(dst, studies.GetText(1), studies.GetText(2));

  // A protocol version's typed columns: given by the first input that has them.
  std::string set_typed;
  for (const Kept& kept : KeptIn(RecordColumns(), "protocol_versions", 7))
    set_typed += (set_typed.empty() ? "" : ", ") + kept.name + " = coalesce(" + kept.name + ", ?)";
  Statement protocols(src, "SELECT id, study_id, json, hash, created" + TypedSelect("protocol_versions", version) +
                               " FROM protocol_versions");
  const int pv_typed = int(KeptIn(RecordColumns(), "protocol_versions", 7).size());
  Statement set_version(dst, "UPDATE protocol_versions SET " + set_typed + " WHERE id = ?");
  while (protocols.Step()) {
    // An input of schema 1 holds raw texts: the merged record keys them by their canonical text, as run does.
    std::string json = protocols.GetText(2), hash = protocols.GetText(3);
    try {
      json = CanonicalProtocolText(json);
      hash = ProtocolHash(json);
    } catch (const Error&) {
    }
    std::string stored_json;
    protocol_ids[protocols.GetInt64(0)] = EnsureProtocolVersion(
        dst, Mapped(study_ids, protocols.GetInt64(1), input, "study"), json, hash, protocols.GetText(4), &stored_json);
    if (stored_json != json)
      throw InputError(input.string(), "protocol hash " + hash + " names a different protocol text in another input");
    CopyTyped("protocol_versions", protocols, 5, set_version, 1);
    set_version.Bind(pv_typed + 1, protocol_ids[protocols.GetInt64(0)]);
    set_version.Run();
    set_version.Reset();
  }
  CopyProcedures(src, dst, input, version, protocol_ids);
  if (version < 8) return;
  // One design per protocol version: the first input that recorded it gives it.
  Statement design(src, "SELECT protocol_version_id, position, name, role, type, unit, allowed FROM "
                        "design_columns ORDER BY protocol_version_id, position");
  Statement insert_design(dst, "INSERT INTO design_columns (protocol_version_id, position, name, role, type, "
                               "unit, allowed) VALUES (?, ?, ?, ?, ?, ?, ?)");
  std::map<int64_t, bool> had_design;
  while (design.Step()) {
    const int64_t id = Mapped(protocol_ids, design.GetInt64(0), input, "protocol version");
    if (!had_design.count(id))
      had_design[id] = dst.QueryInt64("SELECT count(*) FROM design_columns WHERE protocol_version_id = " +
                                      std::to_string(id)) > 0;
    if (had_design[id]) continue;
    insert_design.Bind(1, id);
    insert_design.Bind(2, design.GetInt64(1));
    for (int column = 2; column <= 6; ++column) insert_design.Bind(column + 1, design.GetText(column));
    insert_design.Run();
    insert_design.Reset();
  }
}

// One input's participants, renamed as asked. People kept apart: a code an earlier input holds in the same study is
// two people or one person at two stations; merge does not guess which.
void CopyParticipants(Database& src, Database& dst, const std::filesystem::path& input, const Renames& rename,
                      const std::set<std::string>& same_person, const IdMap& study_ids, IdMap& participant_ids) {
  Statement participants(src, "SELECT p.id, p.study_id, p.code, p.created, s.name FROM participants p JOIN "
                              "studies s ON s.id = p.study_id");
  Statement holds(dst, "SELECT count(*) FROM participants WHERE study_id = ? AND code = ?");
  while (participants.Step()) {
    const int64_t study = Mapped(study_ids, participants.GetInt64(1), input, "study");
    std::string code = participants.GetText(2);
    if (const auto r = rename.find(code); r != rename.end()) {
      if (const std::string why = ParticipantIdProblem(r->second); !why.empty())
        throw InputError("--rename " + input.string() + ":" + code + "=" + OneLine(r->second), "the new id " + why);
      code = r->second;
    }
    holds.Bind(1, study);
    holds.Bind(2, code);
    holds.Step();
    const bool taken = holds.GetInt64(0) > 0;
    holds.Reset();
    // A session of this participant already in the merge is an input merged twice: said by CopySessions.
    bool merged_before = false;
    if (taken) {
      Statement own(src, "SELECT seed, host, started FROM sessions WHERE participant_id = ?");
      own.Bind(1, participants.GetInt64(0));
      Statement twin(dst, "SELECT count(*) FROM sessions s JOIN participants p ON p.id = s.participant_id "
                          "WHERE p.study_id = ? AND p.code = ? AND s.seed = ? AND s.host = ? AND s.started = ?");
      while (own.Step() && !merged_before) {
        twin.Bind(1, study);
        twin.Bind(2, code);
        twin.Bind(3, own.GetInt64(0));
        twin.Bind(4, own.GetText(1));
        twin.Bind(5, own.GetText(2));
        twin.Step();
        merged_before = twin.GetInt64(0) > 0;
        twin.Reset();
      }
    }
    if (taken && !merged_before && !same_person.count(code))
      throw InputError(input.string(), "participant " + code + " of study " + participants.GetText(4) +
                                           " is also in an earlier input of this merge: two people with one id, "
                                           "or one person who ran at two stations? Two people: give one another "
                                           "id with --rename " + input.string() + ":" + code + "=NEW; one "
                                           "person: say so with --same-person " + code);
    participant_ids[participants.GetInt64(0)] = EnsureParticipant(dst, study, code, participants.GetText(3));
  }
}

// One input's sessions and their info; the number each had in its input goes to `numbered`.
void CopySessions(Database& src, Database& dst, const std::filesystem::path& input, int version,
                  const IdMap& participant_ids, const IdMap& protocol_ids, IdMap& session_ids,
                  std::map<int64_t, Numbered>& numbered) {
  Statement sessions(src, "SELECT id, participant_id, protocol_version_id, seed, software_version, host, "
                          "display, started, ended, status, " +
                          std::string(version >= 3 ? "display_profile" : "'{}'") + ", " +
                          std::string(version >= 6 ? "group_name, participant_info" : "'', '{}'") +
                          TypedSelect("sessions", version) + " FROM sessions");
  Statement duplicate(dst, "SELECT id FROM sessions WHERE participant_id = ? AND protocol_version_id = ? "
                           "AND seed = ? AND host = ? AND started = ?");
  Statement insert_session(dst, "INSERT INTO sessions (participant_id, protocol_version_id, seed, "
                                "software_version, host, display, started, ended, status, display_profile, "
                                "group_name, participant_info" + CopiedNames("sessions") +
                                ") VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?" + CopiedPlaceholders("sessions") + ")");
  const int number_at = 13 + TypedIndex("sessions", "session_number");
  while (sessions.Step()) {
    const int64_t participant = Mapped(participant_ids, sessions.GetInt64(1), input, "participant");
    const int64_t protocol = Mapped(protocol_ids, sessions.GetInt64(2), input, "protocol version");
    duplicate.Bind(1, participant);
    duplicate.Bind(2, protocol);
    duplicate.Bind(3, sessions.GetInt64(3));
    duplicate.Bind(4, sessions.GetText(5));
    duplicate.Bind(5, sessions.GetText(7));
    if (duplicate.Step())
      throw InputError(input.string(), "session " + std::to_string(sessions.GetInt64(0)) +
                                           " is already in the merge (an input merged twice?)");
    duplicate.Reset();
    insert_session.Bind(1, participant);
    insert_session.Bind(2, protocol);
    insert_session.Bind(3, sessions.GetInt64(3));
    for (int column = 4; column <= 7; ++column) insert_session.Bind(column, sessions.GetText(column));
    if (sessions.IsNull(8)) insert_session.BindNull(8);
    else insert_session.Bind(8, sessions.GetText(8));
    for (int column = 9; column <= 12; ++column) insert_session.Bind(column, sessions.GetText(column));
    CopyTyped("sessions", sessions, 13, insert_session, 13);
    insert_session.Run();
    insert_session.Reset();
    session_ids[sessions.GetInt64(0)] = dst.LastInsertRowId();
    if (!sessions.IsNull(number_at))
      numbered[dst.LastInsertRowId()] = {input.string(), sessions.GetInt64(0), sessions.GetInt64(number_at)};
  }
  if (version < 7) return;
  Statement info(src, "SELECT session_id, key, value FROM session_info");
  Statement insert_info(dst, "INSERT INTO session_info (session_id, key, value) VALUES (?, ?, ?)");
  while (info.Step()) {
    insert_info.Bind(1, Mapped(session_ids, info.GetInt64(0), input, "session"));
    insert_info.Bind(2, info.GetText(1));
    insert_info.Bind(3, info.GetText(2));
    insert_info.Run();
    insert_info.Reset();
  }
}

// One input's trials, answers and frames (frame_columns.h: NULL for the values its version did not have).
void CopyTrials(Database& src, Database& dst, const std::filesystem::path& input, int version,
                const IdMap& session_ids) {
  IdMap trial_ids;
  Statement trials(src, "SELECT id, session_id, trial_index, block, factors, left_shown, right_shown" +
                            TypedSelect("trials", version) + " FROM trials");
  Statement insert_trial(dst, "INSERT INTO trials (session_id, trial_index, block, factors, left_shown, "
                              "right_shown" + CopiedNames("trials") + ") VALUES (?, ?, ?, ?, ?, ?" +
                              CopiedPlaceholders("trials") + ")");
  while (trials.Step()) {
    insert_trial.Bind(1, Mapped(session_ids, trials.GetInt64(1), input, "session"));
    insert_trial.Bind(2, trials.GetInt64(2));
    insert_trial.Bind(3, trials.GetInt64(3));
    for (int column = 4; column <= 6; ++column) insert_trial.Bind(column, trials.GetText(column));
    CopyTyped("trials", trials, 7, insert_trial, 7);
    insert_trial.Run();
    insert_trial.Reset();
    trial_ids[trials.GetInt64(0)] = dst.LastInsertRowId();
  }

  Statement responses(src, "SELECT trial_id, choice, rt_ms, adjustment, answered_at, " +
                               std::string(version >= 5 ? "shown" : "'{}'") + TypedSelect("responses", version) +
                               " FROM responses");
  Statement insert_response(dst, "INSERT INTO responses (trial_id, choice, rt_ms, adjustment, answered_at, "
                                 "shown" + CopiedNames("responses") + ") VALUES (?, ?, ?, ?, ?, ?" +
                                 CopiedPlaceholders("responses") + ")");
  while (responses.Step()) {
    insert_response.Bind(1, Mapped(trial_ids, responses.GetInt64(0), input, "trial"));
    insert_response.Bind(2, responses.GetText(1));
    if (responses.IsNull(2)) insert_response.BindNull(3);
    else insert_response.Bind(3, responses.GetDouble(2));
    insert_response.Bind(4, responses.GetText(3));
    insert_response.Bind(5, responses.GetText(4));
    insert_response.Bind(6, responses.GetText(5));
    CopyTyped("responses", responses, 6, insert_response, 7);
    insert_response.Run();
    insert_response.Reset();
  }

  Statement frames(src, "SELECT trial_id" + CopySelect(FrameColumns(), version) + " FROM frames");
  Statement insert_frame(dst, InsertSql("frames", "trial_id", FrameColumns()));
  while (frames.Step()) {
    insert_frame.Bind(1, Mapped(trial_ids, frames.GetInt64(0), input, "trial"));
    CopyKept(FrameColumns(), frames, 1, insert_frame, 2);
    insert_frame.Run();
    insert_frame.Reset();
  }
}

// What the merged record says that its inputs did not: sessions numbered again, protocol versions with several
// texts, one participant's sessions run with one seed.
std::vector<std::string> TellWhatChanged(Database& dst, const std::map<int64_t, Numbered>& numbered) {
  std::vector<std::string> told;
  Statement number(dst, "SELECT s.session_number, st.name, p.code FROM sessions s JOIN participants p ON "
                        "p.id = s.participant_id JOIN studies st ON st.id = p.study_id WHERE s.id = ?");
  for (const auto& [id, was] : numbered) {
    number.Bind(1, id);
    number.Step();
    if (number.GetInt64(0) != was.number)
      told.push_back(was.input + ": session " + std::to_string(was.session) + " (study " + number.GetText(1) +
                     ", participant " + number.GetText(2) + ") is session number " + std::to_string(was.number) +
                     " there and " + std::to_string(number.GetInt64(0)) + " in the merged record (numbered by start)");
    number.Reset();
  }
  // Stations that each ran another text under one version (or records made before versions were kept apart) are
  // merged as they are; the tables cannot tell those sessions' designs apart by version, so say so.
  Statement shared(dst, "SELECT st.name, pv.version, count(*) FROM protocol_versions pv JOIN studies st ON "
                        "st.id = pv.study_id GROUP BY pv.study_id, pv.version HAVING count(*) > 1 "
                        "ORDER BY st.name, pv.version");
  while (shared.Step())
    told.push_back("study " + shared.GetText(0) + ": protocol version " + std::to_string(shared.GetInt64(1)) +
                   " has " + std::to_string(shared.GetInt64(2)) + " different texts in the merged record "
                   "(protocol_hash tells their sessions apart)");
  // Two stations that each ran a participant's first session gave both the default seed: merged they read as one
  // person seeing one trial order twice, which run refuses. It used to pass untold; it is likely two people given
  // one id, so say so (the record cannot tell).
  Statement twins(dst, "SELECT st.name, p.code, group_concat(s.session_number, ', ') FROM (SELECT * FROM sessions "
                       "ORDER BY session_number) s JOIN participants p ON p.id = s.participant_id JOIN studies st "
                       "ON st.id = p.study_id GROUP BY s.participant_id, s.seed HAVING count(*) > 1 "
                       "ORDER BY st.name, p.code");
  while (twins.Step())
    told.push_back("study " + twins.GetText(0) + ", participant " + twins.GetText(1) + ": sessions " +
                   twins.GetText(2) + " in the merged record ran with one seed, so in one trial order - "
                   "two people given one id at two stations, or one person shown the same order twice; "
                   "check before analysing them as one participant");
  return told;
}

}  // namespace

void MergeDatabases(const std::vector<std::filesystem::path>& inputs, const std::filesystem::path& out,
                    const ProgressNote& note, const MergeOptions& options) {
  Note(note, RemoveStaleLeftovers(out));
  if (std::filesystem::exists(out)) throw InputError(out.string(), "exists; merge refuses to overwrite it");
  const std::map<std::filesystem::path, Renames> renames = CheckMergeInputs(inputs, options);
  const std::set<std::string> same_person(options.same_person.begin(), options.same_person.end());
  const std::filesystem::path temp = TemporaryBeside(out, "partial");
  RemoveDatabaseFiles(temp);
  std::vector<std::string> unfinished, told;
  std::map<int64_t, Numbered> numbered;
  try {
    {
      Database dst(temp);
      Migrate(dst);
      Transaction transaction(dst);
      for (const auto& input : inputs) {
        Database src(input, OpenMode::kReadOnly);
        RequireReadableRecord(src);
        // One snapshot of the input: the sessions judged below are the ones copied, with the answers they had then.
        src.Exec("BEGIN");
        CheckSessionsToMerge(src, input, &unfinished);
        IdMap study_ids, protocol_ids, participant_ids, session_ids;
        const int version = SchemaVersion(src);
        CopyStudiesAndProtocols(src, dst, input, version, study_ids, protocol_ids);
        const auto own = renames.find(std::filesystem::weakly_canonical(input));
        CopyParticipants(src, dst, input, own == renames.end() ? Renames() : own->second, same_person, study_ids,
                         participant_ids);
        CopySessions(src, dst, input, version, participant_ids, protocol_ids, session_ids, numbered);
        CopyTrials(src, dst, input, version, session_ids);
        src.Exec("COMMIT");
      }
      // Inputs from before the typed record: their typed columns from their texts, as a migration would.
      DeriveTypedColumns(dst);
      // A participant's sessions from several stations are numbered again by start, all together: two inputs' first
      // sessions cannot both be number 1. Each number that differs from its input's is told.
      DeriveVersionsAndNumbers(dst);
      NumberSessions(dst, true);
      told = TellWhatChanged(dst, numbered);
      transaction.Commit();
    }  // the last connection closes: the WAL is checkpointed into the file and removed
    MoveIntoPlace(temp, out);
    if (note) {
      for (const auto& line : unfinished) note(line);
      for (const auto& line : told) note(line);
    }
  } catch (...) {
    RemoveDatabaseFiles(temp);
    throw;
  }
}

}  // namespace blurcue::store
