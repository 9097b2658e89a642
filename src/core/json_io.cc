#include "core/json_io.h"

#include <fstream>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"

namespace blurcue {

Json ReadJsonFile(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string(), "cannot open file");
  try {
    return Json::parse(in);
  } catch (const Json::parse_error& e) {
    throw InputError(path.string(), std::string("not valid JSON: ") + e.what());
  }
}

void WriteJsonFile(const std::filesystem::path& path, const Json& json) {
  WriteFileAtomically(path, json.dump(2) + "\n");
}

static const Json& RequireField(const Json& obj, const std::string& key, const std::string& where) {
  if (!obj.is_object()) throw InputError(where, "must be an object, got " + obj.dump());
  auto it = obj.find(key);
  if (it == obj.end()) throw InputError(where + "/" + key, "is required but missing");
  return *it;
}

double RequireNumber(const Json& obj, const std::string& key, const std::string& where) {
  const Json& v = RequireField(obj, key, where);
  if (!v.is_number()) throw InputError(where + "/" + key, "must be a number, got " + v.dump());
  return v.get<double>();
}

int RequireInt(const Json& obj, const std::string& key, const std::string& where) {
  const Json& v = RequireField(obj, key, where);
  if (!v.is_number_integer()) throw InputError(where + "/" + key, "must be an integer, got " + v.dump());
  return v.get<int>();
}

}  // namespace blurcue
