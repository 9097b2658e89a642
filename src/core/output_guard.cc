#include "core/output_guard.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/typed.h"

namespace blurcue {
namespace fs = std::filesystem;
namespace {

std::string Named(const std::string& option, const fs::path& path) {
  return (option.empty() ? "" : option + " ") + OneLine(path.string());
}

// What an existing path is that a reader or a writer cannot take as a file; empty for a file, folder or nothing.
std::string SpecialKind(const fs::file_status& status) {
  if (fs::is_fifo(status)) return "a FIFO";
  if (fs::is_character_file(status)) return "a character device";
  if (fs::is_block_file(status)) return "a block device";
  if (fs::is_socket(status)) return "a socket";
  return "";
}

// `path` made absolute and normal, through the symlinks of its existing part: two spellings of one place compare
// equal, and "inside" is a prefix of its elements.
fs::path Resolved(const fs::path& path) {
  std::error_code error;
  fs::path p = fs::weakly_canonical(fs::absolute(path, error), error);
  if (error) p = fs::absolute(path).lexically_normal();
  return p;
}

// True when `inner` is `outer` or lies under it (both Resolved).
bool Within(const fs::path& inner, const fs::path& outer) {
  auto i = inner.begin(), o = outer.begin();
  for (; o != outer.end(); ++o, ++i) {
    if (o->empty() && std::next(o) == outer.end()) break;  // a trailing separator
    if (i == inner.end() || *i != *o) return false;
  }
  return true;
}

bool Same(const fs::path& a, const fs::path& b) {
  std::error_code error;
  if (fs::exists(a, error) && fs::exists(b, error)) return fs::equivalent(a, b, error) && !error;
  return Resolved(a) == Resolved(b);
}

// The kind on disk of an output, or the folder it would be made in, that it cannot be written as: one sentence, or
// empty.
std::string KindProblem(const fs::path& path, bool folder, bool record) {
  std::error_code error;
  const fs::file_status link = fs::symlink_status(path, error);
  if (fs::is_symlink(link) && !fs::exists(fs::status(path, error)))
    return "is a symlink to nothing (" + OneLine(fs::read_symlink(path, error).string()) + "); not followed";
  const fs::file_status status = fs::status(path, error);
  if (const std::string special = SpecialKind(status); !special.empty()) return "is " + special + ", not a " +
                                                                                (folder ? "folder" : "file");
  if (!folder && fs::is_directory(status)) return "is a folder, not a file; not replaced";
  if (folder && fs::exists(status) && !fs::is_directory(status)) return "is a file, not a folder; not replaced";
  if (!folder && !record && fs::is_regular_file(status) && IsSqliteFile(path))
    return "is an SQLite record (a study's answers); this command writes no records, so it is not replaced";
  // The nearest existing folder above it: a file there means no folder can be made; one that refuses a new file
  // (permissions, a read-only or virtual file system) is found now rather than after the work.
  fs::path above = fs::absolute(path, error).lexically_normal();
  if (!above.has_filename()) above = above.parent_path();
  above = above.parent_path();
  while (!fs::exists(fs::symlink_status(above, error)) && above.has_parent_path() && above != above.root_path())
    above = above.parent_path();
  if (fs::exists(above, error) && !fs::is_directory(above, error))
    return "lies under " + OneLine(above.string()) + ", which is a file, not a folder";
  const fs::path probe = above / (".blurcue-probe-" + std::to_string(getpid()));
  const int fd = open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) {
    if (errno == EEXIST) return "";
    return "cannot be written: " + OneLine(above.string()) + " takes no new file (" + std::strerror(errno) + ")";
  }
  close(fd);
  unlink(probe.c_str());
  return "";
}

}  // namespace

bool IsSqliteFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  char head[16] = {};
  return in.read(head, sizeof head) && std::memcmp(head, "SQLite format 3", 16) == 0;
}

void RemoveLeftoversBeside(const std::string& command, const fs::path& target) {
  for (const fs::path& path : RemoveStaleLeftovers(target))
    std::fprintf(stderr, "%s: removed %s, left by an interrupted run\n", command.c_str(), OneLine(path.string()).c_str());
}

OutputGuard& OutputGuard::Input(const std::string& option, const fs::path& path) {
  std::error_code error;
  if (const std::string special = SpecialKind(fs::status(path, error)); !special.empty())
    throw Error(ErrorKind::kInput, Named(option, path) + ": is " + special + ", not a file; not read (it could wait "
                                   "forever)");
  inputs_.push_back({option, path, fs::is_directory(path, error), false});
  return *this;
}

OutputGuard& OutputGuard::OutputFile(const std::string& option, const fs::path& path, bool record) {
  outputs_.push_back({option, path, false, record});
  return *this;
}

OutputGuard& OutputGuard::OutputFolder(const std::string& option, const fs::path& path) {
  outputs_.push_back({option, path, true, false});
  return *this;
}

void OutputGuard::Check() const {
  std::error_code error;
  for (size_t k = 0; k < outputs_.size(); ++k) {
    const Entry& out = outputs_[k];
    const std::string name = Named(out.option, out.path);
    const fs::path where = Resolved(out.path);
    for (const Entry& in : inputs_) {
      const std::string input = Named(in.option, in.path);
      if (Same(out.path, in.path))
        throw Error(ErrorKind::kUsage, name + ": is also the input " + input + "; an output may not replace an input");
      if (in.folder && Within(where, Resolved(in.path)))
        throw Error(ErrorKind::kUsage, name + ": lies inside the input folder " + input + "; write it elsewhere");
      if (out.folder && Within(Resolved(in.path), where))
        throw Error(ErrorKind::kUsage, name + ": holds the input " + input + ", which writing it would replace; " +
                                           "write it elsewhere");
    }
    for (size_t j = 0; j < k; ++j) {
      const Entry& other = outputs_[j];
      if (Same(out.path, other.path))
        throw Error(ErrorKind::kUsage, name + ": is also " + Named(other.option, other.path) +
                                           "; two outputs of one run may not be one path");
      const fs::path there = Resolved(other.path);
      if ((other.folder && Within(where, there)) || (out.folder && Within(there, where)))
        throw Error(ErrorKind::kUsage, name + " and " + Named(other.option, other.path) +
                                           ": one lies inside the other, a folder written as a whole; write them "
                                           "apart");
    }
    if (const std::string problem = KindProblem(out.path, out.folder, out.record); !problem.empty())
      throw Error(ErrorKind::kInput, name + ": " + problem);
  }
}

}  // namespace blurcue
