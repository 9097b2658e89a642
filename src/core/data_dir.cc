#include "core/data_dir.h"
#include "blurcue/source_dir.h"

#include <cstdlib>
#include <system_error>

namespace blurcue {

std::filesystem::path ExecutableDir() {
  const std::filesystem::path exe = ExecutablePath();
  return exe.has_parent_path() ? exe.parent_path() : std::filesystem::path();
}

std::filesystem::path ExecutablePath() {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::filesystem::path("blurcue") : exe;
}

const DataDirectory& DataDir() {
  static const DataDirectory dir = [] {
    if (const char* env = std::getenv("BLURCUE_DATA_DIR"); env && *env)
      return DataDirectory{std::filesystem::path(env), "BLURCUE_DATA_DIR"};
    std::error_code ec;
    const std::filesystem::path exe = ExecutableDir();
    if (!exe.empty()) {
      const std::filesystem::path installed = (exe.parent_path() / "share" / "blurcue").lexically_normal();
      if (std::filesystem::is_directory(installed / "shaders", ec)) return DataDirectory{installed, "installed"};
    }
    return DataDirectory{std::filesystem::path(BLURCUE_SOURCE_DIR), "source tree"};
  }();
  return dir;
}

}  // namespace blurcue
