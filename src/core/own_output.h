#pragma once
// An output replaces only what its own command wrote (the charter: "no output ever overwrites an input or a
// record"). OutputGuard (output_guard.h) refuses inputs, records and paths of the wrong kind; these refuse the rest
// of what an experimenter owns at an output's path: a protocol where a log goes, one's own face.png in a folder a
// command writes its textures into.
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace blurcue {

// Tells from a file's first bytes (at most kOwnHeadBytes: a calib.json whole) whether the command wrote it.
using OwnFileTest = std::function<bool(std::string_view head)>;
inline constexpr size_t kOwnHeadBytes = size_t(1) << 20;

// An existing file at an output's path is replaced only when `ours` recognises its head; otherwise
// Error(kInput) "OPTION PATH: exists and is not WHAT (it begins "..."); not replaced: give a new name, or remove
// it yourself". A path that does not exist, or is no regular file (OutputGuard's to refuse), passes.
void RequireOwnFile(const std::string& option, const std::filesystem::path& path, const std::string& what,
                    const OwnFileTest& ours);

// Tests for RequireOwnFile: a file whose bytes begin with `prefix` (a CSV's exact header line with its "\n").
OwnFileTest BeginsWith(std::string prefix);
// A file whose first bytes hold `text` (calib.json's "format": "blurcue-calib").
OwnFileTest Holds(std::string text);
// A file of the image format that `path`'s extension names (.png, .jpg/.jpeg, .tif/.tiff, .bmp, .webp, .ppm...),
// told by its signature; for an extension it does not know, none.
OwnFileTest ImageOfExtension(const std::filesystem::path& path);
// An AVI (RIFF....AVI ).
OwnFileTest AviFile();

// Moves the files a command finished in `partial` (a folder of its own beside `dir`) into `dir`, a folder it shares
// with files of others (make-stimuli's textures beside one's own pictures). A file of the same name in `dir` is
// replaced only when the command wrote it: it holds the same bytes, or dir/MANIFEST (written by every run, one
// "HASH NAME" line per file, FNV-1a 64 of its bytes) lists it unchanged since. Otherwise nothing is moved and
// Error(kInput) names the first such file: "OPTION DIR: holds NAME, which COMMAND did not write ...". `partial` is
// left for the caller to remove. Returns the paths written, in name order.
std::vector<std::filesystem::path> PlaceOwnFiles(const std::string& option, const std::filesystem::path& dir,
                                                 const std::filesystem::path& partial, const std::string& manifest,
                                                 const std::string& command);

// A file that a writer opens by its own name (a video: the extension tells it the container), built where a kill
// cannot leave half of it under the final name: DIR/.NAME.partial-PID/NAME (atomic_file.h's names, so a killed run's
// is removed by a later RemoveStaleLeftovers(target)). The caller writes path() and closes its writer; Finish() then
// fsyncs the file and renames it over `target` (which the caller checked before its work: RequireReplaceableFile,
// RequireOwnFile). The partial folder goes when the object does, finished or not.
class PartialFile {
 public:
  // Makes the partial folder (and target's folder); Error(kInput) naming `target` when it cannot.
  explicit PartialFile(std::filesystem::path target);
  ~PartialFile();
  PartialFile(const PartialFile&) = delete;
  PartialFile& operator=(const PartialFile&) = delete;
  const std::filesystem::path& path() const { return path_; }
  // Moves the finished file into place; Error(kInput) naming the target when it cannot (the target then unchanged).
  void Finish();

 private:
  std::filesystem::path target_, folder_, path_;
};

}  // namespace blurcue
