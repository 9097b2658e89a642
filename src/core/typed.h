#pragma once
// Values a person types: numbers on the command line, in an --observer spec, a --info value or a levels CSV cell,
// and names such as a participant id. One reading for all of them, so that "0x10" is not 16 in one place and an
// error in another.
#include <optional>
#include <string>
#include <string_view>

namespace blurcue {

// `text` as a decimal number, exactly as written: an optional sign, digits with an optional point, an optional
// exponent, and nothing else - no space before or after, no hex ("0x10", which strtod reads as 16), no "inf" or
// "nan", no value past a double's range ("1e999"). nullopt for anything else. A value too small for a double
// ("1e-999") reads as 0 or the nearest subnormal, as strtod gives it.
std::optional<double> ParseDecimal(std::string_view text);

// ParseDecimal that is also a whole number written without a point or exponent ("12", "-3"; not "12.0", "1e3").
bool IsWholeDecimal(std::string_view text);

// Valid UTF-8 (no overlong forms, surrogates or code points past U+10FFFF) without control characters (U+0000 to
// U+001F, U+007F to U+009F): text a record, a CSV cell, a terminal line and the report can all hold as it is.
bool IsPrintableUtf8(std::string_view text);

// The characters (UTF-8 code points) of valid UTF-8 text: what a limit "1-100 characters" counts.
size_t Utf8Length(std::string_view text);

// Why `text` cannot be an id or a name (a participant id, a study, group or block name, an id cell), or "" when it
// can: it begins with = + - or @, which a spreadsheet opening the exported tables runs as a formula
// (=HYPERLINK(...), =cmd|...), or it holds a bidirectional control character (U+061C, U+200E, U+200F, U+202A to
// U+202E, U+2066 to U+2069), which shows the text to a reader in another order than it is recorded.
std::string UnsafeIdReason(std::string_view text);

// The most bytes a participant id may have.
inline constexpr size_t kMaxParticipantIdBytes = 64;

// Why `id` cannot be a participant id, or "" when it can: the record, the exported tables and the report hold
// 1 to kMaxParticipantIdBytes bytes of printable UTF-8 (IsPrintableUtf8), no space at either end, that
// UnsafeIdReason takes. "must not be empty", "must be at most 64 bytes (it has 70)", ...
std::string ParticipantIdProblem(std::string_view id);

// `text` as one printable line: what IsPrintableUtf8 takes kept as it is, a newline, return or tab written \n, \r,
// \t, any other control or broken byte \xNN, a bidirectional control (UnsafeIdReason's list) \uNNNN. For messages
// that echo what someone typed.
std::string OneLine(std::string_view text);

// The most characters of a value a message quotes (Echo).
inline constexpr size_t kMaxEchoChars = 60;

// `text` as a message quotes what someone typed: OneLine of it, cut after kMaxEchoChars characters (a control or
// broken byte counts as one) with "..." and the whole length: 'abc...' (100000 characters). Between single quotes
// when `quoted`, bare otherwise (111... (100000 characters)). Every message that echoes a typed value uses it, so
// a 100,000-digit option is one short line.
std::string Echo(std::string_view text, bool quoted = true);

}  // namespace blurcue
