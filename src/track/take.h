#pragma once
// A whole take tracked: frames read, tracked and measured one by one, one lens model fitted to all of them, and the
// result written as calibrate-format calib-NNNN.json files and a track.csv.
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "optics/fit.h"
#include "track/frames.h"
#include "track/tracker.h"

namespace blurcue::track {

struct TakeResult {
  std::vector<FrameResult> frames;       // every frame read, in order (lost ones too)
  std::optional<optics::FittedModel> model;  // the take's lens model; empty when no frame had a calibration
  std::optional<Error> error;            // what ended the take early (a damaged video, a missing frame)
  double decode_ms = 0;                  // reading and decoding all frames
  int tracked = 0, found = 0, lost = 0;
};

// Reads every frame from `source` and processes it with `tracker`; an input error (damaged video, gap in a
// sequence, unreadable frame) ends the take there and is kept in `error` with what was tracked before it.
// `progress` gets each frame's result as it is done.
TakeResult TrackTake(FrameSource& source, Tracker& tracker,
                     const std::function<void(const FrameResult&)>& progress = {});

// DIR/calib-NNNN.json for every frame with a calibration (calibrate's format, the take's lens model; "frame" and
// "time_s" added) and DIR/track.csv, one row per frame (kTrackColumns). `input` is recorded in each calib file.
// The folder is built beside DIR and swapped in whole (core/atomic_file.h WriteFolderAtomically): a reader, or a
// run killed meanwhile, sees the earlier track or the new one, never a mix. A DIR holding files other than a
// track's (IsTrackFile) is refused, Error(kInput), before anything is written.
void WriteTake(const TakeResult& take, const std::filesystem::path& dir, const std::string& input);

// True for the names a track folder holds: track.csv and calib-NNNN.json (and .NAME.tmp-PID of them, which a killed
// earlier version left there).
bool IsTrackFile(const std::string& name);

// track.csv's columns, in order, with their meaning (docs/track.md explains them).
struct TrackColumn {
  const char* name;
  const char* meaning;
};
extern const std::vector<TrackColumn> kTrackColumns;

std::string CalibFileName(int index);  // calib-0007.json

}  // namespace blurcue::track
