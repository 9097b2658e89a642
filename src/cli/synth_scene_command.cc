#include "cli/commands.h"

namespace blurcue::cli {

// placeholder: being written
void AddSynthSceneCommand(CLI::App&) {}

}  // namespace blurcue::cli
