#include "core/atomic_file.h"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>  // renameat2, RENAME_EXCHANGE, RENAME_NOREPLACE (glibc >= 2.28)
#include <cstring>

#include "core/error.h"

namespace blurcue {
namespace fs = std::filesystem;
namespace {

// "a/b/" and "a/b/." name the folder b: rename and the temporaries beside it need its own name.
fs::path Normal(const fs::path& path) {
  fs::path p = path.lexically_normal();
  while (!p.has_filename() && p.has_parent_path() && p != p.root_path()) p = p.parent_path();
  if (p.filename() == "." || p.filename() == ".." || p.empty()) p = fs::absolute(p).lexically_normal();
  while (!p.has_filename() && p.has_parent_path() && p != p.root_path()) p = p.parent_path();
  return p;
}

// A folder reached through a symlink is replaced where it really is: the link stays and shows the new folder.
fs::path FolderTarget(const fs::path& path) {
  const fs::path normal = Normal(path);
  std::error_code error;
  if (!fs::is_symlink(fs::symlink_status(normal, error)) || !fs::is_directory(normal, error)) return normal;
  const fs::path real = fs::canonical(normal, error);
  return error ? normal : real;
}

std::string Errno() { return std::strerror(errno); }

// The folder a relative name lives in: "" means the current one.
fs::path FolderOf(const fs::path& path) { return path.has_parent_path() ? path.parent_path() : fs::path("."); }

void CreateFolderOf(const fs::path& path, const std::string& where) {
  if (!path.has_parent_path()) return;
  std::error_code error;
  fs::create_directories(path.parent_path(), error);
  if (error) throw InputError(where, "cannot create its folder: " + error.message());
}

// fsync of a file or folder by name; false (errno set) on failure.
bool SyncPath(const fs::path& path, bool folder) {
  const int fd = open(path.c_str(), (folder ? O_RDONLY | O_DIRECTORY : O_RDONLY) | O_CLOEXEC);
  if (fd < 0) return false;
  const bool ok = fsync(fd) == 0;
  const int saved = errno;
  close(fd);
  errno = saved;
  return ok;
}

// After a rename the new name is only durable once its folder is synced. A failure here is not reported: the
// output is complete and in place, only its survival of a power cut in the next seconds is in doubt.
void SyncFolderOf(const fs::path& path) { SyncPath(FolderOf(path), true); }

// Every file and folder under `root`, and `root` itself, on disk: whatever wrote them (this process, a Python
// child) need not have synced. Returns the first path that failed, empty when all did.
fs::path SyncTree(const fs::path& root) {
  std::error_code error;
  for (fs::recursive_directory_iterator it(root, error), end; !error && it != end; it.increment(error)) {
    const fs::file_status status = it->symlink_status(error);
    if (error) return it->path();
    if ((fs::is_regular_file(status) || fs::is_directory(status)) && !SyncPath(it->path(), fs::is_directory(status)))
      return it->path();
  }
  if (error) return root;
  return SyncPath(root, true) ? fs::path() : root;
}

bool ProcessAlive(long pid) {
  // EPERM: it exists but belongs to someone else - alive all the same.
  return pid > 0 && (kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM);
}

// The PID in `rest` ("123" or "123-wal" ...) when that is all there is; -1 when `rest` is something else.
long LeftoverPid(std::string_view rest) {
  size_t digits = 0;
  while (digits < rest.size() && rest[digits] >= '0' && rest[digits] <= '9') ++digits;
  if (digits == 0 || digits > 9) return -1;
  const std::string_view suffix = rest.substr(digits);
  if (!suffix.empty() && suffix != "-wal" && suffix != "-shm" && suffix != "-journal") return -1;
  return std::stol(std::string(rest.substr(0, digits)));
}

}  // namespace

fs::path TemporaryBeside(const fs::path& target, std::string_view kind) {
  const fs::path normal = Normal(target);
  // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) about "." + std::string.
  std::string name(1, '.');
  name.append(normal.filename().string()).append(1, '.').append(kind).append(1, '-').append(std::to_string(getpid()));
  return normal.parent_path() / name;
}

void RequireReplaceableFile(const fs::path& path) {
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (fs::is_directory(status)) throw InputError(path.string(), "is a folder, not a file; not replaced");
  if (fs::exists(status) && !fs::is_regular_file(status))
    throw InputError(path.string(), "is not a regular file (a device, FIFO or socket); not replaced");
}

void WriteFileAtomically(const fs::path& path, std::string_view bytes) {
  // The rename below replaces whatever has the name: a device (/dev/full, /dev/null as root), a FIFO or a socket
  // would be swapped for a plain file.
  RequireReplaceableFile(path);
  CreateFolderOf(path, path.string());
  const fs::path temp = TemporaryBeside(path, "tmp");
  const int fd = open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);  // less the umask
  if (fd < 0) throw InputError(path.string(), "cannot write: " + Errno());
  const auto fail = [&](const std::string& what) {
    const std::string reason = what + Errno();
    if (fd >= 0) close(fd);
    unlink(temp.c_str());
    return InputError(path.string(), reason);
  };
  for (size_t done = 0; done < bytes.size();) {
    const ssize_t n = write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw fail("write failed: ");
    done += static_cast<size_t>(n);
  }
  // The data must be on disk before the rename makes it the file: otherwise a power cut can leave the new name
  // pointing at an empty file.
  if (fsync(fd) != 0) throw fail("write failed: ");
  if (close(fd) != 0) {
    const std::string reason = Errno();
    unlink(temp.c_str());
    throw InputError(path.string(), "write failed: " + reason);
  }
  if (rename(temp.c_str(), path.c_str()) != 0) {
    const std::string reason = Errno();
    unlink(temp.c_str());
    throw InputError(path.string(), "cannot replace: " + reason);
  }
  SyncFolderOf(path);
}

void RequireReplaceableFolder(const fs::path& dir, const std::function<bool(const std::string& name)>& ours) {
  const fs::path target = FolderTarget(dir);
  const std::string where = dir.string();
  std::error_code error;
  const fs::file_status status = fs::symlink_status(target, error);
  if (!fs::exists(status)) return;
  if (!fs::is_directory(status)) throw InputError(where, "exists and is not a folder; not replaced");
  for (fs::directory_iterator it(target, error), end; !error && it != end; it.increment(error)) {
    const std::string name = it->path().filename().string();
    if (!ours(name))
      throw InputError(where, "holds " + name +
                                  ", which this command did not write; the folder is replaced as a whole, so give "
                                  "a new or empty one (nothing was written)");
  }
  if (error) throw InputError(where, "cannot list the folder: " + error.message());
}

void RequireMarkedFolder(const std::string& option, const fs::path& dir, const std::string& marker,
                         const std::string& what, const std::string& guess) {
  std::error_code ec;
  if (fs::is_directory(dir, ec) && !fs::is_empty(dir, ec) && !fs::exists(dir / marker, ec))
    throw InputError(option + " " + dir.string(), "holds no " + marker + ": not " + what + " (" + guess +
                                                      "), and the folder is replaced as a whole, so give a new or "
                                                      "empty one (nothing was written)");
}

void WriteFolderAtomically(const fs::path& dir, const std::function<void(const fs::path& partial)>& fill,
                           const std::function<bool(const std::string& name)>& ours,
                           const std::function<void()>& before_swap) {
  const fs::path target = FolderTarget(dir);
  const std::string where = dir.string();
  CreateFolderOf(target, where);
  RequireReplaceableFolder(dir, ours);
  std::error_code error;
  const bool replacing = fs::exists(fs::symlink_status(target, error));

  const fs::path partial = TemporaryBeside(target, "partial");
  fs::remove_all(partial, error);  // a leftover of a dead process that had our PID
  if (!fs::create_directory(partial, error) || error)
    throw InputError(where, "cannot create " + partial.string() + ": " + error.message());
  const auto discard = [&] {
    std::error_code ignored;
    fs::remove_all(partial, ignored);
  };
  try {
    fill(partial);
  } catch (...) {
    discard();
    throw;
  }
  if (const fs::path failed = SyncTree(partial); !failed.empty()) {
    const std::string reason = Errno();
    discard();
    throw InputError(where, "cannot write " + failed.string() + " to disk: " + reason);
  }
  try {
    if (before_swap) before_swap();
  } catch (...) {
    discard();
    throw;
  }

  if (!replacing) {
    if (rename(partial.c_str(), target.c_str()) != 0) {
      const std::string reason = Errno();
      discard();
      throw InputError(where, "cannot move the new folder into place: " + reason);
    }
  } else if (renameat2(AT_FDCWD, partial.c_str(), AT_FDCWD, target.c_str(), RENAME_EXCHANGE) == 0) {
    // One step: `dir` is the new folder, and the old one is now at `partial`, about to go. A kill here leaves the
    // old folder as a .NAME.partial-PID leftover, never a mix.
    discard();
  } else if (errno == EINVAL || errno == ENOSYS) {
    // A file system without RENAME_EXCHANGE: the old folder aside, the new one in. Between the two renames `dir` is
    // briefly missing; a reader still never sees old and new files together.
    const fs::path old = TemporaryBeside(target, "old");
    fs::remove_all(old, error);
    if (rename(target.c_str(), old.c_str()) != 0) {
      const std::string reason = Errno();
      discard();
      throw InputError(where, "cannot move the old folder aside: " + reason);
    }
    if (rename(partial.c_str(), target.c_str()) != 0) {
      const std::string reason = Errno();
      rename(old.c_str(), target.c_str());
      discard();
      throw InputError(where, "cannot move the new folder into place: " + reason);
    }
    fs::remove_all(old, error);
  } else {
    const std::string reason = Errno();
    discard();
    throw InputError(where, "cannot replace the folder: " + reason);
  }
  SyncFolderOf(target);
}

void MoveIntoPlace(const fs::path& temp, const fs::path& target) {
  if (!SyncPath(temp, false)) throw InputError(target.string(), "cannot write " + temp.string() + ": " + Errno());
  int result = renameat2(AT_FDCWD, temp.c_str(), AT_FDCWD, target.c_str(), RENAME_NOREPLACE);
  if (result != 0 && (errno == EINVAL || errno == ENOSYS)) {
    // No RENAME_NOREPLACE here: link() refuses an existing name just as well.
    result = link(temp.c_str(), target.c_str());
    if (result == 0) unlink(temp.c_str());
  }
  if (result != 0 && errno == EEXIST) throw InputError(target.string(), "exists; not overwritten");
  if (result != 0) throw InputError(target.string(), "cannot move into place: " + Errno());
  SyncFolderOf(target);
}

std::vector<fs::path> RemoveStaleLeftovers(const fs::path& target) {
  const fs::path normal = FolderTarget(target);
  const std::string name = normal.filename().string();
  const std::string dotted = "." + name + ".";
  std::vector<fs::path> stale, removed;
  std::error_code error;
  for (fs::directory_iterator it(FolderOf(normal), error), end; !error && it != end; it.increment(error)) {
    const std::string entry = it->path().filename().string();
    long pid = -1;
    if (entry.rfind(dotted, 0) == 0) {
      const std::string_view rest = std::string_view(entry).substr(dotted.size());
      for (std::string_view kind : {"tmp-", "partial-", "old-"})
        if (rest.substr(0, kind.size()) == kind) pid = LeftoverPid(rest.substr(kind.size()));
    } else if (entry.rfind(name + ".", 0) == 0) {
      // The names of earlier versions: merge's OUT.partialPID, export's FILE.tmpPID.
      const std::string_view rest = std::string_view(entry).substr(name.size() + 1);
      for (std::string_view kind : {"partial", "tmp"})
        if (rest.substr(0, kind.size()) == kind) pid = LeftoverPid(rest.substr(kind.size()));
    }
    if (pid >= 0 && pid != getpid() && !ProcessAlive(pid)) stale.push_back(it->path());
  }
  // Removed after the listing: a folder changing under its own iterator may skip or repeat entries.
  for (const fs::path& path : stale) {
    std::error_code failed;
    fs::remove_all(path, failed);
    if (!failed) removed.push_back(path);
  }
  return removed;
}

}  // namespace blurcue
