// What a new session checks and records of its study and participant, inside StartOrResumeSession's transaction:
// protocol versions kept apart, the design recorded once per version, the session's number and a seed of its own.
#include <algorithm>
#include <charconv>
#include <map>
#include <string>

#include "core/error.h"
#include "core/json_io.h"
#include "store/record.h"
#include "store/record_texts.h"
#include "store/schema.h"

namespace blurcue::store {
namespace {

using detail::ParseBoth;
using detail::SessionName;



// The first place two protocol texts differ, as "POINTER: OLD in the record, NEW now" ("absent" for a member one
// of them lacks); "the recorded text is not JSON" for a damaged record.
std::string FirstChange(const std::string& recorded, const std::string& now, bool ignore_version) {
  Json a, b;
  if (!ParseBoth(recorded, now, &a, &b)) return "the recorded text is not JSON";
  if (ignore_version && a.is_object() && b.is_object()) a.erase("version"), b.erase("version");
  const Json patch = Json::diff(a, b);
  if (patch.empty()) return "the same text but for /version";
  const Json& op = patch.front();
  const std::string path = op.at("path").get<std::string>();
  auto value = [](const Json& v) {
    const std::string t = v.dump();
    return t.size() > 60 ? t.substr(0, 57) + "..." : t;
  };
  const std::string kind = op.at("op").get<std::string>();
  const std::string before = kind == "add" ? "absent" : value(a.at(Json::json_pointer(path)));
  const std::string after = kind == "remove" ? "absent" : value(op.at("value"));
  return (path.empty() ? "/" : path) + ": " + before + " in the record, " + after + " now";
}

// Shortest text that reads back as the same double.
std::string Shortest(double value) {
  char text[64];
  const auto result = std::to_chars(text, text + sizeof(text), value);
  return std::string(text, result.ptr);
}

}  // namespace

std::string AllowedText(const DesignColumnRecord& column) {
  std::string text;
  if (!column.numbers.empty()) {
    for (double v : column.numbers) text += (text.empty() ? "" : "|") + Shortest(v);
  } else if (!column.names.empty()) {
    for (const std::string& v : column.names) text += (text.empty() ? "" : "|") + v;
  } else if (column.min && column.max) {
    text = Shortest(*column.min) + ".." + Shortest(*column.max);
  } else if (column.min) {
    text = ">= " + Shortest(*column.min);
  }
  return text;
}

void Record::CheckProtocolVersion(int64_t study_id, const std::string& study, const std::string& canonical,
                                  const std::string& hash, int64_t version) {
  Statement same(db_, "SELECT count(*) FROM protocol_versions WHERE study_id = ? AND hash = ?");
  same.Bind(1, study_id);
  same.Bind(2, hash);
  same.Step();
  if (same.GetInt64(0) > 0) return;  // a text the study already records: as it was
  // The highest recorded version first: a text under it or under an equal version would make one version name two
  // designs in the tables.
  Statement others(db_, "SELECT coalesce(version, 1), json FROM protocol_versions WHERE study_id = ? "
                        "AND coalesce(version, 1) >= ? ORDER BY coalesce(version, 1) DESC, id DESC LIMIT 1");
  others.Bind(1, study_id);
  others.Bind(2, version);
  if (!others.Step()) return;
  const int64_t recorded = others.GetInt64(0);
  const std::string way_out = "; raise \"version\" to " + std::to_string(recorded + 1) +
                              " to record it as a new version, or use another record (--db)";
  if (recorded == version)
    throw InputError(db_.path(), "study " + study + " records protocol version " + std::to_string(version) +
                                     " with another text (" + FirstChange(others.GetText(1), canonical, false) + ")" +
                                     way_out);
  throw InputError(db_.path(), "study " + study + " records protocol version " + std::to_string(recorded) +
                                   ", this protocol says version " + std::to_string(version) +
                                   " with another text (" + FirstChange(others.GetText(1), canonical, true) + ")" +
                                   way_out);
}

void Record::SaveDesign(int64_t protocol_id, const std::string& study, int64_t version,
                        const std::vector<DesignColumnRecord>& design) {
  Statement set(db_, "UPDATE protocol_versions SET version = ? WHERE id = ? AND version IS NULL");
  set.Bind(1, version);
  set.Bind(2, protocol_id);
  set.Run();
  if (design.empty()) return;
  // Once per protocol version: its sessions share one text, so one design - unless a file the text names changed
  // (a conditions table's rows are not in the text). Such a session used to be recorded under the same version,
  // the codebook giving the first session's values for both.
  // Only the columns the levels set (roles within and procedure_cell) are compared: a label varies nothing, and a
  // later build may describe the other columns otherwise.
  auto varies = [](const std::string& role) { return role == "within" || role == "procedure_cell"; };
  Statement recorded(db_, "SELECT name, role, allowed FROM design_columns WHERE protocol_version_id = ? "
                          "ORDER BY position");
  recorded.Bind(1, protocol_id);
  std::map<std::string, std::string> before, now;
  bool any = false;
  while (recorded.Step()) {
    any = true;
    if (varies(recorded.GetText(1))) before[recorded.GetText(0)] = recorded.GetText(2);
  }
  if (any) {
    for (const DesignColumnRecord& c : design)
      if (varies(c.role)) now[c.name] = AllowedText(c);
    std::string change;
    for (const auto& [name, allowed] : before) {
      const auto it = now.find(name);
      if (it == now.end()) change = "column " + name + " in the record, absent now";
      else if (it->second != allowed) change = "column " + name + ": " + allowed + " in the record, " + it->second + " now";
      if (!change.empty()) break;
    }
    for (const auto& [name, allowed] : now)
      if (change.empty() && !before.count(name)) change = "column " + name + " absent in the record, present now";
    if (change.empty()) return;
    throw InputError(db_.path(), "study " + study + " records protocol version " + std::to_string(version) +
                                     " with another design (" + change + "): the text is the same, so a file it "
                                     "names (a conditions table) has changed; raise \"version\" to " +
                                     std::to_string(version + 1) +
                                     " to record it as a new version, or use another record (--db)");
  }
  Statement insert(db_, "INSERT INTO design_columns (protocol_version_id, position, name, role, type, unit, allowed) "
                        "VALUES (?, ?, ?, ?, ?, ?, ?)");
  int64_t position = 0;
  for (const DesignColumnRecord& c : design) {
    insert.Bind(1, protocol_id);
    insert.Bind(2, position++);
    insert.Bind(3, c.name);
    insert.Bind(4, c.role);
    insert.Bind(5, c.type);
    insert.Bind(6, c.unit);
    insert.Bind(7, AllowedText(c));
    insert.Run();
    insert.Reset();
  }
}

int64_t Record::NextSessionNumber(int64_t participant_id, const std::string& study, const std::string& participant,
                                  uint64_t seed, const SessionMeta& meta) {
  const int64_t number = db_.QueryInt64("SELECT coalesce(max(session_number), 0) + 1 FROM sessions WHERE "
                                        "participant_id = " + std::to_string(participant_id));
  const std::string who = "participant " + participant + " of study " + study;
  if (meta.seed_for_number > 0 && meta.seed_for_number != number)
    throw InputError(db_.path(), "the session of " + who + " was prepared as session number " +
                                     std::to_string(meta.seed_for_number) + " with its seed, but the record now "
                                     "gives it number " + std::to_string(number) + " (another station started a "
                                     "session of this participant meanwhile?); run it again");
  // The same seed makes the same trial order (and a simulated observer's same answers): a copy, not a session.
  Statement used(db_, "SELECT id, coalesce(session_number, 0) FROM sessions WHERE participant_id = ? AND seed = ? "
                      "ORDER BY id LIMIT 1");
  used.Bind(1, participant_id);
  used.Bind(2, static_cast<int64_t>(seed));
  if (used.Step())
    throw InputError(db_.path(), std::string(meta.seed_given ? "--seed " : "seed ") + std::to_string(seed) +
                                     " is the seed of " + who + "'s session number " + std::to_string(used.GetInt64(1)) +
                                     " (" + SessionName(used.GetInt64(0)) + "): a session with it repeats that "
                                     "session's trial order; " +
                                     (meta.seed_given ? "leave out --seed (each session number gets a seed of its own) "
                                                        "or give another"
                                                      : "give another with --seed"));
  return number;
}

SessionsSoFar PeekSessions(const std::filesystem::path& db_path, const std::string& study,
                           const std::string& participant) {
  SessionsSoFar so_far;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(db_path, ec) || std::filesystem::file_size(db_path, ec) == 0) return so_far;
  try {
    Database db(db_path, OpenMode::kReadOnly);
    // No page check here (Record::Open makes it, and refuses a damaged file before anything runs): a peek that
    // read every page would double a large record's start-up.
    // A record from before the application id was stamped has 0 (another program's file fails the queries below).
    const int64_t id = db.QueryInt64("PRAGMA application_id");
    if (db.QueryInt64("SELECT count(*) FROM sqlite_schema") == 0 || (id != kApplicationId && id != 0) ||
        SchemaVersion(db) > CurrentSchemaVersion())
      return so_far;
    // Before version 8 the migration numbers a participant's sessions by start: a session's number is its place.
    const std::string place = "(SELECT count(*) FROM sessions o WHERE o.participant_id = s.participant_id AND "
                              "(o.started < s.started OR (o.started = s.started AND o.id <= s.id)))";
    const std::string number = SchemaVersion(db) >= 8 ? "coalesce(s.session_number, " + place + ")" : place;
    const std::string of = " FROM sessions s JOIN participants p ON p.id = s.participant_id JOIN studies st ON "
                           "st.id = p.study_id WHERE st.name = ? AND p.code = ?";
    Statement next(db, "SELECT coalesce(max(" + number + "), 0) + 1" + of);
    next.Bind(1, study);
    next.Bind(2, participant);
    next.Step();
    so_far.next_number = next.GetInt64(0);
    Statement running(db, "SELECT s.seed, " + number + of + " AND s.status = 'running' ORDER BY s.id DESC LIMIT 1");
    running.Bind(1, study);
    running.Bind(2, participant);
    if (running.Step()) {
      so_far.unfinished = true;
      so_far.unfinished_seed = static_cast<uint64_t>(running.GetInt64(0));
      so_far.unfinished_number = running.GetInt64(1);
    }
  } catch (const Error&) {
    return {};  // not a record this build reads: opening it for the session says why
  }
  return so_far;
}

}  // namespace blurcue::store
