#pragma once
// The protocol's vocabularies: each word a protocol file may use for a mode is an enum value here, with one
// ToString (the word, as the file, the record and every message spell it) and one ParseWord beside it. The parser
// reads the words once; after protocol/, code switches over these enums (exhaustively, no default:), so a new value
// makes the compiler show every place to touch. To add a value: the enum, its case in ToString, its place in
// Vocabulary<E>::values (the order the parser lists the allowed words in).
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/blur_source.h"

namespace blurcue::protocol {

// Every value of a vocabulary, in the order the parser's "must be one of" lists them; specialised per enum below.
template <typename E>
struct Vocabulary;

// "forced_choice": which of two sides or intervals (or, odd one out, which of N intervals); "adjustment": step through
// levels and accept one; "yes_no" and "rating" (layout single): one object, answered yes or no, or on a scale of
// responses.rating's keys.
enum class Task { kForcedChoice, kAdjustment, kYesNo, kRating };
template <>
struct Vocabulary<Task> {
  static constexpr std::array values{Task::kForcedChoice, Task::kAdjustment, Task::kYesNo, Task::kRating};
};

// "none" | "swap_copies" | "by_participant".
enum class Counterbalance { kNone, kSwapCopies, kByParticipant };
template <>
struct Vocabulary<Counterbalance> {
  static constexpr std::array values{Counterbalance::kSwapCopies, Counterbalance::kByParticipant,
                                     Counterbalance::kNone};
};

// An adaptive procedure's type: "staircase" | "quest_plus".
enum class ProcedureKind { kStaircase, kQuestPlus };
template <>
struct Vocabulary<ProcedureKind> {
  static constexpr std::array values{ProcedureKind::kStaircase, ProcedureKind::kQuestPlus};
};

// A procedure's level: "relative_difference" (a blur gain of 1 + level) | "difference_arcmin" (plus level arcmin).
enum class ProcedureVariable { kRelativeDifference, kDifferenceArcmin };
template <>
struct Vocabulary<ProcedureVariable> {
  static constexpr std::array values{ProcedureVariable::kRelativeDifference, ProcedureVariable::kDifferenceArcmin};
};

// The order an adjustment's levels are stepped through: "shuffled" | "ascending" | "descending".
enum class AdjustOrder { kShuffled, kAscending, kDescending };
template <>
struct Vocabulary<AdjustOrder> {
  static constexpr std::array values{AdjustOrder::kShuffled, AdjustOrder::kAscending, AdjustOrder::kDescending};
};

// What the trials show: "grid" (a drawn card) | "ball" | "picture" (a whole low-passed image).
enum class ContentType { kGrid, kBall, kPicture };
template <>
struct Vocabulary<ContentType> {
  static constexpr std::array values{ContentType::kGrid, ContentType::kBall, ContentType::kPicture};
};

// The blur kernel of a grid or ball: "gaussian" | "disc".
enum class Kernel { kGaussian, kDisc };
template <>
struct Vocabulary<Kernel> {
  static constexpr std::array values{Kernel::kGaussian, Kernel::kDisc};
};

// The unit of content.depth_blur_threshold: "screen_px" | "arcmin".
enum class ThresholdUnit { kScreenPx, kArcmin };
template <>
struct Vocabulary<ThresholdUnit> {
  static constexpr std::array values{ThresholdUnit::kScreenPx, ThresholdUnit::kArcmin};
};

// Which scene photo the trials show: "background" | "board_free".
enum class ScenePhoto { kBackground, kBoardFree };
template <>
struct Vocabulary<ScenePhoto> {
  static constexpr std::array values{ScenePhoto::kBackground, ScenePhoto::kBoardFree};
};

// How a trial is laid out: "side_by_side" | "two_intervals" | "single" | "odd_one_out" (see Protocol::layout).
enum class Layout { kSideBySide, kTwoIntervals, kSingle, kOddOneOut };
template <>
struct Vocabulary<Layout> {
  static constexpr std::array values{Layout::kSideBySide, Layout::kTwoIntervals, Layout::kSingle, Layout::kOddOneOut};
};

// The order blocks run in: "fixed" | "random" | "latin_square" (see Protocol::block_order).
enum class BlockSequence { kFixed, kRandom, kLatinSquare };
template <>
struct Vocabulary<BlockSequence> {
  static constexpr std::array values{BlockSequence::kFixed, BlockSequence::kRandom, BlockSequence::kLatinSquare};
};

// How a participant is put in a group: "by_number" | "balanced" (see Groups::assign).
enum class GroupAssign { kByNumber, kBalanced };
template <>
struct Vocabulary<GroupAssign> {
  static constexpr std::array values{GroupAssign::kByNumber, GroupAssign::kBalanced};
};

// A participant information field's type: "integer" | "number" | "choice" | "text".
enum class InfoType { kInteger, kNumber, kChoice, kText };
template <>
struct Vocabulary<InfoType> {
  static constexpr std::array values{InfoType::kInteger, InfoType::kNumber, InfoType::kChoice, InfoType::kText};
};

// Where a side's blur comes from: core's one vocabulary (core/blur_source.h), which calib evaluates too.
using ::blurcue::BlurSource;
using ::blurcue::ToString;
template <>
struct Vocabulary<BlurSource> {
  static constexpr auto values = kBlurSources;
};

// The unit of a fixed radius: "photo_px" (a bare number: the camera's pixels) | "screen_px" | "arcmin" (the keys of
// {"screen_px": r} and {"arcmin": r}).
enum class RadiusUnit { kPhotoPx, kScreenPx, kArcmin };
template <>
struct Vocabulary<RadiusUnit> {
  static constexpr std::array values{RadiusUnit::kPhotoPx, RadiusUnit::kScreenPx, RadiusUnit::kArcmin};
};

// A side of a pair as the participant sees it: the word of a level's or the sides' field, of a procedure's test side,
// of the record's side columns and of a side answer (left | right). Every module spells a side through this one
// table (ToString, ParseWord), so the words live in vocabulary.cc alone.
enum class Side { kLeft, kRight };
template <>
struct Vocabulary<Side> {
  static constexpr std::array values{Side::kLeft, Side::kRight};
};
// The side across from `side`.
constexpr Side Other(Side side) { return side == Side::kLeft ? Side::kRight : Side::kLeft; }
// A side's place in a pair's std::array<T, 2> of per-side values: 0 left, 1 right (Vocabulary<Side>::values' order).
constexpr size_t Index(Side side) { return side == Side::kLeft ? 0 : 1; }

// A /responses field that names one key (left | right | cant_tell | previous | next | accept | yes | no), in the
// order the parser lists the fields; the lists (rating, alternatives) have fields of their own.
enum class ResponseKey { kLeft, kRight, kCantTell, kPrevious, kNext, kAccept, kYes, kNo };
template <>
struct Vocabulary<ResponseKey> {
  static constexpr std::array values{ResponseKey::kLeft,     ResponseKey::kRight, ResponseKey::kCantTell,
                                     ResponseKey::kPrevious, ResponseKey::kNext,  ResponseKey::kAccept,
                                     ResponseKey::kYes,      ResponseKey::kNo};
};

// What a trial of a task shows: a picture (content "picture": the real one and the virtual one to match), one object
// (the layout single), or a pair of objects (side by side, in two intervals, or as an odd one out of n).
enum class TaskShows { kPicture, kOneObject, kPair };
// What the participant answers: a side or interval (left / right / can't tell, or an odd-one-out interval "1".."n"),
// yes or no, a point of a rating scale ("1".."n"), or a level stepped to and accepted.
enum class TaskAnswer { kSide, kYesNo, kRatingPoint, kLevel };

// Everything the code knows of a task, in one place (TraitsOf): after protocol/ a caller asks these instead of
// comparing Task values, so a new task with the shows/answer of an existing one is a row here (see
// docs/contributing.md).
struct TaskTraits {
  TaskShows shows = TaskShows::kPair;
  TaskAnswer answer = TaskAnswer::kSide;
  // An answer is right or wrong (the side showing more blur, a procedure's test side, the odd interval): what a
  // procedure, a practice criterion and feedback need.
  bool scored = false;
  // A deadline (timing.deadline_ms) can end a trial with no answer; false: it runs until a level is accepted.
  bool deadline = true;
  // The /responses fields the task reads (its keys), as the protocol file spells them.
  std::vector<std::string> keys;
};

// The traits of `task` (a switch: a new Task value makes the compiler ask for its row).
const TaskTraits& TraitsOf(Task task);

// The words of the tasks whose traits satisfy `pred`, in Vocabulary<Task>::values order, joined by " or "
// ("yes_no or rating"): how a message names the tasks a rule allows.
template <typename Pred>
std::string TaskWords(Pred pred);

// The word for a value, as protocol files, the record and messages spell it ("" for a value outside the enum).
std::string ToString(Task value);
std::string ToString(Counterbalance value);
std::string ToString(ProcedureKind value);
std::string ToString(ProcedureVariable value);
std::string ToString(AdjustOrder value);
std::string ToString(ContentType value);
std::string ToString(Kernel value);
std::string ToString(ThresholdUnit value);
std::string ToString(ScenePhoto value);
std::string ToString(Layout value);
std::string ToString(BlockSequence value);
std::string ToString(GroupAssign value);
std::string ToString(InfoType value);
std::string ToString(RadiusUnit value);
std::string ToString(Side value);
std::string ToString(ResponseKey value);

// The value a word names, or nullopt when the vocabulary has no such word.
template <typename E>
std::optional<E> ParseWord(std::string_view word) {
  for (const E value : Vocabulary<E>::values)
    if (ToString(value) == word) return value;
  return std::nullopt;
}

template <typename Pred>
std::string TaskWords(Pred pred) {
  std::string words;
  for (const Task task : Vocabulary<Task>::values)
    if (pred(TraitsOf(task))) words += (words.empty() ? "" : " or ") + ToString(task);
  return words;
}

// Every word of a vocabulary, in Vocabulary<E>::values order: the parser's allowed values.
template <typename E>
std::vector<std::string> Words() {
  std::vector<std::string> words;
  for (const E value : Vocabulary<E>::values) words.push_back(ToString(value));
  return words;
}

}  // namespace blurcue::protocol
