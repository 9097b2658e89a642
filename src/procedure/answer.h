#pragma once
// The participant's answer, typed: one Choice for every layout the code knows, with one Name (its word, as the record,
// the export and messages spell it) and one ParseChoice (a word read back). Keys, the simulated observer, scoring, the
// record and the plan pass Choices; the words live in answer.cc's table (a side's are protocol::Side's, the record's
// two non-answers are store's), so a new kind of answer is a value here and a row there.
#include <optional>
#include <string>
#include <string_view>

#include "protocol/vocabulary.h"

namespace blurcue::procedure {

// An answer to one trial, or what the record holds in its place.
struct Choice {
  enum class Kind {
    kNone,      // no answer before the deadline
    kSkipped,   // a trial not shown: a procedure ended by its stop rule, a practice run after the one that met its
                // criterion
    kSide,      // a side of a pair (forced choice side by side or in two intervals)
    kCantTell,  // the pair's third key, where the protocol has one
    kInterval,  // an odd one out's interval, 1..n
    kYes,       // yes_no: the object looks out of place
    kNo,
    kRating,    // a point of a rating scale, 1..n
    kLevel,     // an adjustment's accepted level
  };
  Kind kind = Kind::kNone;
  protocol::Side side = protocol::Side::kLeft;  // kSide
  int point = 0;                                // kInterval, kRating: 1-based
  double level = 0;                             // kLevel

  static Choice Of(Kind kind) { return Choice{kind}; }
  static Choice Of(protocol::Side side) { return Choice{Kind::kSide, side}; }
  static Choice Numbered(Kind kind, int point) { return Choice{kind, protocol::Side::kLeft, point}; }
  static Choice Level(double level) { return Choice{Kind::kLevel, protocol::Side::kLeft, 0, level}; }
  // An answer, not one of the record's two non-answers.
  bool Answers() const { return kind != Kind::kNone && kind != Kind::kSkipped; }
};
bool operator==(const Choice& a, const Choice& b);
inline bool operator!=(const Choice& a, const Choice& b) { return !(a == b); }

// The choice's word: left | right (protocol::Side's), cant_tell, yes, no, an interval's or a rating point's number
// (1..n), a level as protocol::LevelText (%g), and store::kChoiceNone, store::kChoiceSkipped.
std::string Name(const Choice& choice);

// The choice `text` names as a record of a task answered by `answer` (`intervals`: an odd one out, whose numbers are
// intervals; otherwise a number is a rating point), in the exact form Name writes; none and skipped are read for
// every task. nullopt for text that no choice of the task is named by.
std::optional<Choice> ParseChoice(std::string_view text, protocol::TaskAnswer answer, bool intervals);

// What a key press asks for: an answer, a step through an adjustment's levels, the accept of the level shown, the
// pause (Escape), or nothing (a key the protocol does not map).
struct Action {
  enum class Kind { kNothing, kAnswer, kPrevious, kNext, kAccept, kPause };
  Kind kind = Kind::kNothing;
  Choice choice;  // kAnswer

  static Action Answer(const Choice& choice) { return Action{Kind::kAnswer, choice}; }
  static Action Of(Kind kind) { return Action{kind, Choice{}}; }
};
bool operator==(const Action& a, const Action& b);

// The action's word, for logs and tests: the choice's Name for an answer, the /responses field for a step or the
// accept (previous | next | accept), pause, or "" for nothing.
std::string Name(const Action& action);

}  // namespace blurcue::procedure
