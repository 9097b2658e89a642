#pragma once
// Reading and writing JSON files with errors that name the file and the JSON pointer of the bad value.
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

namespace blurcue {

using Json = nlohmann::json;

// Parses a JSON file; throws Error(kInput) naming the file on a missing file or a syntax error.
Json ReadJsonFile(const std::filesystem::path& path);

// Writes atomically (core/atomic_file.h) so a crash never leaves half a file; 2-space indent.
void WriteJsonFile(const std::filesystem::path& path, const Json& json);

// Required number at `key` of `obj`; `where` is "file: /pointer". Throws naming the field on absence or type.
double RequireNumber(const Json& obj, const std::string& key, const std::string& where);
int RequireInt(const Json& obj, const std::string& key, const std::string& where);

}  // namespace blurcue
