#pragma once
// Outputs that a crash, a kill or a full disk never leaves half written: every file and folder the project writes
// is built beside its target under a name that says what it is and which process made it, then renamed into place
// once. A reader sees the old output or the whole new one. What a killed process leaves behind is recognisable:
//   .NAME.tmp-PID      a file being written        (WriteFileAtomically)
//   .NAME.partial-PID  a file or folder being built (WriteFolderAtomically, MoveIntoPlace; SQLite adds -wal, -shm)
//   .NAME.old-PID      a replaced folder not yet removed
// and RemoveStaleLeftovers removes those whose process is gone.
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace blurcue {

// The temporary beside `target` for this process: DIR/.NAME.KIND-PID (KIND: "tmp", "partial" or "old").
std::filesystem::path TemporaryBeside(const std::filesystem::path& target, std::string_view kind);

// Writes `bytes` to `path` through DIR/.NAME.tmp-PID: written, fsynced, renamed over `path`, the folder fsynced (the
// rename survives a power loss). Creates the folder. On any failure the temporary is removed, `path` is untouched,
// and Error(kInput) names `path`; so it is when `path` exists and is not a regular file (a folder, a device such as
// /dev/full, a FIFO): the rename would replace it.
void WriteFileAtomically(const std::filesystem::path& path, std::string_view bytes);
// Throws Error(kInput) naming `path` when it exists and is not a regular file (or a link to one): a folder, a device,
// a FIFO or a socket is not an output to replace. WriteFileAtomically's own check, for a writer that opens `path`
// itself (a video), before its work.
void RequireReplaceableFile(const std::filesystem::path& path);

// Builds the folder `dir` as a whole: `fill` writes into an empty DIR/../.NAME.partial-PID, every file in it is
// fsynced, and it is swapped with `dir` in one rename (the old folder, if any, is removed after). A reader of `dir`
// sees all old files or all new ones, never a mix. Before anything is written, an existing `dir` must hold only
// entries for which `ours(name)` is true: a folder of other files is refused (Error(kInput) naming the first
// stranger) rather than replaced. When `fill` throws, the partial folder is removed and the exception passes on.
// Other failures throw Error(kInput) naming `dir`.
// WriteFolderAtomically's check before it writes, alone: throws its Error(kInput) when `dir` exists and is not a
// folder or holds an entry `ours` does not claim. For a command to refuse such a folder before long work.
void RequireReplaceableFolder(const std::filesystem::path& dir, const std::function<bool(const std::string& name)>& ours);
// A folder a command replaces whole and always writes `marker` into (truth.json, take.json, live.csv): a non-empty
// `dir` without it is someone else's (files named like the command's own, say) and is refused, Error(kInput)
// "OPTION DIR: holds no MARKER: not WHAT (GUESS), and the folder is replaced as a whole, ...".
void RequireMarkedFolder(const std::string& option, const std::filesystem::path& dir, const std::string& marker,
                         const std::string& what, const std::string& guess);
// `before_swap` (optional) runs once the new folder is whole on disk, just before the rename that swaps it in: for
// a command whose outputs are this folder and files elsewhere, to move those in at the same moment (its throwing
// discards the folder like `fill`'s).
void WriteFolderAtomically(const std::filesystem::path& dir,
                           const std::function<void(const std::filesystem::path& partial)>& fill,
                           const std::function<bool(const std::string& name)>& ours,
                           const std::function<void()>& before_swap = {});

// Renames the finished file `temp` to `target` unless `target` exists (then Error(kInput) "exists; not
// overwritten"), in one step that cannot replace a file created meanwhile, and fsyncs the folder. Throws
// Error(kInput) naming `target` on failure; `temp` is left for the caller to remove.
void MoveIntoPlace(const std::filesystem::path& temp, const std::filesystem::path& target);

// Removes what killed runs left beside `target`: DIR/.NAME.{tmp,partial,old}-PID (files or folders, and SQLite's
// -wal, -shm, -journal of them) and the older names NAME.partialPID and NAME.tmpPID (+ the same suffixes), for
// every PID that is no live process on this machine. Returns what it removed. Never throws: a leftover it cannot
// remove is left (and not returned).
std::vector<std::filesystem::path> RemoveStaleLeftovers(const std::filesystem::path& target);

}  // namespace blurcue
