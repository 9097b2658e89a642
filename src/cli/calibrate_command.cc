#include "cli/commands.h"

namespace blurcue::cli {

// placeholder: being written
void AddCalibrateCommand(CLI::App&) {}

}  // namespace blurcue::cli
