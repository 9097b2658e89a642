#include "core/typed.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace blurcue {
namespace {

// The length of the run of ASCII digits at `i`.
size_t Digits(std::string_view text, size_t i) {
  size_t n = 0;
  while (i + n < text.size() && std::isdigit(static_cast<unsigned char>(text[i + n]))) ++n;
  return n;
}

size_t Sign(std::string_view text, size_t i) { return i < text.size() && (text[i] == '+' || text[i] == '-'); }

}  // namespace

std::optional<double> ParseDecimal(std::string_view text) {
  // The grammar first: strtod alone would take hex, inf, nan and leading space.
  size_t i = Sign(text, 0);
  const size_t whole = Digits(text, i);
  i += whole;
  size_t fraction = 0;
  if (i < text.size() && text[i] == '.') fraction = Digits(text, ++i), i += fraction;
  if (whole + fraction == 0) return std::nullopt;
  if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    i += 1 + Sign(text, i + 1);
    const size_t exponent = Digits(text, i);
    if (exponent == 0) return std::nullopt;
    i += exponent;
  }
  if (i != text.size()) return std::nullopt;
  const std::string copy(text);  // strtod needs a terminated string
  const double v = std::strtod(copy.c_str(), nullptr);  // overflow gives inf
  if (!std::isfinite(v)) return std::nullopt;
  return v;
}

namespace {

// The length of the printable UTF-8 character at text[i] (1 to 4 bytes), or 0 when a control character or a broken,
// overlong or surrogate sequence starts there.
size_t PrintableCharAt(std::string_view text, size_t i) {
  const unsigned char c = text[i];
  if (c < 0x20 || c == 0x7f) return 0;
  if (c < 0x80) return 1;
  // Lead byte: how many continuation bytes follow, and the smallest code point that length may encode.
  const int more = c >= 0xf0 ? 3 : c >= 0xe0 ? 2 : c >= 0xc0 ? 1 : -1;
  if (more < 0 || c > 0xf4 || i + more >= text.size()) return 0;
  uint32_t cp = c & (0x3f >> more);
  for (int k = 1; k <= more; ++k) {
    const unsigned char b = text[i + k];
    if ((b & 0xc0) != 0x80) return 0;
    cp = cp << 6 | (b & 0x3f);
  }
  static constexpr uint32_t kMin[] = {0, 0x80, 0x800, 0x10000};
  if (cp < kMin[more] || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff)) return 0;
  if (cp <= 0x9f) return 0;  // the C1 controls, U+0080 to U+009F
  return size_t(more) + 1;
}

// The bidirectional control character whose UTF-8 begins at text[i], or 0: U+061C (D8 9C), U+200E/F (E2 80 8E/8F),
// U+202A-E (E2 80 AA-AE), U+2066-9 (E2 81 A6-A9).
unsigned BidiControlAt(std::string_view text, size_t i) {
  const auto b = [&](size_t k) { return i + k < text.size() ? static_cast<unsigned char>(text[i + k]) : 0u; };
  if (b(0) == 0xD8 && b(1) == 0x9C) return 0x061C;
  if (b(0) == 0xE2 && b(1) == 0x80 && (b(2) == 0x8E || b(2) == 0x8F || (b(2) >= 0xAA && b(2) <= 0xAE)))
    return 0x2000 + (b(2) - 0x80);
  if (b(0) == 0xE2 && b(1) == 0x81 && b(2) >= 0xA6 && b(2) <= 0xA9) return 0x2040 + (b(2) - 0x80);
  return 0;
}

}  // namespace

bool IsPrintableUtf8(std::string_view text) {
  for (size_t i = 0; i < text.size();) {
    const size_t n = PrintableCharAt(text, i);
    if (n == 0) return false;
    i += n;
  }
  return true;
}

size_t Utf8Length(std::string_view text) {
  size_t n = 0;
  for (char c : text) n += (static_cast<unsigned char>(c) & 0xC0) != 0x80;
  return n;
}

std::string UnsafeIdReason(std::string_view text) {
  if (!text.empty() && std::string_view("=+-@").find(text.front()) != std::string_view::npos)
    return std::string("begins with ") + text.front() + ", which a spreadsheet opening the exported tables runs as a "
           "formula";
  // What the readers of the exported tables take for no value or for an infinite number instead of a name: pandas
  // reads NA, NaN, nan, null, N/A, #N/A, <NA>, 1.#IND, inf and Infinity (in any case) so, R reads NA; another
  // spelling of one of them in other letter cases is refused too, so the rule does not depend on a reader's version.
  // An id Infinity stopped the report (exit 10); a participant NA was dropped as missing.
  std::string lower(text);
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  for (const char* missing : {"na", "nan", "n/a", "null", "none", "#n/a", "#na", "#n/a n/a", "<na>", "1.#ind",
                              "1.#qnan", "inf", "infinity"})
    if (lower == missing)
      return "is text the readers of the exported tables (pandas, R) take as a missing value or an infinite number, "
             "not as a name";
  for (size_t i = 0; i + 1 < text.size(); ++i) {
    if (const unsigned code = BidiControlAt(text, i)) {
      char hex[16];
      std::snprintf(hex, sizeof hex, "U+%04X", code);
      return std::string("holds the bidirectional control character ") + hex +
             ", which shows the text to a reader in another order than it is recorded";
    }
  }
  return "";
}

std::string ParticipantIdProblem(std::string_view id) {
  if (id.empty()) return "must not be empty";
  if (id.size() > kMaxParticipantIdBytes)
    return "must be at most " + std::to_string(kMaxParticipantIdBytes) + " bytes (it has " + std::to_string(id.size()) +
           ")";
  if (!IsPrintableUtf8(id)) return "must be printable UTF-8 text (no newline, tab, escape or broken bytes)";
  if (id.front() == ' ' || id.back() == ' ') return "must not begin or end with a space";
  return UnsafeIdReason(id);
}

std::string OneLine(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (size_t i = 0; i < text.size();) {
    if (const size_t n = PrintableCharAt(text, i)) {
      // A bidirectional control would reorder the rest of the line on a terminal: written as its code point.
      if (const unsigned code = BidiControlAt(text, i)) {
        char hex[16];
        std::snprintf(hex, sizeof hex, "\\u%04X", code);
        out += hex;
      } else {
        out.append(text.substr(i, n));
      }
      i += n;
      continue;
    }
    const unsigned char c = text[i++];
    if (c == '\n') out += "\\n";
    else if (c == '\r') out += "\\r";
    else if (c == '\t') out += "\\t";
    else {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      out += hex;
    }
  }
  return out;
}

std::string Echo(std::string_view text, bool quoted) {
  const std::string quote = quoted ? "'" : "";
  size_t chars = 0, cut = text.size();
  for (size_t i = 0; i < text.size(); ++chars) {
    if (chars == kMaxEchoChars) cut = i;
    i += std::max<size_t>(PrintableCharAt(text, i), 1);
  }
  if (chars <= kMaxEchoChars) return quote + OneLine(text) + quote;
  return quote + OneLine(text.substr(0, cut)) + "..." + quote + " (" + std::to_string(chars) + " characters)";
}

bool IsWholeDecimal(std::string_view text) {
  return ParseDecimal(text) && text.find_first_of(".eE") == std::string_view::npos;
}

}  // namespace blurcue
