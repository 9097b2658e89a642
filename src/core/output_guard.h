#pragma once
// What a command may write, checked before it does any work: nothing an experimenter owns is destroyed (issue 39).
// A command names what it reads and what it writes; Check() refuses, in one line naming the option and the path,
//   - an output that is one of the inputs (the same file by device and inode), lies inside an input folder, or is a
//     folder holding an input                                                             Error(kUsage)
//   - two outputs that are the same path, or one inside an output folder                   Error(kUsage)
//   - an output that exists as another kind than it writes: a folder where a file goes, a file where a folder goes,
//     a FIFO, a device or a socket; a dangling symlink; a path under a file; a folder it cannot write in
//                                                                                          Error(kInput)
//   - an existing SQLite record where a command that writes no records writes a file      Error(kInput)
// Inputs that are FIFOs, devices or sockets are refused at once (reading one could block forever): Error(kInput).
// Writing stays with atomic_file.h (WriteFileAtomically, WriteFolderAtomically, MoveIntoPlace): this only decides
// whether a path may be written at all.
#include <filesystem>
#include <string>
#include <vector>

namespace blurcue {

class OutputGuard {
 public:
  // An input file or folder (a video, a photo, a --track folder). Throws Error(kInput) naming `option` and `path`
  // when it is a FIFO, a device or a socket. A path that does not exist is left to the reader to report.
  OutputGuard& Input(const std::string& option, const std::filesystem::path& path);
  // An output file; `record` for a command that writes SQLite records (then an existing record may be its output).
  OutputGuard& OutputFile(const std::string& option, const std::filesystem::path& path, bool record = false);
  // An output folder, replaced or filled as a whole by the command.
  OutputGuard& OutputFolder(const std::string& option, const std::filesystem::path& path);
  // Throws the first refusal (see above); does nothing on disk except test, in the nearest folder that exists, that
  // a file can be made there (made and removed at once).
  void Check() const;

 private:
  struct Entry {
    std::string option;
    std::filesystem::path path;
    bool folder = false, record = false;
  };
  std::vector<Entry> inputs_, outputs_;
};

// RemoveStaleLeftovers(target), each removal said on stderr as "COMMAND: removed PATH, left by an interrupted run".
void RemoveLeftoversBeside(const std::string& command, const std::filesystem::path& target);

// True when the file at `path` begins with SQLite's 16-byte header ("SQLite format 3\0").
bool IsSqliteFile(const std::filesystem::path& path);

}  // namespace blurcue
