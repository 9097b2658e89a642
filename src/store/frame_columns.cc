#include "store/frame_columns.h"

#include "protocol/vocabulary.h"
#include "store/sqlite.h"

namespace blurcue::store {
namespace {

Value Maybe(const std::optional<double>& v) { return v ? Value(*v) : Value(); }

// A column of the frames table: its codebook definition, SQL type, CHECK, the version that added it, its reader.
FrameColumn FrameKept(ColumnSpec spec, const std::string& sql, const std::string& check, int since,
                      std::function<Value(const FrameRecord&)> of) {
  FrameColumn c;
  static_cast<ColumnSpec&>(c) = std::move(spec);
  c.sql = sql, c.check = check, c.since = since, c.of = std::move(of);
  return c;
}
// A column of frames.csv read from another table (`select`), written as `cell`.
FrameColumn FrameJoined(ColumnSpec spec, const std::string& select, enum Cell cell) {
  FrameColumn c;
  static_cast<ColumnSpec&>(c) = std::move(spec);
  c.select = select, c.cell = cell;
  return c;
}

std::string StatusCheck() {
  std::string list;
  for (const char* s : kTakeStatuses) list += (list.empty() ? "'" : ", '") + std::string(s) + "'";
  return "take_status IN (" + list + ")";
}

std::string StatusAllowed() {
  std::string list;
  for (const char* s : kTakeStatuses) list += (list.empty() ? "" : "|") + std::string(s);
  return list;
}

}  // namespace

namespace {

// One quantity of each side in photo px (FrameSide's member): its two columns, named by SideColumn, in the table's
// order. `meaning` gives a side's text of the codebook.
void AddSides(std::vector<FrameColumn>* values, const std::string& quantity, const std::string& suffix,
              std::optional<double> FrameSide::*member, const std::string& allowed, int since,
              const std::function<std::string(protocol::Side)>& meaning) {
  for (const protocol::Side side : protocol::Vocabulary<protocol::Side>::values)
    values->push_back(
        FrameKept({SideColumn(quantity, side, suffix), "number", "photo px", allowed, meaning(side)}, "REAL", "", since,
                  [member, k = protocol::Index(side)](const FrameRecord& f) { return Maybe(f.sides[k].*member); }));
}

// long: a data table, one row per column of frames.csv.
std::vector<FrameColumn> MakeFrameColumns() {
  using F = FrameRecord;
  using protocol::Side;
  std::vector<FrameColumn> values = {
      // frames.csv's columns of the session and the trial (a join, not the table's).
      FrameJoined({"study", "string", "", "", "the protocol's name"}, "st.name", Cell::kText),
      FrameJoined({"participant", "string", "", "", "the participant's id"}, "p.code", Cell::kText),
      FrameJoined({"session_id", "integer", "", ">= 1", "the session's id in this record (as in trials.csv)"}, "s.id",
                  Cell::kInteger),
      FrameJoined(
          {"window", "boolean", "", "0|1", "1: a real window on the real clock; 0: headless on a simulated clock"},
          "coalesce(s.window, s.display LIKE 'window%')", Cell::kInteger),
      FrameJoined({"trial_index", "integer", "", ">= 0", "the trial (as in trials.csv)"}, "t.trial_index",
                  Cell::kInteger),
      // The table's own (version 1's are its CREATE TABLE's).
      FrameKept({"frame_index", "integer", "", ">= 0", "the frame's place in the trial"}, "INTEGER", "", 1,
                [](const F& f) { return Value(f.frame_index); }),
      FrameKept(
          {"flip_time_s", "number", "s", ">= 0", "when the frame reached the screen, from the trial's first flip"},
          "REAL", "", 1, [](const F& f) { return Value(f.flip_time_s); }),
      FrameKept(
          {"dropped", "boolean", "", "0|1", "1: more than 1.5 refresh periods after the frame before (window only)"},
          "INTEGER", "", 1, [](const F& f) { return Value(int64_t(f.dropped ? 1 : 0)); }),
  };
  AddSides(&values, "r", "px", &FrameSide::r_px, ">= 0", 4, [](Side side) -> std::string {
    if (side == Side::kRight) return "the right object's blur radius in this frame; empty: not shown";
    return "the left object's blur radius as drawn in this frame (without the motion; under a streak at least the "
           "width the streak is drawn with across it, up to 1 screen px); empty: not shown";
  });
  values.push_back(
      FrameKept({"y_mm", "number", "mm", "", "the objects' place along the board's y in this frame (0 at edge 1)"},
                "REAL", "", 4, [](const F& f) { return Maybe(f.y_mm); }));
  values.push_back(FrameKept(
      {"take_frame", "integer", "", ">= 0",
       "a study on video: the take's frame at this moment (its index in track.csv; past the take's end its last); "
       "when held, the photo and objects on screen are those of the last frame with a pose before it; empty for "
       "a photo"},
      "INTEGER", "take_frame >= 0", 9, [](const F& f) { return f.take_frame ? Value(*f.take_frame) : Value(); }));
  values.push_back(FrameKept(
      {"take_status", "string", "", StatusAllowed(),
       "a study on video: the take frame's status (found or tracked: shown at its own pose; held: a lost frame or "
       "one past the take's end, showing the last frame with a pose); empty for a photo"},
      "TEXT", StatusCheck(), 9, [](const F& f) { return f.take_status ? Value(*f.take_status) : Value(); }));
  AddSides(&values, "floor_sigma", "px", &FrameSide::floor_sigma_px, ">= 0", 9, [](Side side) -> std::string {
    if (side == Side::kRight) return "... the right object's";
    return "the lens floor (std) inside the left object's radius in this frame; empty: not shown";
  });
  // A streak's x and y of one side, then the other's.
  for (const Side side : protocol::Vocabulary<Side>::values) {
    const size_t k = protocol::Index(side);
    values.push_back(FrameKept(
        {SideColumn("motion", side, "x_px"), "number", "photo px", "",
         side == Side::kLeft ? "the left object's motion streak in this frame (its image velocity x the exposure: "
                               "its own motion's and, on video, the camera's), x right; empty: not shown"
                             : "the right object's, x right"},
        "REAL", "", 9, [k](const F& f) { return Maybe(f.sides[k].motion_x_px); }));
    values.push_back(FrameKept({SideColumn("motion", side, "y_px"), "number", "photo px", "", "... y down"}, "REAL", "",
                               9, [k](const F& f) { return Maybe(f.sides[k].motion_y_px); }));
  }
  return values;
}

}  // namespace

const std::vector<FrameColumn>& FrameColumns() {
  static const std::vector<FrameColumn> columns = WithCells(MakeFrameColumns());
  return columns;
}

}  // namespace blurcue::store
