#pragma once
// The frames table's recorded values, defined once: what each display flip of a trial showed (FrameRecord), each
// value with its SQL type and CHECK, the schema version that added it and its row of the codebook. Generated from it:
// the migration that adds version 9's, the record's INSERT, the merge's copy, and frames.csv's columns after the
// session's and the trial's.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "store/columns.h"

namespace blurcue::store {

struct FrameRecord {
  int64_t frame_index = 0;
  double flip_time_s = 0;
  bool dropped = false;
  // What the frame showed of a pair: each side's blur radius (photo px) and the objects' place along the board's y
  // (mm); empty for a side not shown (a ball wiped at the end of its section) and for pictures.
  std::optional<double> r_left_px, r_right_px, y_mm;
  // Schema 9. A study on video: the take's frame on screen and its status (found, tracked, or held: a lost frame or
  // one past the take's end, showing the last frame with a pose); empty for a photo's study. Each side shown: its
  // lens floor (std) and motion streak (photo px, x right, y down) in this frame.
  std::optional<int64_t> take_frame;
  std::optional<std::string> take_status;
  std::optional<double> floor_sigma_left_px, floor_sigma_right_px, motion_left_x_px, motion_left_y_px,
      motion_right_x_px, motion_right_y_px;
};

// The take statuses a frame may record (take_status's CHECK and the codebook's allowed values).
inline constexpr const char* kTakeStatuses[] = {"found", "tracked", "held"};

struct FrameValue {
  std::string name;                  // the column, in the frames table and frames.csv
  std::string type, unit, allowed, meaning;  // the codebook's
  std::string sql, check;            // INTEGER | REAL | TEXT; "" = no CHECK
  int since = 1;                     // the schema version that added it (1: the table's own)
  Value (*of)(const FrameRecord&) = nullptr;
};

// In the table's order.
const std::vector<FrameValue>& FrameValues();

// "ALTER TABLE frames ADD COLUMN ...;" for the values schema version `version` added.
std::string AddFrameColumnsSql(int version);

// Binds a value to parameter `index` (NULL for none).
void BindValue(Statement& insert, int index, const Value& value);

}  // namespace blurcue::store
