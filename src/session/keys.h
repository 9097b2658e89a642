#pragma once
// Keys -> actions and back, as a protocol maps them: what the trial loop reads from a responder's keys, and what the
// simulated observer presses for its answers.
#include <algorithm>
#include <cctype>
#include <string>
#include <vector>

#include "protocol/protocol.h"
#include "protocol/trials.h"
#include "session/recording.h"

namespace blurcue::session {

// Keys -> actions, as the protocol maps them: left / right / cant_tell, an odd-one-out interval or a rating point
// ("1".."n"), yes / no, or the adjustment's steps (the mouse steps and accepts too).
struct KeyMap {
  const protocol::Responses& r;
  bool odd_one_out;
  // The keys whose position names the answer ("1".."n"): a rating's points, an odd-one-out trial's intervals.
  const std::vector<std::string>* Numbered(protocol::Task task) const {
    const protocol::TaskAnswer answer = protocol::TraitsOf(task).answer;
    return answer == protocol::TaskAnswer::kRatingPoint             ? &r.rating
           : answer == protocol::TaskAnswer::kSide && odd_one_out ? &r.alternatives
                                                                  : nullptr;
  }
  std::string Action(const std::string& key, protocol::Task task) const {
    if (key == "Escape") return "pause";
    const protocol::TaskAnswer answer = protocol::TraitsOf(task).answer;
    if (const auto* keys = Numbered(task)) {
      const auto it = std::find(keys->begin(), keys->end(), key);
      if (it != keys->end()) return std::to_string(it - keys->begin() + 1);
      if (answer == protocol::TaskAnswer::kSide && !r.cant_tell.empty() && key == r.cant_tell) return "cant_tell";
      return "";
    }
    switch (answer) {
      case protocol::TaskAnswer::kSide:
        if (key == r.left) return "left";
        if (key == r.right) return "right";
        if (key == r.cant_tell) return "cant_tell";
        break;
      case protocol::TaskAnswer::kYesNo:
        if (key == r.yes) return "yes";
        if (key == r.no) return "no";
        break;
      case protocol::TaskAnswer::kLevel:
        if (key == r.previous || key == "WheelDown") return "previous";
        if (key == r.next || key == "WheelUp") return "next";
        if (key == r.accept || key == "MouseLeft") return "accept";
        break;
      case protocol::TaskAnswer::kRatingPoint: break;  // numbered above
    }
    return "";
  }
  std::string Key(const std::string& action, protocol::Task task) const {
    if (const auto* keys = Numbered(task); keys && !action.empty() && std::isdigit(unsigned(action[0])))
      return (*keys)[size_t(std::stoi(action) - 1)];
    if (action == "left") return r.left;
    if (action == "right") return r.right;
    if (action == "cant_tell") return r.cant_tell;
    if (action == "yes") return r.yes;
    if (action == "no") return r.no;
    if (action == "previous") return r.previous;
    if (action == "next") return r.next;
    return r.accept;
  }
  // Whether `choice` is an answer a session can record for `trial`: one of its task's actions as these keys give
  // them, an adjustment's level (as the record writes it), or no answer (a deadline passed).
  bool CanRecord(const std::string& choice, const protocol::Trial& trial) const {
    if (choice == kChoiceNone) return true;
    const protocol::TaskAnswer answer = protocol::TraitsOf(trial.task).answer;
    if (answer == protocol::TaskAnswer::kLevel)
      return std::any_of(trial.adjust_levels.begin(), trial.adjust_levels.end(),
                         [&](double level) { return protocol::LevelText(level) == choice; });
    const bool cant_tell = answer == protocol::TaskAnswer::kSide && !r.cant_tell.empty() && choice == "cant_tell";
    if (const auto* keys = Numbered(trial.task)) {
      for (size_t i = 0; i < keys->size(); ++i)
        if (choice == std::to_string(i + 1)) return true;
      return cant_tell;
    }
    if (answer == protocol::TaskAnswer::kSide) return choice == "left" || choice == "right" || cant_tell;
    if (answer == protocol::TaskAnswer::kYesNo) return choice == "yes" || choice == "no";
    return false;
  }
  // An action that answers a trial (not a step of an adjustment, not the pause).
  static bool Answers(const std::string& action) {
    return action == "left" || action == "right" || action == "cant_tell" || action == "yes" || action == "no" ||
           (!action.empty() && std::isdigit(unsigned(action[0])));
  }
};

}  // namespace blurcue::session
