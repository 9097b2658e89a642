#include "core/own_output.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include <fcntl.h>
#include <unistd.h>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/hash.h"
#include "core/typed.h"

namespace blurcue {
namespace fs = std::filesystem;
namespace {

std::string ReadBytes(const fs::path& path, size_t limit = std::string::npos) {
  std::ifstream in(path, std::ios::binary);
  if (limit == std::string::npos) return std::string(std::istreambuf_iterator<char>(in), {});
  std::string bytes(limit, '\0');
  in.read(bytes.data(), std::streamsize(limit));
  bytes.resize(size_t(in.gcount()));
  return bytes;
}

// The first line of a file, printable, for a message: what the file looks like to its owner.
std::string Beginning(std::string_view head) {
  std::string line(head.substr(0, std::min(head.find('\n'), size_t(40))));
  for (char& c : line)
    if (!std::isprint(static_cast<unsigned char>(c))) c = '.';
  return "it begins \"" + line + (head.size() > line.size() && head[line.size()] != '\n' ? "...\"" : "\"");
}

std::string Lower(std::string text) {
  for (char& c : text) c = char(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

std::string ManifestHeader(const std::string& command) {
  return "# files blurcue " + command + " wrote into this folder, with the FNV-1a 64 hash of each: a later run "
         "replaces only these, unchanged\n";
}

// NAME -> hash as the folder's manifest lists them; refuses a manifest the command did not write.
std::map<std::string, std::string> ReadManifest(const std::string& where, const fs::path& path,
                                                const std::string& command) {
  std::map<std::string, std::string> listed;
  std::error_code error;
  if (!fs::exists(fs::symlink_status(path, error))) return listed;
  const std::string text = fs::is_regular_file(path, error) ? ReadBytes(path) : "";
  const std::string header = ManifestHeader(command);
  if (text.compare(0, header.size(), header) != 0)
    throw InputError(where, "holds " + path.filename().string() + ", which " + command +
                                " did not write (the name of its list of files); nothing was written: give "
                                "another folder");
  std::istringstream lines(text.substr(header.size()));
  std::string hash, name;
  while (lines >> hash && std::getline(lines >> std::ws, name)) listed[name] = hash;
  return listed;
}

}  // namespace

void RequireOwnFile(const std::string& option, const fs::path& path, const std::string& what,
                    const OwnFileTest& ours) {
  std::error_code error;
  if (!fs::is_regular_file(path, error)) return;
  const std::string head = ReadBytes(path, kOwnHeadBytes);
  if (ours(head)) return;
  throw InputError(option + " " + OneLine(path.string()), "exists and is not " + what + " (" + Beginning(head) +
                                                              "); not replaced: give a new name, or remove it "
                                                              "yourself");
}

OwnFileTest BeginsWith(std::string prefix) {
  return [prefix = std::move(prefix)](std::string_view head) { return head.substr(0, prefix.size()) == prefix; };
}

OwnFileTest Holds(std::string text) {
  return [text = std::move(text)](std::string_view head) { return head.find(text) != std::string_view::npos; };
}

OwnFileTest ImageOfExtension(const fs::path& path) {
  const std::string ext = Lower(path.extension().string());
  std::vector<std::string> magic;
  if (ext == ".png") magic = {"\x89PNG\r\n\x1a\n"};
  else if (ext == ".jpg" || ext == ".jpeg" || ext == ".jpe") magic = {"\xff\xd8\xff"};
  else if (ext == ".tif" || ext == ".tiff") magic = {std::string("II*\0", 4), std::string("MM\0*", 4)};
  else if (ext == ".bmp" || ext == ".dib") magic = {"BM"};
  else if (ext == ".webp") magic = {"RIFF"};
  else if (ext == ".ppm" || ext == ".pgm" || ext == ".pbm" || ext == ".pnm") magic = {"P"};
  else if (ext == ".exr") magic = {"\x76\x2f\x31\x01"};
  else if (ext == ".hdr" || ext == ".pic") magic = {"#?"};
  return [magic](std::string_view head) {
    for (const std::string& m : magic)
      if (head.substr(0, m.size()) == m) return true;
    return false;
  };
}

OwnFileTest AviFile() {
  return [](std::string_view head) { return head.size() >= 12 && head.substr(0, 4) == "RIFF" &&
                                            head.substr(8, 4) == "AVI "; };
}

std::vector<fs::path> PlaceOwnFiles(const std::string& option, const fs::path& dir, const fs::path& partial,
                                    const std::string& manifest, const std::string& command) {
  const std::string where = option + " " + OneLine(dir.string());
  std::error_code error;
  fs::create_directories(dir, error);
  if (error) throw InputError(where, "cannot create the folder: " + error.message());
  std::map<std::string, std::string> listed = ReadManifest(where, dir / manifest, command);
  std::vector<std::string> names;
  for (fs::directory_iterator it(partial, error), end; !error && it != end; it.increment(error))
    names.push_back(it->path().filename().string());
  if (error) throw InputError(where, "cannot list " + partial.string() + ": " + error.message());
  std::sort(names.begin(), names.end());
  // Every file checked before any is moved: a refusal leaves the folder as it was.
  std::map<std::string, std::string> hashes;
  for (const std::string& name : names) {
    const fs::path target = dir / name;
    hashes[name] = HashHex(Fnv1a64(ReadBytes(partial / name)));
    if (!fs::exists(fs::symlink_status(target, error))) continue;
    if (!fs::is_regular_file(fs::symlink_status(target, error)))
      throw InputError(where, "holds " + name + ", which is no file " + command + " wrote; nothing was written: "
                                                                                 "give another folder");
    const std::string now = HashHex(Fnv1a64(ReadBytes(target)));
    if (now == hashes[name]) continue;
    const auto entry = listed.find(name);
    if (entry != listed.end() && entry->second == now) continue;
    throw InputError(where, "holds " + name + ", which " + command + " did not write (" +
                                (entry == listed.end() ? "its " + manifest + " does not list it"
                                                       : "changed since " + command + " wrote it") +
                                ": one's own picture?); nothing was written: give another folder, or move " + name +
                                " away yourself");
  }
  std::vector<fs::path> written;
  for (const std::string& name : names) {
    if (std::rename((partial / name).c_str(), (dir / name).c_str()) != 0)
      throw InputError(OneLine((dir / name).string()), "cannot move into place: " + std::string(std::strerror(errno)));
    listed[name] = hashes[name];
    written.push_back(dir / name);
  }
  std::string text = ManifestHeader(command);
  for (const auto& [name, hash] : listed)
    if (fs::exists(dir / name, error)) text += hash + " " + name + "\n";
  WriteFileAtomically(dir / manifest, text);
  return written;
}

namespace {
// fsync of a file or folder by name; a failure is not reported: the file is whole, only its survival of a power cut
// is in doubt.
void SyncByName(const fs::path& path, bool folder) {
  const int fd = open(path.c_str(), (folder ? O_RDONLY | O_DIRECTORY : O_RDONLY) | O_CLOEXEC);
  if (fd < 0) return;
  fsync(fd);
  close(fd);
}
}  // namespace

PartialFile::PartialFile(fs::path target) : target_(std::move(target)) {
  folder_ = TemporaryBeside(target_, "partial");
  path_ = folder_ / target_.filename();
  std::error_code error;
  fs::create_directories(folder_, error);
  if (error)
    throw InputError(OneLine(target_.string()), "cannot make " + OneLine(folder_.string()) + " to write it in: " +
                                                     error.message());
}

PartialFile::~PartialFile() {
  std::error_code ignored;
  fs::remove_all(folder_, ignored);
}

void PartialFile::Finish() {
  SyncByName(path_, false);
  if (std::rename(path_.c_str(), target_.c_str()) != 0)
    throw InputError(OneLine(target_.string()), "cannot move the finished file into place: " +
                                                     std::string(std::strerror(errno)));
  SyncByName(target_.has_parent_path() ? target_.parent_path() : fs::path("."), true);
}

}  // namespace blurcue
