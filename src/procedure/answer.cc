#include "procedure/answer.h"

#include <string>

#include "core/error.h"
#include "core/seed.h"

namespace blurcue::procedure {

using stimulus::Presentation;
using stimulus::TrialScene;

uint64_t TrialSeed(uint64_t seed, int index) { return DeriveSeed(seed, static_cast<uint64_t>(index)); }

PairView ViewOf(const TrialScene& scene, const Presentation& presentation) {
  // One photo px's angle at the centre of the screen (Presentation::Arcmin): the radii are a few px, where the
  // exact 2 atan(s / 2d) and the straight line agree to far better than 1e-6.
  return {scene.r_left_px, scene.r_right_px, scene.r_scene_px, presentation.Arcmin(1)};
}

AdjustView AdjustViewOf(const protocol::Trial& trial, const TrialScene& scene, const Presentation& presentation) {
  AdjustView view;
  view.distance_m = scene.distance_m;
  if (scene.content != protocol::ContentType::kPicture) return view;
  if (presentation.real_frame_px_per_px > 0) view.r_real_arcmin = presentation.RealArcmin(scene.r_scene_px);
  for (double level : trial.adjust_levels) view.level_r_arcmin.push_back(presentation.LevelArcmin(level));
  return view;
}

void CheckObserverCanAnswer(const ObserverParams& observer, const protocol::Protocol& protocol) {
  if (observer.model != ObserverModel::kArcmin || protocol.content.type != protocol::ContentType::kPicture || protocol.content.real_camera)
    return;
  for (const auto& block : protocol.blocks)
    if (protocol::TraitsOf(block.task).answer == protocol::TaskAnswer::kLevel)
      throw InputError(protocol.file.string() + ": /content/real_camera",
                       "is needed by the simulated observer (model=arcmin), which sets the picture to the real "
                       "picture's blur in visual angle: name the camera and focus of the real photos, or use "
                       "--observer sim:model=pixel (a cut-off per distance)");
}

std::vector<KeyPress> AnswerTrial(SimulatedObserver& observer, const protocol::Protocol& protocol,
                                  const protocol::Trial& trial, const TrialScene& scene,
                                  const Presentation& presentation) {
  using protocol::TaskAnswer;
  switch (protocol::TraitsOf(trial.task).answer) {
    case TaskAnswer::kLevel:
      return observer.Adjust(trial.adjust_levels, trial.start_index, AdjustViewOf(trial, scene, presentation));
    case TaskAnswer::kYesNo: return {observer.SayYesNo(ViewOf(scene, presentation))};
    case TaskAnswer::kRatingPoint:
      return {observer.Rate(ViewOf(scene, presentation), int(protocol.responses.rating.size()))};
    case TaskAnswer::kSide: break;
  }
  const PairView view = ViewOf(scene, presentation);
  const KeyPress press =
      scene.intervals > 2 ? observer.ChooseOdd(view, scene.intervals, std::stoi(trial.test_side))
      // A procedure, or practice scored by a criterion: "which side is more blurred?"
      : trial.cell >= 0 || trial.round >= 0 ? observer.ChooseBlurrier(view)
                                            : observer.ChooseSide(view, !protocol.responses.cant_tell.empty());
  return {press};
}

}  // namespace blurcue::procedure
