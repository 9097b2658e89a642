#pragma once
// A protocol's contact sheet: every distinct stimulus it shows, each at its onset as the window shows it, labelled
// with its levels, each side's radius (photo px, screen px, arcmin), its blur plan and what an observer can see of it.
// `blurcue preview` is its command line.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "procedure/observer.h"
#include "procedure/prepare.h"

namespace blurcue::preview {

struct SheetOptions {
  std::string participant = "P1";  // whose trial list (by_participant sides)
  std::optional<uint64_t> seed;    // default: as blurcue run
  // The groups whose tiles are drawn, each labelled with its name: {""} for a protocol without groups
  // (cli::GroupsToCheck's answer).
  std::vector<std::string> groups = {""};
  procedure::ObserverParams observer;  // the model that predicts what is visible
  double visible = 0.75;               // predicted share correct (2AFC) below which a pair is flagged invisible
  int columns = 6;                     // tiles per row
  int tile_width_px = 320;             // each tile's whole frame; a frame this wide or narrower is shown at 1:1
  int zoom = 1;                        // sheet px per screen px in the 1:1 insets
};

struct Sheet {
  cv::Mat image;                        // 8-bit BGR
  std::vector<std::string> tiles;       // per tile, in sheet order: "#N levels: sides | plan | seen"
  size_t trial_count = 0;               // the trials of every group drawn
  std::vector<std::string> visibility;  // procedure::VisibilityLines of each group, prefixed "group NAME: "
  // procedure::UndeterminedBlurNote of each group that has one (fitted blur where the calibration's model is not
  // determined within 5 %), prefixed as visibility.
  std::vector<std::string> notes;
};

// Called after each tile is drawn with its number (1-based), the tile count and its line of Sheet::tiles.
using SheetProgress = std::function<void(size_t done, size_t total, const std::string& tile)>;

// Draws the contact sheet of `prepared` (procedure::PrepareStudy's; PrepareParticipant is called on it for each
// group). Needs no current GL context (it makes an offscreen one). Throws InputError naming the protocol when it
// makes no trials.
Sheet DrawContactSheet(procedure::PreparedSession* prepared, const SheetOptions& options,
                       const SheetProgress& progress = {});

}  // namespace blurcue::preview
