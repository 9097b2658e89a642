#pragma once
// Keys -> actions and back, as a protocol maps them: what the trial loop reads from a responder's keys, and what the
// simulated observer presses for its answers.
#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include "protocol/protocol.h"
#include "protocol/trials.h"
#include "procedure/answer.h"
#include "session/recording.h"

namespace blurcue::session {

// Keys -> actions, as the protocol maps them: a side or can't tell, an odd-one-out interval or a rating point (the
// key's place in its list), yes / no, or the adjustment's steps (the mouse steps and accepts too).
struct KeyMap {
  using Action = procedure::Action;
  using Choice = procedure::Choice;

  const protocol::Responses& r;
  bool odd_one_out;
  // The keys whose position names the answer (1..n): a rating's points, an odd-one-out trial's intervals.
  const std::vector<std::string>* Numbered(protocol::Task task) const {
    const protocol::TaskAnswer answer = protocol::TraitsOf(task).answer;
    return answer == protocol::TaskAnswer::kRatingPoint             ? &r.rating
           : answer == protocol::TaskAnswer::kSide && odd_one_out ? &r.alternatives
                                                                  : nullptr;
  }
  Action ActionOf(const std::string& key, protocol::Task task) const {
    using Kind = Choice::Kind;
    if (key == "Escape") return Action::Of(Action::Kind::kPause);
    const protocol::TaskAnswer answer = protocol::TraitsOf(task).answer;
    const bool cant_tell = answer == protocol::TaskAnswer::kSide && !r.cant_tell.empty() && key == r.cant_tell;
    if (const auto* keys = Numbered(task)) {
      const auto it = std::find(keys->begin(), keys->end(), key);
      const Kind kind = answer == protocol::TaskAnswer::kRatingPoint ? Kind::kRating : Kind::kInterval;
      if (it != keys->end()) return Action::Answer(Choice::Numbered(kind, int(it - keys->begin() + 1)));
      if (cant_tell) return Action::Answer(Choice::Of(Kind::kCantTell));
      return {};
    }
    switch (answer) {
      case protocol::TaskAnswer::kSide:
        if (key == r.left) return Action::Answer(Choice::Of(protocol::Side::kLeft));
        if (key == r.right) return Action::Answer(Choice::Of(protocol::Side::kRight));
        if (key == r.cant_tell) return Action::Answer(Choice::Of(Kind::kCantTell));
        break;
      case protocol::TaskAnswer::kYesNo:
        if (key == r.yes) return Action::Answer(Choice::Of(Kind::kYes));
        if (key == r.no) return Action::Answer(Choice::Of(Kind::kNo));
        break;
      case protocol::TaskAnswer::kLevel:
        if (key == r.previous || key == "WheelDown") return Action::Of(Action::Kind::kPrevious);
        if (key == r.next || key == "WheelUp") return Action::Of(Action::Kind::kNext);
        if (key == r.accept || key == "MouseLeft") return Action::Of(Action::Kind::kAccept);
        break;
      case protocol::TaskAnswer::kRatingPoint: break;  // numbered above
    }
    return {};
  }
  // The key that gives `action` (the accept key for an action no key gives).
  std::string Key(const Action& action, protocol::Task task) const {
    using Kind = Choice::Kind;
    switch (action.kind) {
      case Action::Kind::kPrevious: return r.previous;
      case Action::Kind::kNext: return r.next;
      case Action::Kind::kAccept:
      case Action::Kind::kPause:
      case Action::Kind::kNothing: return r.accept;
      case Action::Kind::kAnswer: break;
    }
    const Choice& c = action.choice;
    switch (c.kind) {
      case Kind::kInterval:
      case Kind::kRating:
        if (const auto* keys = Numbered(task)) return (*keys)[size_t(c.point - 1)];
        return r.accept;
      case Kind::kSide: return r.Key(c.side == protocol::Side::kLeft ? protocol::ResponseKey::kLeft
                                                                     : protocol::ResponseKey::kRight);
      case Kind::kCantTell: return r.cant_tell;
      case Kind::kYes: return r.yes;
      case Kind::kNo: return r.no;
      case Kind::kLevel:
      case Kind::kNone:
      case Kind::kSkipped: return r.accept;
    }
    return r.accept;
  }
  // The choice a record's text names for `trial` (as ParseChoice reads it for the trial's task and layout).
  std::optional<Choice> Parse(const std::string& text, const protocol::Trial& trial) const {
    return procedure::ParseChoice(text, protocol::TraitsOf(trial.task).answer, odd_one_out);
  }
  // Whether `choice` is an answer a session can record for `trial`: one of its task's actions as these keys give
  // them, an adjustment's level (one of the trial's), or no answer (a deadline passed).
  bool CanRecord(const Choice& choice, const protocol::Trial& trial) const {
    using Kind = Choice::Kind;
    const protocol::TaskAnswer answer = protocol::TraitsOf(trial.task).answer;
    const std::vector<std::string>* keys = Numbered(trial.task);
    switch (choice.kind) {
      case Kind::kNone: return true;
      case Kind::kSkipped: return false;
      case Kind::kLevel:
        return answer == protocol::TaskAnswer::kLevel &&
               std::any_of(trial.adjust_levels.begin(), trial.adjust_levels.end(),
                           [&](double level) { return protocol::LevelText(level) == procedure::Name(choice); });
      case Kind::kCantTell: return answer == protocol::TaskAnswer::kSide && !r.cant_tell.empty();
      case Kind::kInterval:
      case Kind::kRating: return keys && choice.point >= 1 && size_t(choice.point) <= keys->size();
      case Kind::kSide: return answer == protocol::TaskAnswer::kSide && !keys;
      case Kind::kYes:
      case Kind::kNo: return answer == protocol::TaskAnswer::kYesNo;
    }
    return false;
  }
};

}  // namespace blurcue::session
