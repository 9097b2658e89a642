#include "procedure/answer.h"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <utility>

#include "protocol/protocol.h"
#include "store/record.h"

namespace blurcue::procedure {
namespace {

using Kind = Choice::Kind;

// The words of the choices that are one word each. A side's word is protocol::Side's (the word of its /responses
// field too); the record's two non-answers are store's, which counts them in SQL (store/list_sessions.cc).
struct Word {
  Kind kind;
  const char* word;
};
const Word kWords[] = {
    {Kind::kCantTell, "cant_tell"},
    {Kind::kYes, "yes"},
    {Kind::kNo, "no"},
    {Kind::kNone, store::kChoiceNone},
    {Kind::kSkipped, store::kChoiceSkipped},
};

const char* WordOf(Kind kind) {
  for (const Word& w : kWords)
    if (w.kind == kind) return w.word;
  return nullptr;
}

// 1..n as std::to_string writes it (no sign, no leading zero): the only form a record holds.
std::optional<int> Point(std::string_view text) {
  if (text.empty() || text.size() > 9 || text[0] == '0') return std::nullopt;
  int n = 0;
  for (const char c : text) {
    if (!std::isdigit(static_cast<unsigned char>(c))) return std::nullopt;
    n = n * 10 + (c - '0');
  }
  return n;
}

// A level as protocol::LevelText writes it, and only so: the record's text names one level of the trial.
std::optional<double> LevelOf(std::string_view text) {
  const std::string s(text);
  if (s.empty() || std::isspace(static_cast<unsigned char>(s[0]))) return std::nullopt;
  char* end = nullptr;
  const double level = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size() || !std::isfinite(level) || protocol::LevelText(level) != s) return std::nullopt;
  return level;
}

}  // namespace

bool operator==(const Choice& a, const Choice& b) {
  if (a.kind != b.kind) return false;
  switch (a.kind) {
    case Kind::kSide: return a.side == b.side;
    case Kind::kInterval:
    case Kind::kRating: return a.point == b.point;
    case Kind::kLevel: return a.level == b.level;
    case Kind::kNone:
    case Kind::kSkipped:
    case Kind::kCantTell:
    case Kind::kYes:
    case Kind::kNo: return true;
  }
  return true;
}

std::string Name(const Choice& choice) {
  switch (choice.kind) {
    case Kind::kSide: return protocol::ToString(choice.side);
    case Kind::kInterval:
    case Kind::kRating: return std::to_string(choice.point);
    case Kind::kLevel: return protocol::LevelText(choice.level);
    case Kind::kNone:
    case Kind::kSkipped:
    case Kind::kCantTell:
    case Kind::kYes:
    case Kind::kNo: return WordOf(choice.kind);
  }
  return "";
}

std::optional<Choice> ParseChoice(std::string_view text, protocol::TaskAnswer answer, bool intervals) {
  using protocol::TaskAnswer;
  for (const Word& w : kWords) {
    if (text != w.word) continue;
    const bool read = w.kind == Kind::kNone || w.kind == Kind::kSkipped ||
                      (w.kind == Kind::kCantTell && answer == TaskAnswer::kSide) ||
                      ((w.kind == Kind::kYes || w.kind == Kind::kNo) && answer == TaskAnswer::kYesNo);
    return read ? std::optional<Choice>(Choice::Of(w.kind)) : std::nullopt;
  }
  switch (answer) {
    case TaskAnswer::kSide:
      if (intervals) {
        if (const auto n = Point(text)) return Choice::Numbered(Kind::kInterval, *n);
        return std::nullopt;
      }
      if (const auto side = protocol::ParseWord<protocol::Side>(text)) return Choice::Of(*side);
      return std::nullopt;
    case TaskAnswer::kRatingPoint:
      if (const auto n = Point(text)) return Choice::Numbered(Kind::kRating, *n);
      return std::nullopt;
    case TaskAnswer::kLevel:
      if (const auto level = LevelOf(text)) return Choice::Level(*level);
      return std::nullopt;
    case TaskAnswer::kYesNo: return std::nullopt;
  }
  return std::nullopt;
}

bool operator==(const Action& a, const Action& b) {
  return a.kind == b.kind && (a.kind != Action::Kind::kAnswer || a.choice == b.choice);
}

std::string Name(const Action& action) {
  using protocol::ResponseKey;
  switch (action.kind) {
    case Action::Kind::kAnswer: return Name(action.choice);
    case Action::Kind::kPrevious: return protocol::ToString(ResponseKey::kPrevious);
    case Action::Kind::kNext: return protocol::ToString(ResponseKey::kNext);
    case Action::Kind::kAccept: return protocol::ToString(ResponseKey::kAccept);
    case Action::Kind::kPause: return "pause";
    case Action::Kind::kNothing: return "";
  }
  return "";
}

}  // namespace blurcue::procedure
