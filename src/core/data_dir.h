#pragma once
// Where blurcue finds what it ships besides its binary: shaders/, stimuli/, analysis/ and protocols/.
#include <filesystem>
#include <string>

namespace blurcue {

struct DataDirectory {
  std::filesystem::path path;
  // How it was found: "BLURCUE_DATA_DIR" (the environment), "installed" (beside the binary, ../share/blurcue) or
  // "source tree" (the tree this binary was built from, when it runs from its build folder).
  std::string origin;
};

// BLURCUE_DATA_DIR when set; else ../share/blurcue beside the running binary when that holds shaders/ (an installed,
// relocatable blurcue: `cmake --install build --prefix P`, moved anywhere); else the source tree it was built from.
// Looked up once.
const DataDirectory& DataDir();

// The folder of the running executable (/proc/self/exe); empty when it cannot be read.
std::filesystem::path ExecutableDir();
// The running executable itself, whatever it is named (a copy as /tmp/bc ran /tmp/blurcue); "blurcue" on PATH when
// /proc/self/exe cannot be read.
std::filesystem::path ExecutablePath();

}  // namespace blurcue
