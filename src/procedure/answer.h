#pragma once
// What a simulated observer answers to a trial, from the trial and what it shows - the one place `blurcue run`
// (headless or in a window) and `blurcue plan` (many simulated sessions, no GL) get their simulated answers from, so
// a plan predicts the answers a run records.
#include <cstdint>
#include <vector>

#include "protocol/protocol.h"
#include "protocol/trials.h"
#include "procedure/observer.h"
#include "stimulus/stimulus.h"

namespace blurcue::procedure {

// The choices recorded besides the answers themselves: no answer before the deadline, and a trial not shown (a
// procedure ended by its stop rule, a practice run after the one that met its criterion). The record's own words
// (store::kChoiceNone, store::kChoiceSkipped; session/recording.cc checks they agree).
inline constexpr const char* kChoiceNone = "none";
inline constexpr const char* kChoiceSkipped = "skipped";

// The seed of the observer of one trial: from the session seed and the trial index (splitmix64), so a resumed
// session answers exactly as an uninterrupted one, and a plan as a run.
uint64_t TrialSeed(uint64_t session_seed, int trial_index);

// The key presses a simulated observer makes for a trial whose stimulus is `scene` (after ApplyLevel for a procedure's
// trial): the single answer, or the adjustment's presses. The task decides the question: yes/no and rating judge the
// one object against the scene; an odd-one-out trial names an interval; a procedure's trial or a practice run to a
// criterion asks "which side is more blurred?"; other pairs "which fits the scene?" (with can't tell when the
// protocol has its key). The presentation gives the arcmin per photo px the arcmin model sees.
std::vector<KeyPress> AnswerTrial(SimulatedObserver& observer, const protocol::Protocol& protocol,
                                  const protocol::Trial& trial, const stimulus::TrialScene& scene,
                                  const stimulus::Presentation& presentation);

// What the observer sees of an adjustment trial: the distance, and for a picture the real picture's blur (when the
// protocol names its camera) and each level's blur in arcmin as this presentation shows them.
AdjustView AdjustViewOf(const protocol::Trial& trial, const stimulus::TrialScene& scene, const stimulus::Presentation& presentation);

// Throws Error(kInput) naming /content/real_camera when `observer` cannot answer the protocol's trials: the arcmin
// model in a depth-matching (adjustment) block without the real photos' camera. Run and plan check before any trial.
void CheckObserverCanAnswer(const ObserverParams& observer, const protocol::Protocol& protocol);

// What the observer sees of a trial's pair: its radii (photo px) and arcmin per photo px on this presentation.
PairView ViewOf(const stimulus::TrialScene& scene, const stimulus::Presentation& presentation);

}  // namespace blurcue::procedure
