#include "cli/commands.h"

namespace blurcue::cli {

// placeholder: being written
void AddEstimateCommand(CLI::App&) {}

}  // namespace blurcue::cli
