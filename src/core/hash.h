#pragma once
// FNV-1a 64: the one hash of texts the project records (protocol versions, trial lists, default seeds). Stable on
// every platform and standard library, which std::hash is not.
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

namespace blurcue {

inline uint64_t Fnv1a64(std::string_view text) {
  uint64_t h = 14695981039346656037ull;
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

// 16 lower-case hex digits.
inline std::string HashHex(uint64_t hash) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash));
  return text;
}

}  // namespace blurcue
