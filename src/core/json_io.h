#pragma once
// Reading and writing JSON files with errors that name the file and the JSON pointer of the bad value.
#include <cstddef>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

namespace blurcue {

using Json = nlohmann::json;

// The most a JSON file read by ReadJsonFile may hold, and how deep its arrays and objects may nest.
inline constexpr size_t kMaxJsonBytes = size_t(16) << 20;  // 16 MiB
inline constexpr int kMaxJsonDepth = 64;

// Parses a JSON file. Throws one Error(kInput) naming the file (and the line and column where it applies) for a
// missing or unreadable file, anything but a regular file (a folder, /dev/zero, a FIFO), a file over 16 MiB,
// nesting deeper than 64, a syntax error, a number beyond double's range (1e400) or a key given twice in one
// object (named by its JSON pointer).
Json ReadJsonFile(const std::filesystem::path& path);
// The two halves of ReadJsonFile: the checked read of the text, and its parse (`name` names it in messages).
// `what` names the kind of file in the messages ("a folder, not a JSON file", "a track.csv may have at most 16 MiB").
std::string ReadTextFile(const std::filesystem::path& path, const std::string& what = "a JSON file");
Json ParseJson(const std::string& text, const std::string& name);

// Writes atomically (core/atomic_file.h) so a crash never leaves half a file; 2-space indent.
void WriteJsonFile(const std::filesystem::path& path, const Json& json);

// Required number at `key` of `obj`; `where` is "file: /pointer". Throws naming the field on absence or type.
double RequireNumber(const Json& obj, const std::string& key, const std::string& where);
int RequireInt(const Json& obj, const std::string& key, const std::string& where);

// A key as a JSON pointer token (RFC 6901: '~' -> "~0", '/' -> "~1"), control characters as \uXXXX so a message
// stays one readable line.
std::string JsonPointerToken(const std::string& key);

}  // namespace blurcue
