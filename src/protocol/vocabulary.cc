#include "protocol/vocabulary.h"

namespace blurcue::protocol {

// Each switch lists every value and has no default: -Wswitch names the function when a value is added. The return
// after it is reached only by a value outside the enum (vocabulary_test checks each Vocabulary is complete by it).

std::string ToString(Task value) {
  switch (value) {
    case Task::kForcedChoice: return "forced_choice";
    case Task::kAdjustment: return "adjustment";
    case Task::kYesNo: return "yes_no";
    case Task::kRating: return "rating";
  }
  return "";
}

const TaskTraits& TraitsOf(Task task) {
  // shows, answer, scored, deadline, keys (the /responses fields read; an odd one out's intervals read
  // responses.alternatives, which the layout decides).
  static const TaskTraits kForcedChoice{TaskShows::kPair, TaskAnswer::kSide, true, true,
                                         {ToString(ResponseKey::kLeft), ToString(ResponseKey::kRight),
                                          ToString(ResponseKey::kCantTell)}};
  static const TaskTraits kAdjustment{TaskShows::kPicture, TaskAnswer::kLevel, false, false,
                                      {ToString(ResponseKey::kPrevious), ToString(ResponseKey::kNext),
                                       ToString(ResponseKey::kAccept)}};
  static const TaskTraits kYesNo{TaskShows::kOneObject, TaskAnswer::kYesNo, false, true,
                                 {ToString(ResponseKey::kYes), ToString(ResponseKey::kNo)}};
  static const TaskTraits kRating{TaskShows::kOneObject, TaskAnswer::kRatingPoint, false, true, {"rating"}};
  switch (task) {
    case Task::kForcedChoice: return kForcedChoice;
    case Task::kAdjustment: return kAdjustment;
    case Task::kYesNo: return kYesNo;
    case Task::kRating: return kRating;
  }
  return kForcedChoice;
}

std::string ToString(Counterbalance value) {
  switch (value) {
    case Counterbalance::kNone: return "none";
    case Counterbalance::kSwapCopies: return "swap_copies";
    case Counterbalance::kByParticipant: return "by_participant";
  }
  return "";
}

std::string ToString(ProcedureKind value) {
  switch (value) {
    case ProcedureKind::kStaircase: return "staircase";
    case ProcedureKind::kQuestPlus: return "quest_plus";
  }
  return "";
}

std::string ToString(ProcedureVariable value) {
  switch (value) {
    case ProcedureVariable::kRelativeDifference: return "relative_difference";
    case ProcedureVariable::kDifferenceArcmin: return "difference_arcmin";
  }
  return "";
}

std::string ToString(AdjustOrder value) {
  switch (value) {
    case AdjustOrder::kShuffled: return "shuffled";
    case AdjustOrder::kAscending: return "ascending";
    case AdjustOrder::kDescending: return "descending";
  }
  return "";
}

std::string ToString(ContentType value) {
  switch (value) {
    case ContentType::kGrid: return "grid";
    case ContentType::kBall: return "ball";
    case ContentType::kPicture: return "picture";
  }
  return "";
}

std::string ToString(Kernel value) {
  switch (value) {
    case Kernel::kGaussian: return "gaussian";
    case Kernel::kDisc: return "disc";
  }
  return "";
}

std::string ToString(ThresholdUnit value) {
  switch (value) {
    case ThresholdUnit::kScreenPx: return "screen_px";
    case ThresholdUnit::kArcmin: return "arcmin";
  }
  return "";
}

std::string ToString(ScenePhoto value) {
  switch (value) {
    case ScenePhoto::kBackground: return "background";
    case ScenePhoto::kBoardFree: return "board_free";
  }
  return "";
}

std::string ToString(Layout value) {
  switch (value) {
    case Layout::kSideBySide: return "side_by_side";
    case Layout::kTwoIntervals: return "two_intervals";
    case Layout::kSingle: return "single";
    case Layout::kOddOneOut: return "odd_one_out";
  }
  return "";
}

std::string ToString(BlockSequence value) {
  switch (value) {
    case BlockSequence::kFixed: return "fixed";
    case BlockSequence::kRandom: return "random";
    case BlockSequence::kLatinSquare: return "latin_square";
  }
  return "";
}

std::string ToString(GroupAssign value) {
  switch (value) {
    case GroupAssign::kByNumber: return "by_number";
    case GroupAssign::kBalanced: return "balanced";
  }
  return "";
}

std::string ToString(InfoType value) {
  switch (value) {
    case InfoType::kInteger: return "integer";
    case InfoType::kNumber: return "number";
    case InfoType::kChoice: return "choice";
    case InfoType::kText: return "text";
  }
  return "";
}

std::string ToString(RadiusUnit value) {
  switch (value) {
    case RadiusUnit::kPhotoPx: return "photo_px";
    case RadiusUnit::kScreenPx: return "screen_px";
    case RadiusUnit::kArcmin: return "arcmin";
  }
  return "";
}

std::string ToString(Side value) {
  switch (value) {
    case Side::kLeft: return "left";
    case Side::kRight: return "right";
  }
  return "";
}

// The fields that answer a side are named by the side; can't tell by the word the record writes for it
// (procedure/answer.cc's choice table has the same word: a key's field and its answer are spelled alike).
std::string ToString(ResponseKey value) {
  switch (value) {
    case ResponseKey::kLeft: return ToString(Side::kLeft);
    case ResponseKey::kRight: return ToString(Side::kRight);
    case ResponseKey::kCantTell: return "cant_tell";
    case ResponseKey::kPrevious: return "previous";
    case ResponseKey::kNext: return "next";
    case ResponseKey::kAccept: return "accept";
    case ResponseKey::kYes: return "yes";
    case ResponseKey::kNo: return "no";
  }
  return "";
}

}  // namespace blurcue::protocol
