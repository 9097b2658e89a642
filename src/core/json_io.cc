#include "core/json_io.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <set>
#include <vector>
#include <fstream>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"

namespace blurcue {
namespace {

// "line L, column C" of the 0-based byte offset `at` in `text`.
std::string Position(const std::string& text, size_t at) {
  size_t line = 1, column = 1;
  for (size_t i = 0; i < at && i < text.size(); ++i) {
    if (text[i] == '\n') ++line, column = 1;
    else ++column;
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(column);
}

// The offset of the first bracket nested deeper than kMaxJsonDepth (brackets inside strings do not count), or npos.
// Runs before the parser, so no recursive code (dump, comparison, even the destructor of older nlohmann versions)
// ever meets a deep value.
size_t TooDeepAt(const std::string& text) {
  int depth = 0;
  bool in_string = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') ++i;
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth) return i;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return std::string::npos;
}

// nlohmann's message without its "[json.exception.NAME.ID] " prefix.
std::string Plain(const char* what) {
  const std::string text = what;
  const size_t end = text.find("] ");
  return text.rfind("[json.exception.", 0) == 0 && end != std::string::npos ? text.substr(end + 2) : text;
}

struct Fd {
  int fd;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace

std::string ReadTextFile(const std::filesystem::path& path, const std::string& what) {
  const std::string name = path.string();
  // A text file is a regular file: a folder, a device (/dev/zero never ends), a FIFO (blocks until a writer
  // comes) or a socket is refused before it is opened.
  struct stat st;
  if (::stat(name.c_str(), &st) != 0) throw InputError(name, std::string("cannot open file: ") + std::strerror(errno));
  auto check_kind = [&](const struct stat& s) {
    if (S_ISDIR(s.st_mode)) throw InputError(name, "is a folder, not " + what);
    if (!S_ISREG(s.st_mode)) throw InputError(name, "is not a regular file (a device, FIFO or socket), not " + what);
    if (s.st_size > static_cast<off_t>(kMaxJsonBytes))
      throw InputError(name, "is " + std::to_string(s.st_size) + " bytes; " + what + " may have at most 16 MiB");
  };
  check_kind(st);
  const Fd in{::open(name.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC)};
  if (in.fd < 0) throw InputError(name, std::string("cannot open file: ") + std::strerror(errno));
  if (::fstat(in.fd, &st) != 0) throw InputError(name, std::string("cannot read file: ") + std::strerror(errno));
  check_kind(st);  // the file opened, not one swapped in since the first look
  // Files of /proc and /sys say they are empty and are not: read up to one byte past the cap whatever the size says.
  std::string text;
  char buffer[65536];
  for (;;) {
    const ssize_t n = ::read(in.fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw InputError(name, std::string("cannot read file: ") + std::strerror(errno));
    if (n == 0) break;
    text.append(buffer, static_cast<size_t>(n));
    if (text.size() > kMaxJsonBytes) throw InputError(name, "is larger than 16 MiB, the most " + what + " may have");
  }
  return text;
}

Json ParseJson(const std::string& text, const std::string& name) {
  // Text that cannot start a JSON value (a PNG, say) is the parser's to report at its first byte; only what starts
  // like JSON (after a byte-order mark, which the parser skips) is scanned for depth.
  const size_t start = text.find_first_not_of(" \t\r\n", text.rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0);
  const bool json_like =
      start != std::string::npos && std::string("{[\"-0123456789tfn").find(text[start]) != std::string::npos;
  if (const size_t at = json_like ? TooDeepAt(text) : std::string::npos; at != std::string::npos)
    throw InputError(name, "not valid JSON: nested deeper than " + std::to_string(kMaxJsonDepth) + " levels at " +
                               Position(text, at));
  // A key given twice in one object would silently lose one value (nlohmann keeps the last): refuse it, naming
  // where. The parser reports each object and array as it starts and ends, each key, and each plain value.
  struct Frame {
    bool object;
    std::set<std::string> keys;
    std::string key;   // object: the key being read
    size_t index = 0;  // array: the element being read
  };
  std::vector<Frame> stack;
  std::string duplicate;  // pointer of the first key given twice
  const Json::parser_callback_t check_keys = [&](int, Json::parse_event_t event, Json& parsed) {
    using Event = Json::parse_event_t;
    if (!duplicate.empty()) return false;
    switch (event) {
      case Event::object_start: stack.push_back({true, {}, {}, 0}); break;
      case Event::array_start: stack.push_back({false, {}, {}, 0}); break;
      case Event::key:
        if (!stack.empty() && stack.back().object) {
          stack.back().key = parsed.get<std::string>();
          if (!stack.back().keys.insert(stack.back().key).second) {
            for (const Frame& f : stack) duplicate += "/" + (f.object ? JsonPointerToken(f.key) : std::to_string(f.index));
          }
        }
        break;
      case Event::object_end:
      case Event::array_end:
        if (!stack.empty()) stack.pop_back();
        [[fallthrough]];
      case Event::value:
        if (!stack.empty() && !stack.back().object) ++stack.back().index;
        break;
    }
    return true;
  };
  try {
    Json json = Json::parse(text, check_keys);
    if (!duplicate.empty())
      throw InputError(name, duplicate + ": is given twice in the same object (which value is meant?)");
    return json;
  } catch (const Json::parse_error& e) {
    throw InputError(name, "not valid JSON: " + Plain(e.what()));
  } catch (const Json::out_of_range& e) {
    // A number beyond double's range (1e400): nlohmann names the number but not where it is.
    std::string where;
    const std::string message = Plain(e.what());
    const size_t open = message.find('\''), close = message.rfind('\'');
    if (open != std::string::npos && close > open + 1)
      if (const size_t at = text.find(message.substr(open + 1, close - open - 1)); at != std::string::npos)
        where = " at " + Position(text, at);
    throw InputError(name, "not valid JSON" + where + ": " + message);
  } catch (const Json::exception& e) {
    throw InputError(name, "not valid JSON: " + Plain(e.what()));
  }
}

Json ReadJsonFile(const std::filesystem::path& path) { return ParseJson(ReadTextFile(path), path.string()); }

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
  // get<int> would wrap a larger number silently (2^32 + 1148 -> 1148).
  if ((v.is_number_unsigned() && v.get<uint64_t>() > uint64_t(INT_MAX)) ||
      (!v.is_number_unsigned() && (v.get<int64_t>() > INT_MAX || v.get<int64_t>() < INT_MIN)))
    throw InputError(where + "/" + key, "is out of range for an integer, got " + v.dump());
  return v.get<int>();
}

std::string JsonPointerToken(const std::string& key) {
  std::string out;
  for (char c : key) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      char text[8];
      std::snprintf(text, sizeof text, "\\u%04x", static_cast<unsigned char>(c));
      out += text;
    } else out += c;
  }
  return out;
}


}  // namespace blurcue
