#pragma once
// What a participant can see of a protocol before anyone sits down: for every distinct stimulus pair, on the session's
// display, the probability that an observer (the simulated observer's model, without lapses or bias) tells its two
// sides apart in a 2AFC - and the pairs below a stated level flagged. `blurcue validate --plan` and `blurcue preview`
// print it; both start from PrepareSession, as `blurcue run` does.
#include <string>
#include <vector>

#include "protocol/trials.h"
#include "session/observer.h"
#include "session/prepare.h"

namespace blurcue::session {

struct PairVisibility {
  std::string what;        // "measured vs estimated at edge 2", or "object measured vs the scene at blur 3"
  double r_a_arcmin = 0, r_b_arcmin = 0;  // the two radii compared on the screen (left, right; or object, scene)
  double p_correct = 0.5;  // ProbabilityCorrect2afc of the two
  bool visible = false;    // p_correct >= the level asked for
  int trials = 0;          // trials of the list showing this pair (either side order)
};

// A trial's levels as a label: "edge 2", "edge 2 speed 3" ("" without levels).
std::string LevelsLabel(const protocol::Trial& trial);

// Every distinct pair of the prepared session's trial list (the same levels and sources, either side order, counted
// once), each trial of a procedure at its first level (ApplyLevel, as `blurcue preview` shows it): its two radii on the
// presentation, in arcmin, and the observer's probability of telling them apart. A layout-single trial (one object)
// compares its object with the scene's own blur there. Adjustment (picture) trials have no pair: none are listed.
// `level`: the share correct below which a pair is not visible.
std::vector<PairVisibility> PairVisibilities(const PreparedSession& prepared, const ObserverParams& observer,
                                             double level);

// "measured vs estimated at edge 2: 0.30 arcmin apart (0.50' vs 0.80'), predicted 53 % correct - invisible at 60 cm on
// this monitor" (the profile's distance), or "... predicted 91 % correct".
std::string Describe(const PairVisibility& pair, const display::Profile& profile);

}  // namespace blurcue::session
