#pragma once
// The virtual objects `ar` and `live` place on the board, from their options: --ball X,Y[,R], --card
// X,Y[,W[,H]] (board mm) and --objects FILE, each texture decoded once however many objects wear it.
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "core/output_guard.h"
#include "stimulus/tracked_take.h"

namespace blurcue::cli {

struct ObjectOptions {
  std::vector<std::string> balls, cards;
  std::string objects_file, ball_texture = "soccer", card_texture = "wood";
};

// --ball, --card, --objects, --ball-texture and --card-texture on `cmd`, into `options`.
void AddObjectOptions(CLI::App* cmd, ObjectOptions* options);
// The files the options read (the objects file, the textures of the objects given), as inputs no output may be.
void GuardObjectInputs(OutputGuard& guard, const ObjectOptions& options);

// The objects of the file first, then the balls, then the cards; `given[i]` says where object i was given, for
// messages (the option, or the file and its JSON pointer). Error(kUsage) naming the option for a malformed value,
// more than stimulus::kMaxPlacedObjects objects or none at all; Error(kInput) for the file's own errors.
std::vector<stimulus::PlacedObject> PlaceObjects(const ObjectOptions& options, std::vector<std::string>* given);

}  // namespace blurcue::cli
