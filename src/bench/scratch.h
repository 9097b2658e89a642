#pragma once
// A bench's scratch folder: made new under the system's temporary folder (TMPDIR), never one that was there before.
// Internal to the bench module.
#include <stdlib.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>

#include "core/error.h"

namespace blurcue::bench::detail {

// A new, empty folder TMPDIR/PREFIXxxxxxx (mkdtemp). Error(kInput) naming TMPDIR when it is no folder one can make a
// folder in (std::filesystem's own error used to end the bench as an internal error, exit 10).
inline std::filesystem::path MakeScratchFolder(const std::string& prefix) {
  const char* env = std::getenv("TMPDIR");
  const std::string named = env && *env ? std::string("TMPDIR ") + env : std::string("/tmp");
  std::error_code ec;
  const std::filesystem::path tmp = std::filesystem::temp_directory_path(ec);
  if (ec) throw InputError(named, ec.message() + "; the bench writes its take there: set TMPDIR to a folder");
  std::string pattern = (tmp / (prefix + "XXXXXX")).string();
  if (!::mkdtemp(pattern.data()))
    throw InputError(named, std::string("cannot make a folder there: ") + std::strerror(errno) +
                                "; set TMPDIR to a folder it can write in");
  return pattern;
}

}  // namespace blurcue::bench::detail
