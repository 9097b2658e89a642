#include "session/answer.h"

#include <string>

namespace blurcue::session {

uint64_t TrialSeed(uint64_t seed, int index) {
  uint64_t z = seed + 0x9e3779b97f4a7c15ULL * uint64_t(index + 1);  // splitmix64
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

PairView ViewOf(const TrialScene& scene, const Presentation& presentation) {
  // One photo px's angle at the centre of the screen (Presentation::Arcmin): the radii are a few px, where the
  // exact 2 atan(s / 2d) and the straight line agree to far better than 1e-6.
  return {scene.r_left_px, scene.r_right_px, scene.r_scene_px, presentation.Arcmin(1)};
}

std::vector<KeyPress> AnswerTrial(SimulatedObserver& observer, const protocol::Protocol& protocol,
                                  const protocol::Trial& trial, const TrialScene& scene,
                                  const Presentation& presentation) {
  using protocol::Task;
  if (trial.task == Task::kAdjustment) return observer.Adjust(trial.adjust_levels, trial.start_index, scene.distance_m);
  const PairView view = ViewOf(scene, presentation);
  const KeyPress press =
      trial.task == Task::kYesNo    ? observer.SayYesNo(view)
      : trial.task == Task::kRating ? observer.Rate(view, int(protocol.responses.rating.size()))
      : scene.intervals > 2         ? observer.ChooseOdd(view, scene.intervals, std::stoi(trial.test_side))
      // A procedure, or practice scored by a criterion: "which side is more blurred?"
      : trial.cell >= 0 || trial.round >= 0 ? observer.ChooseBlurrier(view)
                                            : observer.ChooseSide(view, !protocol.responses.cant_tell.empty());
  return {press};
}

}  // namespace blurcue::session
