#include "cli/commands.h"

namespace blurcue::cli {

// placeholder: being written
void AddBenchCommand(CLI::App&) {}

}  // namespace blurcue::cli
