#pragma once
// The frames table and frames.csv, defined once: what each display flip of a trial showed (FrameRecord), each value
// with its SQL type and CHECK, the schema version that added it and its row of the codebook, and frames.csv's columns
// read from the session and the trial (a declared join). Generated from the one list (FrameColumns, table_columns.h):
// the migrations that added versions 4's and 9's columns, the record's INSERT, the merge's copy, frames.csv's header,
// SELECT and cells, and the codebook's rows.
#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "store/table_columns.h"

namespace blurcue::store {

// What a frame showed on one side of a pair: the blur radius (photo px) and, schema 9, the lens floor (std) and the
// motion streak (photo px, x right, y down); empty for a side not shown (a ball wiped at the end of its section) and
// for pictures. Recorded as r_SIDE_px, floor_sigma_SIDE_px, motion_SIDE_x_px, motion_SIDE_y_px (SideColumn).
struct FrameSide {
  std::optional<double> r_px, floor_sigma_px, motion_x_px, motion_y_px;
};

struct FrameRecord {
  int64_t frame_index = 0;
  double flip_time_s = 0;
  bool dropped = false;
  // What the frame showed of a pair, indexed by protocol::Index(side).
  std::array<FrameSide, 2> sides;
  // The objects' place along the board's y (mm); empty for pictures.
  std::optional<double> y_mm;
  // Schema 9. A study on video: the take's frame on screen and its status (found, tracked, or held: a lost frame or
  // one past the take's end, showing the last frame with a pose); empty for a photo's study.
  std::optional<int64_t> take_frame;
  std::optional<std::string> take_status;
};

// The take statuses a frame may record (take_status's CHECK and the codebook's allowed values).
inline constexpr const char* kTakeStatuses[] = {"found", "tracked", "held"};

// A column of the frames table (kept: read from a FrameRecord by `of`) or of frames.csv only (the session's and the
// trial's, selected over f = frames, t = trials, s = sessions, p = participants, st = studies).
using FrameColumn = TableColumn<FrameRecord>;

// In frames.csv's order: the session's and the trial's columns, then the table's own in the table's order.
const std::vector<FrameColumn>& FrameColumns();

}  // namespace blurcue::store
